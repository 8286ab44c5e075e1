"""The worked example of the chapter "Design your own drive": a drive that is not the paper's.

The drive is a drive file shipped with the package (:data:`EXAMPLE_DRIVE_FILE`), read as
``passmd --drive FILE`` reads it. Every figure's data comes from the functions a designer
calls: :func:`passmd.protocols.maps.compute_map` (what ``passmd sweep`` runs) for the
critical amplitude, the step and velocity map, the Eq. 15 gain map and the stall force, and
:func:`passmd.protocols.fit.estimator.fit` (what ``passmd fit`` runs) for the calibration. One function
per figure; the grids of each profile are in :data:`PROFILE_SETTINGS`.

The calibration's settings are here (:data:`NOISE_NM`, :data:`SEED`, :data:`START`, each profile's
free parameters and points); its functions, and what the chapter quotes of each figure, are
:mod:`passmd.experiments.design_your_drive.facts`. The chapter draws its figures from these tables
with :mod:`passmd.plots.design` (maps with their quantity and title, the fit's results), as a designer
would, so :data:`FIGURES` holds no row: the figure table is also every result the ledger computes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd

from passmd.model import drive_file
from passmd.model.defaults import PROTOCOL
from passmd.model.drive_file import parameter_rows, read_drive_file, resolve
from passmd.model.parameters import Drive
from passmd.model.theory import contact_arrangement
from passmd.protocols import stall
from passmd.protocols.maps import compute_map
from passmd.runtime.config import PROFILES, RunConfig
from passmd.runtime.units import from_si
from passmd.runtime.validation import check_choice

__all__ = [
    "FIGURES",
    "EXAMPLE_DRIVE_FILE",
    "NOISE_NM",
    "PROFILE_SETTINGS",
    "SEED",
    "START",
    "ProfileSettings",
    "contact_table",
    "critical_amplitude_curve",
    "curve_from_maps",
    "example_drive",
    "gain_map",
    "map_axes",
    "map_points",
    "parameter_table",
    "preload_points",
    "run_config",
    "stall_force_curve",
    "stall_frame",
    "stall_points",
    "step_velocity_map",
]

#: The example drive file (package data, so an installed wheel has it too; ``passmd drive template
#: --example`` prints it).
EXAMPLE_DRIVE_FILE = drive_file.EXAMPLE_DRIVE_FILE
#: Standard deviation of the synthetic measurements' noise (nm): a step read to about 1 nm, as
#: a capacitive or interferometric sensor on a test stand reads it.
NOISE_NM = 1.0
#: Seed of the noise (numpy's default generator): the measurements are the same on every build.
SEED = 0
#: Frequency of the calibration's steps (Hz): Section 4.1's saw-tooth frequency.
FIT_FREQUENCY = PROTOCOL.drive_frequency
#: A designer's first guess of each free parameter: its source. The values are the paper's.
START = {"friction_coefficient": "Table 1 (μ = 0.2)",
         "actuator.stiffness": "Table 2 interpolated at the radius"}


@dataclass(frozen=True)
class ProfileSettings:
    """What a profile computes for the chapter."""

    preloads: tuple[float, ...]  # critical amplitude against preload (N)
    map_frequencies: int  # log-spaced from MAP_FREQUENCY_RANGE
    map_amplitudes: int  # linear over MAP_AMPLITUDE_RANGE
    stall_fractions: tuple[float, ...]  # stall force amplitudes, fractions of the full stroke
    stall_preloads: tuple[float, ...]  # N
    free: tuple[str, ...]  # fitted parameters
    fit_preloads: tuple[float, ...]  # N
    fit_amplitudes_nm: tuple[float, ...]  # at each fit preload, FIT_FREQUENCY
    #: held-back points: (frequency Hz, preload N, amplitude nm), steps never shown to the fit
    heldback: tuple[tuple[float, float, float], ...]
    #: executor of the sweeps when the configuration names none (None: the sweep engine's default)
    executor: str | None = None


#: Frequency and amplitude ranges of the maps: 100 Hz (Fig. 9a) to 110 kHz (Fig. 9b); amplitudes
#: from 40 nm (above the example drive's steady critical amplitude) to its full stroke.
MAP_FREQUENCY_RANGE = (100.0, 110e3)
MAP_AMPLITUDE_LOW = 40e-9

#: The grids of each book profile (quick: coarse, for CI; paper: finer maps, two fitted parameters).
PROFILE_SETTINGS = {
    "quick": ProfileSettings(
        preloads=(0.2, 0.6, 1.0),
        map_frequencies=6, map_amplitudes=6,
        stall_fractions=(0.6, 1.0), stall_preloads=(0.6,),
        free=("friction_coefficient",),
        fit_preloads=(0.6,), fit_amplitudes_nm=(70.0, 90.0, 110.0, 130.0),
        heldback=((100.0, 0.9, 80.0), (100.0, 0.9, 125.0), (5e3, 0.6, 80.0), (5e3, 0.6, 125.0)),
        # A few cheap points per sweep: starting a process pool (each worker imports numpy, numba
        # and passmd, seconds on a loaded 2-core machine) costs more than the points themselves.
        executor="serial",
    ),
    # The example drive is not the paper's: "paper" here means finer maps. The calibration is the
    # quick profile's: its data are independent runs of 16 periods with the integrator refined, and
    # a two-parameter fit on them alone takes longer than the cold paper-profile book's budget (the
    # calibration chapter fits μ and k_p together).
    "paper": ProfileSettings(
        preloads=tuple(np.round(np.linspace(0.1, 1.0, 10), 3)),
        map_frequencies=12, map_amplitudes=12,
        stall_fractions=(0.4, 0.7, 1.0), stall_preloads=(0.3, 0.6),
        free=("friction_coefficient",),
        fit_preloads=(0.6,), fit_amplitudes_nm=(70.0, 90.0, 110.0, 130.0),
        heldback=((100.0, 0.9, 80.0), (100.0, 0.9, 125.0), (5e3, 0.6, 80.0), (5e3, 0.6, 125.0)),
    ),
}


def _settings(profile: str) -> ProfileSettings:
    return PROFILE_SETTINGS[check_choice("profile", profile, PROFILES)]


def _run_config(config: RunConfig | None, profile: str) -> RunConfig:
    """``config`` with the profile's executor where it names none (an explicit choice wins)."""
    config = RunConfig() if config is None else config
    executor = _settings(profile).executor
    if config.executor is None and config.scheduler is None and executor is not None:
        return replace(config, executor=executor)
    return config


