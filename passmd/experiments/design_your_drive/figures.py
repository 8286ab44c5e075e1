"""The worked example of the chapter "Design your own drive": a drive that is not the paper's.

The drive is a drive file shipped with the package (:data:`EXAMPLE_DRIVE_FILE`), read as
``passmd --drive FILE`` reads it. Every figure's data comes from the functions a designer
calls: :func:`passmd.protocols.maps.compute_map` (what ``passmd sweep`` runs) for the
critical amplitude, the step and velocity map, the Eq. 15 gain map and the stall force,
:func:`passmd.protocols.ringing.stick_ringing` for the ringing, and
:func:`passmd.protocols.fit.estimator.fit` (what ``passmd fit`` runs) for the calibration. The grids
of each profile are in :data:`PROFILE_SETTINGS`; the calibration's settings are here
(:data:`NOISE_NM`, :data:`SEED`, :data:`START`, each profile's free parameters and points).

:data:`FIGURES` holds a row per figure the chapter shows, each computed on the example drive at the
configuration's profile (the sweep cache serves the page's own runs); the ledger computes none of
them (no claim requires them). What the chapter quotes of each figure is
:mod:`passmd.experiments.design_your_drive.facts`.
"""

from __future__ import annotations

import math
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd

from passmd.experiments import FigureSpec
from passmd.model import drive_file
from passmd.model.defaults import PROTOCOL
from passmd.model.drive_file import load_drive, parameter_rows, read_drive_file, resolve
from passmd.model.parameters import Drive
from passmd.model.tables import actuator_for_radius
from passmd.model.theory import contact_arrangement
from passmd.protocols import fit, ringing, stall
from passmd.protocols.maps import compute_map
from passmd.protocols.synthetic import independent_steps
from passmd.runtime.config import PROFILES, RunConfig
from passmd.runtime.units import from_si
from passmd.runtime.validation import check_choice