def example_drive(path=None) -> tuple[Drive, dict]:
    """The drive a drive file describes and where each parameter came from, as ``passmd drive show``.

    ``path``: default :data:`EXAMPLE_DRIVE_FILE`; the given keys' source is ``given in NAME``.
    """
    path = EXAMPLE_DRIVE_FILE if path is None else Path(path)
    values = read_drive_file(path)
    return resolve(values, dict.fromkeys(values, f"given in {path.name}"))


def parameter_table(drive: Drive, sources: dict) -> pd.DataFrame:
    """The rows of ``passmd drive show`` (:func:`passmd.model.drive_file.parameter_rows`), each value in
    its display unit."""
    rows = []
    for row in parameter_rows(drive, sources):
        value, unit = row["value"], row["display_unit"]
        if isinstance(value, list):  # contact groups
            shown = "; ".join(_group_text(g) for g in value) or "–"
        elif isinstance(value, bool):
            shown = str(value).lower()
        elif isinstance(value, str):
            shown = value
        else:
            shown = f"{float(from_si(value, unit)) if unit else value:.4g}"
        rows.append({"key": row["key"], "symbol": row["symbol"], "value": shown, "unit": unit,
                     "source": row["source"]})
    return pd.DataFrame(rows)


def _group_text(group: dict) -> str:
    """A drive file's contact group in words: ``2 at 45° (side 1), R = 0.5 mm, F_N/F_p = 0.5``."""
    text = f"{group['count']} at {math.degrees(group['contact_angle']):.4g}°"
    text += f" (side {group['side']})" if "side" in group else ""
    text += f", R = {group['radius'] * 1e3:.4g} mm" if "radius" in group else ""
    text += f", F_N/F_p = {group['load_share']:.4g}" if "load_share" in group else ""
    return text + (f", F_N = {group['normal_force']:.4g} N" if "normal_force" in group else "")


def run_config(config: RunConfig | None, profile: str) -> RunConfig:
    """The run configuration of the chapter's sweeps on ``profile`` (:data:`PROFILE_SETTINGS`)."""
    return _run_config(config, profile)


def contact_table(drive: Drive) -> pd.DataFrame:
    """Each contact group of ``drive`` as ``passmd drive show`` lists it: side, count, contact angle,
    radius, normal force per contact and where it comes from (given, or Eq. 1's balance)."""
    rows = contact_arrangement(drive)
    return pd.DataFrame({
        "side": [r["side"] for r in rows], "contacts": [r["count"] for r in rows],
        "contact angle α [°]": [math.degrees(r["contact_angle_rad"]) for r in rows],
        "R [mm]": [r["radius_m"] * 1e3 for r in rows],
        "F_N per contact [N]": [r["normal_force_N"] for r in rows],
        "n F_N sin α [N]": [r["preload_share_N"] for r in rows],
        "F_N from": [{"Eq. 1": "F_p / (n sin α), Eq. 1", "load_share": "given share of F_p",
                      "normal_force": "given"}[r["force_from"]] for r in rows]})


def preload_points(drive: Drive, profile: str) -> list[dict]:
    """The points of A_c against preload at Section 4.1's frequency (``passmd sweep
    critical-amplitude --vary preload=...``)."""
    return [{"drive": replace(drive, preload=float(p)), "frequency": PROTOCOL.drive_frequency,
             "preload_N": float(p)} for p in _settings(profile).preloads]


def curve_from_maps(steady: pd.DataFrame, first: pd.DataFrame) -> pd.DataFrame:
    """A_c against preload from the two ``critical-amplitude`` maps (readings ``steady``, ``first``).

    Columns (nm, N, Hz): ``preload_N``, ``closed_form_nm``, ``steady_nm``, ``first_nm``, and the
    runner's ringing at the steady A_c (:func:`passmd.protocols.ringing.at_frequency`):
    ``ringing_frequency_Hz``, ``ringing_amplitude_nm``, ``ringing_left_nm`` (at the next fly-back),
    ``ringing_affects``.
    """
    def nm(values):
        return [math.nan if v is None else float(v) * 1e9 for v in values]

    return pd.DataFrame({
        "preload_N": steady["preload_N"].to_numpy(float),
        "closed_form_nm": steady["analytic_critical_amplitude_m"].to_numpy(float) * 1e9,
        "steady_nm": nm(steady["critical_amplitude_m"]), "first_nm": nm(first["critical_amplitude_m"]),
        "ringing_frequency_Hz": steady["ringing_frequency_Hz"].to_numpy(float),
        "ringing_amplitude_nm": nm(steady["ringing_amplitude_m"]),
        "ringing_left_nm": nm(steady["ringing_at_next_flyback_m"]),
        "ringing_affects": steady["ringing_affects_steps"].astype(bool).to_numpy()})