__all__ = [
    "EXAMPLE_DRIVE_FILE", "FIGURES", "HELDBACK_LABELS", "NOISE_NM", "PROFILE_SETTINGS", "SEED", "START",
    "ProfileSettings", "calibrate", "contact_table", "critical_amplitude_curve", "curve_from_maps",
    "example_drive", "gain_map", "heldback_predictions", "load_fitted", "map_axes", "map_points",
    "parameter_table", "preload_points", "profile_of", "ringing_frame", "run_config", "stall_force_curve",
    "stall_frame", "stall_points", "start_drive", "step_velocity_map", "synthetic_measurements",
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


def run_config(config: RunConfig | None, profile: str) -> RunConfig:
    """The run configuration of the chapter's sweeps on ``profile``: ``config`` with the profile's
    executor (:data:`PROFILE_SETTINGS`) where it names none (an explicit choice wins)."""
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
        elif isinstance(value, str):  # a choice or a rule ("slew"): no unit
            shown, unit = value, ""
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


def curve_from_maps(steady: pd.DataFrame, first: pd.DataFrame, full_stroke: float) -> pd.DataFrame:
    """A_c against preload from the two ``critical-amplitude`` maps (readings ``steady``, ``first``),
    with the actuator's ``full_stroke`` (m) as ``attrs["full_stroke_nm"]``.

    Columns (nm, N, Hz): ``preload_N``, ``closed_form_nm``, ``steady_nm``, ``first_nm``, and the
    runner's ringing at the steady A_c (:func:`passmd.protocols.ringing.at_frequency`):
    ``ringing_frequency_Hz``, ``ringing_amplitude_nm``, ``ringing_left_nm`` (at the next fly-back),
    ``ringing_affects``.
    """
    def nm(values):
        return [math.nan if v is None else float(v) * 1e9 for v in values]

    curve = pd.DataFrame({
        "preload_N": steady["preload_N"].to_numpy(float),
        "closed_form_nm": steady["analytic_critical_amplitude_m"].to_numpy(float) * 1e9,
        "steady_nm": nm(steady["critical_amplitude_m"]), "first_nm": nm(first["critical_amplitude_m"]),
        "ringing_frequency_Hz": steady["ringing_frequency_Hz"].to_numpy(float),
        "ringing_amplitude_nm": nm(steady["ringing_amplitude_m"]),
        "ringing_left_nm": nm(steady["ringing_at_next_flyback_m"]),
        "ringing_affects": steady["ringing_affects_steps"].astype(bool).to_numpy()})
    curve.attrs["full_stroke_nm"] = full_stroke * 1e9
    return curve


def critical_amplitude_curve(drive: Drive, profile: str, config: RunConfig | None = None) -> pd.DataFrame:
    """A_c against preload at Section 4.1's frequency: the closed form (Eqs. 7–8, 11–12) and the
    two simulated readings (``steady``, ``first``), as ``passmd sweep critical-amplitude``
    (:func:`curve_from_maps`)."""
    config = run_config(config, profile)
    points = preload_points(drive, profile)
    steady, first = (compute_map("critical-amplitude", points, reading=reading, config=config,
                                 description=f"A_c ({reading}) against preload")
                     for reading in ("steady", "first"))
    return curve_from_maps(steady, first, drive.actuator.full_stroke_amplitude)


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
    return compute_map("velocity", map_points(drive, profile), config=run_config(config, profile),
                       description="step/velocity map")


def gain_map(drive: Drive, profile: str, config: RunConfig | None = None) -> pd.DataFrame:
    """Eq. 15 waveform's steady velocity minus the saw-tooth's over the map grid (``passmd sweep gain``)."""
    return compute_map("gain", map_points(drive, profile), config=run_config(config, profile),
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
    table = compute_map("stall-force", points, config=run_config(config, profile), description="stall force")
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


def ringing_frame(probe: dict) -> pd.DataFrame:
    """The swing of a :func:`~passmd.protocols.ringing.stick_ringing` probe against the time since the
    fly-back (``swing_times_s``, ``swing_amplitudes_m``); ``attrs``: its ``ringing_frequency_Hz`` and
    ``flyback_time_s``, the measurable step (``measurable_m``) and the drive frequencies whose next
    fly-back the chapter marks (``next_flyback_Hz``: Section 4.1's and 1 kHz)."""
    frame = pd.DataFrame({key: np.asarray(probe[key]) for key in ("swing_times_s", "swing_amplitudes_m")})
    frame.attrs.update(ringing_frequency_Hz=probe["ringing_frequency_Hz"], measurable_m=ringing.MEASURABLE,
                       flyback_time_s=probe["flyback_time_s"],
                       next_flyback_Hz=(PROTOCOL.drive_frequency, 1e3))
    return frame


def start_drive(truth: Drive, free: Sequence[str]) -> Drive:
    """A designer's first guess: ``truth`` with each parameter named in ``free`` at the paper's value
    (μ of Table 1; k_p of Table 2 for the drive's radius, c_p kept)."""
    drive = truth
    for name in free:
        if name == "friction_coefficient":
            drive = replace(drive, friction_coefficient=Drive().friction_coefficient)
        elif name == "actuator.stiffness":
            table2 = actuator_for_radius(truth.hemisphere_radius).stiffness
            drive = fit.FREE_PARAMETERS[name].set(drive, table2, truth)
        else:
            raise ValueError(f"free = {name!r}: the example's first guess knows friction_coefficient and "
                             "actuator.stiffness")
    return drive


def _measurements(points, truth: Drive, rng, config, flyback=None) -> fit.Measurements:
    """Steps at (frequency, preload, amplitude nm) points:
    :func:`~passmd.protocols.synthetic.independent_steps` below 1 kHz (the
    steady-velocity protocol's step above, as a stand measures it there) plus noise of NOISE_NM."""
    header = ["amplitude_nm", "preload_N", "frequency_Hz", "step_nm", "step_nm_sd"]
    rows = [[repr(float(a)), repr(float(p)), repr(float(f)), "0", repr(NOISE_NM)] for f, p, a in points]
    data = fit.measurements_from_rows(header, rows, name="synthetic measurements")
    low = [i for i, (f, _, _) in enumerate(points) if f < 1e3]
    exact = np.array(fit.predict(truth, data, config=config))  # the steady-velocity protocol above 1 kHz
    if low:
        conditions = [(points[i][1], points[i][2] * 1e-9, points[i][0]) for i in low]
        exact[low] = independent_steps(truth, conditions, flyback=flyback, config=config, executor=None,
                                       cache=True)
    return replace(data, value=exact + rng.normal(0.0, NOISE_NM * 1e-9, exact.size))


def synthetic_measurements(truth: Drive, profile: str, config: RunConfig | None = None, flyback=None
                           ) -> tuple[fit.Measurements, fit.Measurements]:
    """Steps of ``truth`` made independently of the fit's forward model
    (:func:`~passmd.protocols.synthetic.independent_steps`), plus Gaussian noise of
    NOISE_NM (seed SEED): ``(fit data, held-back data)``; ``flyback`` overrides the drive's fly-back
    rule in the data (a mis-specified model)."""
    s = PROFILE_SETTINGS[profile]
    config = run_config(config, profile)
    rng = np.random.default_rng(SEED)
    fit_points = [(FIT_FREQUENCY, p, a) for p in s.fit_preloads for a in s.fit_amplitudes_nm]
    return (_measurements(fit_points, truth, rng, config, flyback),
            _measurements(s.heldback, truth, rng, config, flyback))


def calibrate(start: Drive, data: fit.Measurements, profile: str,
              config: RunConfig | None = None) -> fit.FitResult:
    """The fit of the profile's free parameters to ``data`` from ``start`` (``passmd fit``'s defaults)."""
    return fit.fit(start, data, list(PROFILE_SETTINGS[profile].free), config=run_config(config, profile))


def load_fitted(text: str) -> Drive:
    """The drive a drive file's text describes, read as ``--drive`` reads a file
    (:func:`passmd.model.drive_file.load_drive`)."""
    with tempfile.TemporaryDirectory(prefix="passmd-design-") as folder:
        path = Path(folder) / "fitted-drive.toml"
        path.write_text(text, encoding="utf-8")
        return load_drive(path)


def heldback_predictions(heldback: fit.Measurements, drives: dict[str, Drive], profile: str,
                         config: RunConfig | None = None) -> pd.DataFrame:
    """The held-back measurements and each drive's prediction of them (nm), one row per point.

    ``drives``: label -> drive (e.g. the first guess and the fitted drive); a column
    ``<label>_nm`` each, and the legend text of each in ``attrs["labels"]`` (:data:`HELDBACK_LABELS`).
    """
    out = pd.DataFrame({"frequency_Hz": heldback.frequency, "preload_N": heldback.preload,
                        "amplitude_nm": heldback.amplitude * 1e9, "measured_nm": heldback.value * 1e9,
                        "sd_nm": heldback.sd * 1e9})
    config = run_config(config, profile)
    for label, drive in drives.items():
        out[f"{label}_nm"] = fit.predict(drive, heldback, config=config) * 1e9
    out.attrs["labels"] = {label: HELDBACK_LABELS.get(label, label) for label in drives}
    return out


def profile_of(result: fit.FitResult, truth: Drive) -> pd.DataFrame:
    """The profile of the last free parameter of ``result``
    (:meth:`~passmd.protocols.fit.result.FitResult.profile_table`) with the value ``truth`` has."""
    name = result.names[-1]
    table = result.profile_table(name)
    table.attrs["truth"] = fit.FREE_PARAMETERS[name].get(truth)
    return table


#: Legend text of the held-back predictions, by drive label (:func:`heldback_predictions`).
HELDBACK_LABELS = {"start": "first guess (paper's values)", "fitted": "fitted drive file"}


def _calibration(config: RunConfig) -> tuple[fit.FitResult, Drive, pd.DataFrame]:
    """The chapter's calibration on ``config.profile``: the fit from the first guess (of the measurements
    as ``passmd fit`` reads them from their file: the amplitudes pass through nm), the example drive
    that made the data, and the held-back measurements with each drive's prediction."""
    truth, sources = example_drive()
    start = start_drive(truth, _settings(config.profile).free)
    data, heldback = synthetic_measurements(truth, config.profile, config)
    with tempfile.TemporaryDirectory(prefix="passmd-design-") as folder:  # read back as the page reads it
        path = Path(folder) / "design_measurements.csv"
        fit.write_measurements(path, data)
        result = calibrate(start, fit.read_measurements(path), config.profile, config)
    fitted = load_fitted(fit.fitted_drive_file(result, "design_measurements.csv", sources))
    return result, truth, heldback_predictions(heldback, {"start": start, "fitted": fitted}, config.profile,
                                               config)


def _no_drive(table: pd.DataFrame) -> pd.DataFrame:
    return table.drop(columns=["drive"], errors="ignore")


def _example() -> Drive:
    return example_drive()[0]


def _ringing(config: RunConfig) -> pd.DataFrame:
    drive = _example()
    return ringing_frame(ringing.stick_ringing(drive, drive.actuator.full_stroke_amplitude,
                                               frequency=PROTOCOL.drive_frequency))


def _example_row(name: str, title: str, compute, plot: str) -> FigureSpec:
    return FigureSpec(name, title, "design_your_drive", compute, plot)


#: The chapter's rows of the figure table: every figure it shows, on the example drive.
FIGURES = (
    _example_row("design_critical_amplitude", "Example drive: A_c against preload, closed form and the two "
                 "simulated readings", lambda c: critical_amplitude_curve(_example(), c.profile, c),
                 "design:critical_amplitude_figure"),
    _example_row("design_ringing", "Example drive: the runner's swing after a fly-back against time",
                 _ringing, "design:ringing_figure"),
    _example_row("design_step_map", "Example drive: steady step of the saw-tooth over frequency × amplitude",
                 lambda c: _no_drive(step_velocity_map(_example(), c.profile, c)), "design:step_map_figure"),
    _example_row("design_velocity_map", "Example drive: steady velocity of the saw-tooth over frequency × "
                 "amplitude", lambda c: _no_drive(step_velocity_map(_example(), c.profile, c)),
                 "design:velocity_map_figure"),
    _example_row("design_gain_map", "Example drive: Eq. 15 waveform's steady velocity minus the saw-tooth's",
                 lambda c: _no_drive(gain_map(_example(), c.profile, c)), "design:gain_map_figure"),
    _example_row("design_stall_force", "Example drive: stall force against amplitude, with μ·ΣF_N",
                 lambda c: stall_force_curve(_example(), c.profile, c), "design:stall_force_figure"),
    _example_row("design_fit", "Example drive's calibration: synthetic steps against the fitted model",
                 lambda c: _calibration(c)[0].residual_table(), "fit:fit_figure"),
    _example_row("design_profile", "Example drive's calibration: the profile of the last free parameter",
                 lambda c: profile_of(*_calibration(c)[:2]),
                 "fit:profile_figure"),
    _example_row("design_heldback", "Example drive: held-back steps against the first guess and the fitted "
                 "drive", lambda c: _calibration(c)[2], "design:heldback_figure"),
)