def critical_amplitude_curve(drive: Drive, profile: str, config: RunConfig | None = None) -> pd.DataFrame:
    """A_c against preload at Section 4.1's frequency: the closed form (Eqs. 7–8, 11–12) and the
    two simulated readings (``steady``, ``first``), as ``passmd sweep critical-amplitude``
    (:func:`curve_from_maps`)."""
    config = _run_config(config, profile)
    points = preload_points(drive, profile)
    steady, first = (compute_map("critical-amplitude", points, reading=reading, config=config,
                                 description=f"A_c ({reading}) against preload")
                     for reading in ("steady", "first"))
    return curve_from_maps(steady, first)


def map_axes(drive: Drive, profile: str) -> tuple[np.ndarray, np.ndarray]:
    """The maps' frequencies (log-spaced, Hz) and amplitudes (linear up to the full stroke, m)."""
    s = _settings(profile)
    return (np.geomspace(*MAP_FREQUENCY_RANGE, s.map_frequencies),
            np.linspace(MAP_AMPLITUDE_LOW, drive.actuator.full_stroke_amplitude, s.map_amplitudes))


def map_points(drive: Drive, profile: str) -> list[dict]:
    """The frequency × amplitude grid of the maps (frequency the x axis, amplitude fastest), with
    the columns ``passmd sweep --vary frequency=... --vary amplitude=...`` writes."""
    frequencies, amplitudes = map_axes(drive, profile)
    return [{"drive": drive, "frequency": float(f), "amplitude": float(a), "frequency_Hz": float(f),
             "amplitude_m": float(a)} for f in frequencies for a in amplitudes]


def step_velocity_map(drive: Drive, profile: str, config: RunConfig | None = None) -> pd.DataFrame:
    """Steady velocity, step and back-step of the saw-tooth over the map grid (``passmd sweep velocity``)."""
    return compute_map("velocity", map_points(drive, profile), config=_run_config(config, profile),
                       description="step/velocity map")


def gain_map(drive: Drive, profile: str, config: RunConfig | None = None) -> pd.DataFrame:
    """Eq. 15 waveform's steady velocity minus the saw-tooth's over the map grid (``passmd sweep gain``)."""
    return compute_map("gain", map_points(drive, profile), config=_run_config(config, profile),
                       description="Eq. 15 gain map")


def stall_points(drive: Drive, profile: str) -> list[dict]:
    """The stall-force points at Section 4.2's frequency: the profile's preloads × amplitudes
    (fractions of the full stroke), the runner against the load cell."""
    s = _settings(profile)
    a_max = drive.actuator.full_stroke_amplitude
    return [{"drive": replace(drive, preload=float(p), load_cell=True), "frequency": PROTOCOL.drive_frequency,
             "amplitude": float(x * a_max), "preload_N": float(p)}
            for p in s.stall_preloads for x in s.stall_fractions]


def stall_force_curve(drive: Drive, profile: str, config: RunConfig | None = None) -> pd.DataFrame:
    """Generated force at stall against the amplitude at Section 4.2's frequency, per preload
    (``passmd sweep stall-force``), with the Coulomb bound μ·ΣF_N of each preload (:func:`stall_frame`)."""
    points = stall_points(drive, profile)
    table = compute_map("stall-force", points, config=_run_config(config, profile), description="stall force")
    return stall_frame(points, table)


def stall_frame(points: list[dict], table: pd.DataFrame) -> pd.DataFrame:
    """The stall-force map of :func:`stall_points` as the chapter draws it.

    Columns: ``preload_N``, ``amplitude_nm``, ``force_mN``, ``converged``, ``periods``, ``bound_mN``.
    """
    return pd.DataFrame({
        "preload_N": table["preload_N"],
        "amplitude_nm": [p["amplitude"] * 1e9 for p in points],
        "force_mN": table["generated_force_N"].to_numpy(float) * 1e3,
        "converged": table["converged"].astype(bool),
        "periods": table["periods"],
        "bound_mN": [stall.coulomb_bound(p["drive"]) * 1e3 for p in points],
    })


#: The chapter's rows of the figure table: none (see the module's docstring).
FIGURES = ()
