"""Force generation against the load cell: Fig. 7 (Section 4.2).

The runner starts at rest, touching the load cell (a linear spring k, Table 1) at its free
length, with virgin contacts, and is driven by a saw-tooth until its steps stall: the load
cell then pushes back, on average over a period, as hard as the contacts carry the runner
forward. The force at stall is the *generated force* F_gen = k·x̄_r, x̄_r the runner's mean
position over the last period (:attr:`passmd.dynamics.SimulationResult.generated_force`).
By momentum balance over a periodic (stalled) cycle it equals the mean total friction
force on the runner; the tests check that.

Stall criterion (registered assumption ``force_stall_criterion``)
    F_n is k times the runner's mean position over period n. Near stall each step is a
    fixed fraction of the previous one (the step shrinks in proportion to the force still
    missing), so F_n approaches its limit geometrically. With D₁ and D₂ the changes of F
    over the two halves of the last :data:`STALL_WINDOW` periods, the rise still to come
    is estimated as the geometric tail D₂·r/(1 − r), r = D₂/D₁; the run has stalled when
    that tail and the spread of F over the window are both below the tolerance
    max(:data:`STALL_ABS_TOLERANCE`, :data:`STALL_REL_TOLERANCE`·F). A run that has not
    stalled is repeated from rest with more periods (predicted from the geometric rate),
    up to :data:`MAX_PERIODS`; if it still has not stalled the point is returned with
    ``converged = False``, drawn as such and never used by the ledger.

Onset of force generation
    The runner generates force only if it steps at all from the free length, so the onset
    is the critical amplitude of the drive with the load cell engaged, found exactly as in
    the critical-amplitude chapters (:func:`passmd.experiments.critical_amplitude.critical_amplitude`,
    steady-state protocol at the same frequency).

Figures (registered in :mod:`passmd.experiments`): ``fig7a`` (R = 1 mm, 0.3 and 0.8 N),
``fig7b`` (R = 0.25 mm, 0.2 and 0.4 N), each with the earlier model (rigid actuators,
μ = 0.3, [12]) and this paper's (flexible, μ = 0.2); ``fig7grid`` (every preload of both
radii); ``fig7freq`` (F_gen against the drive frequency) and ``fig7cycle`` (one period at
stall, rigid/flexible × μ = 0.2/0.3, the physics of the difference).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import pandas as pd

from passmd import dynamics, sweep, waveforms
from passmd._validation import check_choice, check_positive, check_range
from passmd.config import PROFILES
from passmd.ledger import ClaimFails, NotEvaluable, register_evidence, register_extractor
from passmd.parameters import PRELOAD_GRIDS, Assumption, Drive, paper_drive
from passmd.protocols.critical_amplitude import critical_amplitude
from passmd.theory import drive_theory, normal_forces

__all__ = [
    "CYCLE_COMBINATIONS",
    "FORCE_FREQUENCY",
    "MAX_PERIODS",
    "MODELS",
    "PANELS",
    "PANELS_FULL_STROKE_NM",
    "PROFILE_SETTINGS",
    "STALL_ABS_TOLERANCE",
    "STALL_REL_TOLERANCE",
    "STALL_WINDOW",
    "cycle_point",
    "fig7a",
    "fig7b",
    "fig7cycle",
    "fig7freq",
    "fig7grid",
    "force_difference",
    "force_drive",
    "force_onset",
    "generated_force",
    "onset_point",
    "stall_cycle",
    "stall_estimate",
    "stall_point",
]

#: Saw-tooth frequency of every force run (Hz): Section 5.2's 100 Hz (Fig. 9a), as in the
#: critical-amplitude chapters (assumption ``force_frequency``).
FORCE_FREQUENCY = 100.0
#: Periods over which the stall criterion looks at the force (two halves of 8).
STALL_WINDOW = 16
#: Absolute stall tolerance on the remaining rise and on the spread of F_gen (N).
STALL_ABS_TOLERANCE = 0.2e-3
#: Relative stall tolerance (fraction of F_gen).
STALL_REL_TOLERANCE = 2e-3
#: Periods of the first run of a point.
INITIAL_PERIODS = 64
#: Most periods a point may take.
MAX_PERIODS = 4096
#: Width of the final bracket of the onset (critical-amplitude) search (m).
ONSET_TOLERANCE = {"quick": 0.5e-9, "paper": 0.2e-9}

#: (actuator model, μ, label): the earlier model of [12] and this paper's.
MODELS = (
    ("rigid", 0.3, "rigid actuators, μ = 0.3 (earlier work [12])"),
    ("flexible", 0.2, "flexible actuators, μ = 0.2 (this paper)"),
)
#: Fig. 7 panels: hemisphere radius (m) and the preloads shown (N).
PANELS = {"fig7a": (1.0e-3, (0.3, 0.8)), "fig7b": (0.25e-3, (0.2, 0.4))}
#: Full stroke A_max of each panel's radius (nm), the amplitude of the 115 mN claim for fig7a.
PANELS_FULL_STROKE_NM = {name: paper_drive(r).actuator.full_stroke_amplitude * 1e9
                         for name, (r, _) in PANELS.items()}


@dataclass(frozen=True)
class ProfileSettings:
    """What a profile computes."""

    panel_fractions: tuple  # amplitudes of the Fig. 7 panels, as fractions of A_max
    grid_fractions: tuple  # amplitudes of the full preload grid (fractions of A_max)
    grid_preloads: dict  # radius -> preloads of the full grid
    frequencies: tuple  # drive frequencies of the sensitivity panel (Hz)
    cycle_samples: int  # recorded samples per period of the stall-cycle runs
    cycle_preload: float  # preload of the stall-cycle runs (N), R = 1 mm, full stroke


PROFILE_SETTINGS = {
    "quick": ProfileSettings(
        panel_fractions=(0.0, 0.2, 0.7, 1.0),
        grid_fractions=(1.0,),
        grid_preloads={1.0e-3: (0.1, 0.3, 0.8), 0.25e-3: (0.2, 0.4)},
        frequencies=(FORCE_FREQUENCY, 1000.0),
        cycle_samples=1000,
        cycle_preload=0.8,
    ),
    "paper": ProfileSettings(
        panel_fractions=tuple(i / 10 for i in range(11)),
        grid_fractions=(0.5, 1.0),
        grid_preloads={r: tuple(float(p) for p in grid) for r, grid in PRELOAD_GRIDS.items()},
        frequencies=(90.0, 100.0, 110.0, 200.0, 500.0, 900.0, 1000.0, 1100.0),
        cycle_samples=2000,
        cycle_preload=0.8,
    ),
}

ASSUMPTIONS: tuple[Assumption, ...] = (
    Assumption(
        key="force_frequency",
        symbol="f",
        value=f"{FORCE_FREQUENCY:g}",
        unit="Hz",
        rationale=(
            "Section 4.2 does not state the saw-tooth frequency of the force runs. 100 Hz is the "
            "frequency Section 5.2 uses (Fig. 9a) and the critical-amplitude chapters use, so the onset "
            "of force generation is their critical amplitude. After each fly-back the runner rings on "
            "its contacts (about 10 kHz) with only micro-slip to damp it; at 100 Hz the ringing has "
            "mostly died out before the next fly-back, at 1 kHz it has not and the stall force scatters "
            "several times more from one frequency to the next."
        ),
        sensitivity="Force chapter: F_gen at full amplitude from 90 Hz to 1.1 kHz (fig7freq).",
    ),
    Assumption(
        key="force_stall_criterion",
        symbol="F_gen",
        value=(
            f"k·x̄_r over the last period, once the geometric tail of its rise and its spread over the "
            f"last {STALL_WINDOW} periods are below max({STALL_ABS_TOLERANCE * 1e3:g} mN, "
            f"{STALL_REL_TOLERANCE:.1%}·F_gen); at most {MAX_PERIODS} periods"
        ),
        unit="N",
        rationale=(
            "Section 4.2 does not say when a simulated force was read. The runner starts at rest at "
            "the load cell's free length and steps until the load stops it; near stall the force "
            "approaches its limit geometrically, so the tail left is estimated from two half-windows "
            "rather than read from the last step alone, which would stop early when the approach is "
            "slow. The tolerance is far below the force's own scatter with the drive frequency."
        ),
        sensitivity="Force chapter: periods used and the estimated remaining rise of every point.",
    ),
    Assumption(
        key="force_onset",
        symbol="A_c (load cell)",
        value="critical amplitude of the drive with the load cell engaged (steady-state protocol)",
        unit="nm",
        rationale=(
            "A runner that makes no step from the free length never loads the cell, and one that "
            "does keeps stepping until stall, so force generation starts at the critical amplitude; "
            "it is found with the critical-amplitude chapters' protocol, load cell engaged."
        ),
        sensitivity="Force chapter: F_gen just below the onset is the load cell following the piezo.",
    ),
)


def stall_estimate(forces, window: int = STALL_WINDOW) -> dict:
    """Remaining rise and spread of a per-period force series (the stall criterion).

    Parameters
    ----------
    forces : array_like
        F_n, one value per period (N).
    window : int
        Number of last periods examined (even, >= 4).

    Returns
    -------
    dict
        ``remaining_N``: estimated rise still to come (``inf`` while the force grows at
        an undiminished rate); ``spread_N``: max − min over the window; ``ratio``:
        D₂/D₁ of the two half-windows (nan when undefined).
    """
    f = np.asarray(forces, dtype=float)
    if int(window) != window or window < 4 or window % 2:
        raise ValueError(f"window = {window!r} is out of range: must be an even integer >= 4")
    if f.ndim != 1 or f.size < window + 1:
        return {"remaining_N": math.inf, "spread_N": math.inf, "ratio": math.nan}
    half = window // 2
    d1 = f[-1 - half] - f[-1 - window]
    d2 = f[-1] - f[-1 - half]
    spread = float(np.ptp(f[-1 - window :]))
    if d2 == 0.0:
        return {"remaining_N": 0.0, "spread_N": spread, "ratio": 0.0 if d1 != 0 else math.nan}
    if d1 == 0.0:
        return {"remaining_N": math.inf, "spread_N": spread, "ratio": math.nan}
    ratio = d2 / d1
    if ratio < 0:  # oscillating about the stall level: bounded by the last swing
        remaining = max(abs(d1), abs(d2))
    elif ratio < 1:  # geometric approach
        remaining = abs(d2) * ratio / (1.0 - ratio)
    else:  # not slowing down
        remaining = math.inf
    return {"remaining_N": float(remaining), "spread_N": spread, "ratio": float(ratio)}


def _stalled(estimate: dict, force: float, abs_tol: float, rel_tol: float) -> bool:
    tol = max(abs_tol, rel_tol * abs(force))
    return estimate["remaining_N"] <= tol and estimate["spread_N"] <= tol


def _next_periods(periods: int, estimate: dict, force: float, window: int, abs_tol: float, rel_tol: float,
                  max_periods: int) -> int:
    """Periods of the next (longer) run from rest.

    In the geometric approach the per-period factor q = r^(1/half) predicts how many more
    periods bring the remaining rise below half the tolerance; the next run asks for that
    with a 25 % margin, at least 1.5× and at most 4× the current run. Before the approach
    is geometric (the force still rises at an undiminished rate) the run is doubled.
    """
    ratio = estimate["ratio"]
    if 0.0 < ratio < 1.0 and math.isfinite(estimate["remaining_N"]) and estimate["remaining_N"] > 0:
        q = ratio ** (1.0 / (window // 2))
        tol = max(abs_tol, rel_tol * abs(force))
        more = math.log(0.5 * tol / estimate["remaining_N"]) / math.log(q)
        wanted = math.ceil(1.25 * (periods + max(more, 0.0)))
        wanted = min(max(wanted, math.ceil(1.5 * periods)), 4 * periods)
    else:
        wanted = 2 * periods
    return int(min(max_periods, window * math.ceil(wanted / window)))


def generated_force(
    drive: Drive,
    amplitude: float,
    frequency: float,
    *,
    flyback: str = "slew",
    initial_periods: int = INITIAL_PERIODS,
    max_periods: int = MAX_PERIODS,
    abs_tolerance: float = STALL_ABS_TOLERANCE,
    rel_tolerance: float = STALL_REL_TOLERANCE,
    window: int = STALL_WINDOW,
) -> dict:
    """Generated force at stall: saw-tooth runs from rest against the load cell (Section 4.2).

    Parameters
    ----------
    drive : Drive
        The drive; the load cell is engaged whatever ``drive.load_cell`` says.
    amplitude : float
        Actuation amplitude A (m).
    frequency : float
        Driving frequency f (Hz).
    flyback : {"slew", "fixed"}
        Fly-back rule of :func:`passmd.waveforms.sawtooth`.
    initial_periods, max_periods : int
        Periods of the first run, doubled until stall or until ``max_periods``.
    abs_tolerance, rel_tolerance : float
        Stall tolerance max(abs, rel·F_gen) (N, fraction) on the remaining rise and the
        spread of the per-period force (see the module docstring).
    window : int
        Periods examined by the stall criterion.

    Returns
    -------
    dict
        SI values, keys carrying the unit: ``generated_force_N`` (k·x̄_r over the last
        period), ``converged`` (stall criterion met), ``periods`` (of the run reported),
        ``periods_simulated`` (all runs together), ``remaining_force_N`` (estimated rise
        still to come), ``force_spread_N`` (over the window), ``mean_friction_N`` (mean
        total friction on the runner over the last period), ``piezo_mean_force_N`` (k times
        the mean piezo position x̄_p, what the load cell reads if the runner only follows
        the piezo), ``last_step_m``, ``net_displacement_m`` (x̄_r − x̄_p over the last
        period), ``wall_time_s`` (integration time of all runs), ``cpu_time_s`` (CPU time of
        the whole call).

    Raises
    ------
    ValueError
        Bad input (names the parameter, its value and the allowed range).
    passmd.dynamics.SimulationError
        A run diverged.
    """
    cpu = time.process_time()
    if not isinstance(drive, Drive):
        raise ValueError(f"drive = {drive!r} is not a Drive")
    check_positive("frequency", frequency, "Hz")
    check_choice("flyback", flyback, ("slew", "fixed"))
    check_positive("abs_tolerance", abs_tolerance, "N")
    check_range("rel_tolerance", rel_tolerance, 0.0, 1.0, upper_open=True)
    for name, value in (("initial_periods", initial_periods), ("max_periods", max_periods)):
        if isinstance(value, bool) or int(value) != value or value < window + 1:
            raise ValueError(f"{name} = {value!r} is out of range: must be an integer >= {window + 1}")
    if max_periods < initial_periods:
        raise ValueError(f"max_periods = {max_periods!r} is out of range: must be >= initial_periods "
                         f"= {initial_periods!r}")
    drive = drive if drive.load_cell else drive.replace(load_cell=True)
    k = drive.load_cell_stiffness
    periods, simulated, wall = int(initial_periods), 0, 0.0
    while True:
        wave = waveforms.sawtooth(amplitude, frequency, drive, periods=periods, flyback=flyback)
        result = dynamics.simulate(drive, wave, max_points=2)
        simulated += periods
        wall += result.wall_time
        forces = k * result.period_mean_position
        estimate = stall_estimate(forces, window)
        converged = _stalled(estimate, float(forces[-1]), abs_tolerance, rel_tolerance)
        if converged or periods >= max_periods:
            break
        periods = _next_periods(periods, estimate, float(forces[-1]), window, abs_tolerance, rel_tolerance,
                                int(max_periods))
    T = wave.period
    piezo_mean = float(np.mean(wave.position(np.linspace((periods - 1) * T, periods * T, 4001))))
    return {
        "generated_force_N": float(forces[-1]),
        "converged": bool(converged),
        "periods": int(periods),
        "periods_simulated": int(simulated),
        "remaining_force_N": estimate["remaining_N"],
        "force_spread_N": estimate["spread_N"],
        "mean_friction_N": float(result.period_mean_friction[-1]),
        "piezo_mean_force_N": k * piezo_mean,
        "last_step_m": float(result.step_sizes[-1]),
        "net_displacement_m": float(result.period_mean_position[-1] - piezo_mean),
        "wall_time_s": float(wall),
        "cpu_time_s": float(time.process_time() - cpu),
    }


def force_drive(
    hemisphere_radius: float, preload: float, actuator_model: str, friction_coefficient: float
) -> Drive:
    """The Fig. 7 drive: Tables 1–2, six contacts, load cell engaged (Section 4.2)."""
    return paper_drive(
        hemisphere_radius,
        preload,
        actuator_model=actuator_model,
        friction_coefficient=friction_coefficient,
        load_cell=True,
    )


def force_onset(drive: Drive, frequency: float = FORCE_FREQUENCY, tolerance: float = 0.2e-9) -> dict:
    """Onset of force generation: the critical amplitude with the load cell engaged (m).

    Calls :func:`passmd.experiments.critical_amplitude.critical_amplitude` (steady-state
    protocol) on ``drive`` with its load cell engaged. Returns its dict
    (``critical_amplitude_m`` — ``None`` if even the full stroke makes no step —,
    ``bracket_low_m``, ``bracket_high_m``, ``runs``, ``wall_time_s``).
    """
    if not isinstance(drive, Drive):
        raise ValueError(f"drive = {drive!r} is not a Drive")
    return critical_amplitude(drive if drive.load_cell else drive.replace(load_cell=True),
                              frequency=frequency, tolerance=tolerance)


# --------------------------------------------------------------------------------------
# Sweep point functions (top level, scalar keyword arguments: picklable and cacheable)
# --------------------------------------------------------------------------------------


def stall_point(
    hemisphere_radius: float,
    preload: float,
    actuator_model: str,
    friction_coefficient: float,
    amplitude_fraction: float,
    frequency: float,
) -> dict:
    """:func:`generated_force` of the Fig. 7 drive at ``amplitude_fraction`` × A_max."""
    drive = force_drive(hemisphere_radius, preload, actuator_model, friction_coefficient)
    fraction = check_range("amplitude_fraction", amplitude_fraction, 0.0, 1.0)
    amplitude = fraction * drive.actuator.full_stroke_amplitude
    out = generated_force(drive, amplitude, frequency)
    out["amplitude_m"] = amplitude
    return out


def onset_point(
    hemisphere_radius: float,
    preload: float,
    actuator_model: str,
    friction_coefficient: float,
    frequency: float,
    tolerance: float,
) -> dict:
    """:func:`force_onset` of the Fig. 7 drive, plus the closed form (Eq. 11 or 12) in m."""
    drive = force_drive(hemisphere_radius, preload, actuator_model, friction_coefficient)
    out = force_onset(drive, frequency, tolerance)
    if out["critical_amplitude_m"] is None:
        out["critical_amplitude_m"] = math.nan
    out["analytic_critical_amplitude_m"] = float(drive_theory(drive)["analytic_critical_amplitude_m"])
    return out


def stall_cycle(
    drive: Drive, amplitude: float, frequency: float, periods: int, samples_per_period: int = 2000
) -> dict:
    """One period at stall, from the fly-back that starts it: time series and measures.

    Runs ``periods`` saw-tooth periods from rest (the count :func:`generated_force` needed to
    stall) recording ``samples_per_period`` samples per period, and keeps the window from the
    fly-back of period ``periods − 1`` to that of the last period.

    Returns
    -------
    dict
        Arrays (SI) ``time_s`` (since the fly-back), ``piezo_m``, ``runner_m`` (x_r − x̄_r),
        ``load_cell_N`` (k·x_r), ``friction_N`` (total on the runner), and per contact group
        (side 1: two contacts at F_N1, side 2: four at F_N2) ``friction_side{1,2}_N``,
        ``deflection_side{1,2}_m`` (x_p − x_a), ``slip_share_side{1,2}``; scalars
        ``generated_force_N``, ``sliding_capacity_N`` (Σ μF_N), ``back_slide_m`` (largest
        backward excursion of the runner after the fly-back, from every integrator step),
        ``deflection_before_flyback_side{1,2}_m`` (x_p − x_a at the last sample before it),
        ``full_slip_time_s`` (time every contact slides, to the sample spacing),
        ``mean_slip_share_side{1,2}`` (over the period), ``sample_spacing_s``. The first
        sample is the last one before the fly-back (negative time).
    """
    if not isinstance(drive, Drive) or drive.contacts != 6:
        raise ValueError(f"drive = {drive!r} is not allowed: must be a six-contact Drive")
    if isinstance(periods, bool) or int(periods) != periods or periods < 2:
        raise ValueError(f"periods = {periods!r} is out of range: must be an integer >= 2")
    if isinstance(samples_per_period, bool) or int(samples_per_period) != samples_per_period \
            or samples_per_period < 100:
        raise ValueError(
            f"samples_per_period = {samples_per_period!r} is out of range: must be an integer >= 100"
        )
    drive = drive if drive.load_cell else drive.replace(load_cell=True)
    wave = waveforms.sawtooth(amplitude, frequency, drive, periods=int(periods))
    result = dynamics.simulate(drive, wave, max_points=int(periods) * int(samples_per_period) + 1)
    start, end = wave.slip_marks[-2], wave.slip_marks[-1]
    spacing = float(result.time[1] - result.time[0])
    first = int(np.searchsorted(result.time, start, side="right")) - 1  # last sample before the fly-back
    last = int(np.searchsorted(result.time, end, side="right"))
    sel = slice(first, last)
    t = result.time[sel] - start
    k = drive.load_cell_stiffness
    x_r = result.runner_position[sel]
    x_p = result.piezo_position[sel]
    n = result.multiplicity
    friction = result.friction_force[:, sel] * n[:, None]
    deflection = x_p[None, :] - result.actuator_position[:, sel]
    slip = result.slip_share[:, sel]
    forces = np.asarray(normal_forces(drive.preload, 6), dtype=float)
    capacity = float(drive.friction_coefficient * np.sum(n * forces))
    out = {
        "time_s": t,
        "piezo_m": x_p,
        "runner_m": x_r - float(np.mean(x_r[1:])),
        "load_cell_N": k * x_r,
        "friction_N": friction.sum(axis=0),
        "generated_force_N": float(result.generated_force),
        "sliding_capacity_N": capacity,
        "back_slide_m": float(result.back_steps[-2]),
        "full_slip_time_s": float(np.count_nonzero(np.all(slip[:, 1:] >= 1.0 - 1e-9, axis=0)) * spacing),
        "sample_spacing_s": spacing,
    }
    for g, side in enumerate(("side1", "side2")):
        out[f"friction_{side}_N"] = friction[g]
        out[f"deflection_{side}_m"] = deflection[g]
        out[f"slip_share_{side}"] = slip[g]
        out[f"deflection_before_flyback_{side}_m"] = float(deflection[g, 0])
        out[f"mean_slip_share_{side}"] = float(np.mean(slip[g, 1:]))
    return out


def cycle_point(
    hemisphere_radius: float,
    preload: float,
    actuator_model: str,
    friction_coefficient: float,
    amplitude_fraction: float,
    frequency: float,
    periods: int,
    samples_per_period: int,
) -> dict:
    """:func:`stall_cycle` of the Fig. 7 drive at ``amplitude_fraction`` × A_max."""
    drive = force_drive(hemisphere_radius, preload, actuator_model, friction_coefficient)
    fraction = check_range("amplitude_fraction", amplitude_fraction, 0.0, 1.0)
    return stall_cycle(drive, fraction * drive.actuator.full_stroke_amplitude, frequency, int(periods),
                       int(samples_per_period))


# --------------------------------------------------------------------------------------
# Figure data
# --------------------------------------------------------------------------------------


def _settings(profile: str) -> ProfileSettings:
    return PROFILE_SETTINGS[check_choice("profile", profile, PROFILES)]


def _stall_frame(points: list[dict], description: str) -> pd.DataFrame:
    """Stall runs through the sweep engine; tidy frame in display units (nm, mN)."""
    f = sweep.run(stall_point, points, description=description)
    labels = {(m, mu): label for m, mu, label in MODELS}
    return pd.DataFrame(
        {
            "radius_mm": f["hemisphere_radius"] * 1e3,
            "preload_N": f["preload"],
            "actuator_model": f["actuator_model"],
            "friction_coefficient": f["friction_coefficient"],
            "model": [labels.get((m, mu), f"{m} actuators, μ = {mu:g}")
                      for m, mu in zip(f["actuator_model"], f["friction_coefficient"], strict=True)],
            "frequency_Hz": f["frequency"],
            "amplitude_fraction": f["amplitude_fraction"],
            "amplitude_nm": f["amplitude_m"] * 1e9,
            "generated_force_mN": f["generated_force_N"] * 1e3,
            "converged": f["converged"].astype(bool),
            "periods": f["periods"].astype(int),
            "periods_simulated": f["periods_simulated"].astype(int),
            "remaining_force_mN": f["remaining_force_N"] * 1e3,
            "force_spread_mN": f["force_spread_N"] * 1e3,
            "mean_friction_mN": f["mean_friction_N"] * 1e3,
            "piezo_mean_force_mN": f["piezo_mean_force_N"] * 1e3,
            "net_displacement_nm": f["net_displacement_m"] * 1e9,
            "last_step_nm": f["last_step_m"] * 1e9,
            "cpu_time_s": f["cpu_time_s"],
        }
    )


def _onset_frame(curves: list[tuple], profile: str) -> pd.DataFrame:
    points = [
        {"hemisphere_radius": r, "preload": float(p), "actuator_model": m, "friction_coefficient": mu,
         "frequency": FORCE_FREQUENCY, "tolerance": ONSET_TOLERANCE[profile]}
        for r, p, m, mu in curves
    ]
    f = sweep.run(onset_point, points, description="fig7 onsets")
    return pd.DataFrame(
        {
            "radius_mm": f["hemisphere_radius"] * 1e3,
            "preload_N": f["preload"],
            "actuator_model": f["actuator_model"],
            "friction_coefficient": f["friction_coefficient"],
            "onset_nm": f["critical_amplitude_m"] * 1e9,
            "onset_low_nm": f["bracket_low_m"] * 1e9,
            "onset_high_nm": f["bracket_high_m"] * 1e9,
            "analytic_onset_nm": f["analytic_critical_amplitude_m"] * 1e9,
            "onset_cpu_time_s": f["wall_time_s"],
        }
    )


def _curves_frame(radius_preloads: dict, fractions, profile: str, panel: str) -> pd.DataFrame:
    """F_gen against amplitude for every (radius, preload, model), with each curve's onset."""
    curves = [(r, float(p), m, mu) for r, preloads in radius_preloads.items() for p in preloads
              for m, mu, _ in MODELS]
    points = [
        {"hemisphere_radius": r, "preload": p, "actuator_model": m, "friction_coefficient": mu,
         "amplitude_fraction": float(a), "frequency": FORCE_FREQUENCY}
        for r, p, m, mu in curves for a in fractions
    ]
    stalls = _stall_frame(points, panel)
    onsets = _onset_frame(curves, profile)
    keys = ["radius_mm", "preload_N", "actuator_model", "friction_coefficient"]
    frame = stalls.merge(onsets, on=keys, how="left", validate="many_to_one")
    frame.insert(0, "panel", panel)
    return frame


def _panel(name: str, profile: str) -> pd.DataFrame:
    radius, preloads = PANELS[name]
    return _curves_frame({radius: preloads}, _settings(profile).panel_fractions, profile, name)


def fig7a(profile: str = "paper") -> pd.DataFrame:
    """Fig. 7a: F_gen against A (0–202 nm), R = 1 mm, F_p = 0.3 and 0.8 N, both models (mN, nm)."""
    return _panel("fig7a", profile)


def fig7b(profile: str = "paper") -> pd.DataFrame:
    """Fig. 7b: F_gen against A (0–96 nm), R = 0.25 mm, F_p = 0.2 and 0.4 N, both models (mN, nm)."""
    return _panel("fig7b", profile)


def fig7grid(profile: str = "paper") -> pd.DataFrame:
    """F_gen against A for the full preload grids of both radii, both models, with onsets."""
    s = _settings(profile)
    return _curves_frame(s.grid_preloads, s.grid_fractions, profile, "grid")


def fig7freq(profile: str = "paper") -> pd.DataFrame:
    """F_gen at A_max against the saw-tooth frequency, each panel's higher preload, both models."""
    s = _settings(profile)
    points = [
        {"hemisphere_radius": radius, "preload": float(max(preloads)), "actuator_model": m,
         "friction_coefficient": mu, "amplitude_fraction": 1.0, "frequency": float(f)}
        for radius, preloads in PANELS.values() for m, mu, _ in MODELS for f in s.frequencies
    ]
    return _stall_frame(points, "fig7freq")


#: Actuator model × μ of the stall-cycle figure: the two models and the two crossings.
CYCLE_COMBINATIONS = (("rigid", 0.3), ("rigid", 0.2), ("flexible", 0.3), ("flexible", 0.2))
#: Radius (m) and amplitude fraction of the stall-cycle figure: Fig. 7a's drive at the full stroke
#: (the paper profile's preload, 0.8 N, is the one of the 115 mN claim).
CYCLE_DRIVE = (1.0e-3, 1.0)


def fig7cycle(profile: str = "paper") -> pd.DataFrame:
    """One stall period of the four actuator-model × μ combinations (tidy, one row per sample).

    Per-run measures (``generated_force_mN``, ``back_slide_nm``, ...) repeat on every row of
    their run.
    """
    s = _settings(profile)
    radius, fraction = CYCLE_DRIVE
    preload = s.cycle_preload
    base = {"hemisphere_radius": radius, "preload": preload, "amplitude_fraction": fraction,
            "frequency": FORCE_FREQUENCY}
    combos = [{**base, "actuator_model": m, "friction_coefficient": mu} for m, mu in CYCLE_COMBINATIONS]
    stalls = sweep.run(stall_point, combos, description="fig7cycle stall")
    if not stalls["converged"].all():
        bad = stalls.loc[~stalls["converged"], ["actuator_model", "friction_coefficient"]]
        raise RuntimeError(f"stall-cycle runs did not stall: {bad.to_dict('records')}")
    points = [{**c, "periods": int(p), "samples_per_period": s.cycle_samples}
              for c, p in zip(combos, stalls["periods"], strict=True)]
    cycles = sweep.run(cycle_point, points, description="fig7cycle")
    frames = []
    for (_, row), stall in zip(cycles.iterrows(), stalls.itertuples(), strict=True):
        n = len(row["time_s"])
        frame = {
            "actuator_model": [row["actuator_model"]] * n,
            "friction_coefficient": row["friction_coefficient"],
            "time_us": row["time_s"] * 1e6,
            "piezo_nm": row["piezo_m"] * 1e9,
            "runner_nm": row["runner_m"] * 1e9,
            "load_cell_mN": row["load_cell_N"] * 1e3,
            "friction_mN": row["friction_N"] * 1e3,
        }
        for side in ("side1", "side2"):
            frame[f"friction_{side}_mN"] = row[f"friction_{side}_N"] * 1e3
            frame[f"deflection_{side}_nm"] = row[f"deflection_{side}_m"] * 1e9
            frame[f"slip_share_{side}"] = row[f"slip_share_{side}"]
        for key, factor, name in (
            ("generated_force_N", 1e3, "generated_force_mN"),
            ("sliding_capacity_N", 1e3, "sliding_capacity_mN"),
            ("back_slide_m", 1e9, "back_slide_nm"),
            ("full_slip_time_s", 1e6, "full_slip_time_us"),
            ("sample_spacing_s", 1e6, "sample_spacing_us"),
            ("deflection_before_flyback_side1_m", 1e9, "deflection_before_flyback_side1_nm"),
            ("deflection_before_flyback_side2_m", 1e9, "deflection_before_flyback_side2_nm"),
            ("mean_slip_share_side1", 1.0, "mean_slip_share_side1"),
            ("mean_slip_share_side2", 1.0, "mean_slip_share_side2"),
        ):
            frame[name] = row[key] * factor
        frame["periods"] = int(stall.periods)
        frames.append(pd.DataFrame(frame))
    out = pd.concat(frames, ignore_index=True)
    out.insert(0, "amplitude_nm", float(stalls["amplitude_m"].iloc[0]) * 1e9)
    out.insert(0, "preload_N", preload)
    out.insert(0, "radius_mm", radius * 1e3)
    return out


# --------------------------------------------------------------------------------------
# Ledger extractors (claims.csv ids)
# --------------------------------------------------------------------------------------

_EARLIER, _THIS = (MODELS[0][0], MODELS[0][1]), (MODELS[1][0], MODELS[1][1])


def _model_rows(table: pd.DataFrame, model: tuple, preload: float) -> pd.DataFrame:
    rows = table[(table["actuator_model"] == model[0]) & np.isclose(table["friction_coefficient"], model[1])
                 & np.isclose(table["preload_N"], preload)]
    return rows.set_index("amplitude_fraction").sort_index()


def force_difference(table: pd.DataFrame, preload: float) -> pd.DataFrame:
    """F_gen(rigid, μ = 0.3) − F_gen(flexible, μ = 0.2) against amplitude at one preload (mN).

    Only amplitudes where both runs stalled; columns ``amplitude_nm``, ``difference_mN``.
    """
    earlier, this = _model_rows(table, _EARLIER, preload), _model_rows(table, _THIS, preload)
    common = earlier.index.intersection(this.index)
    ok = earlier.loc[common, "converged"].to_numpy() & this.loc[common, "converged"].to_numpy()
    common = common[ok]
    return pd.DataFrame({
        "amplitude_nm": this.loc[common, "amplitude_nm"].to_numpy(),
        "difference_mN": (earlier.loc[common, "generated_force_mN"]
                          - this.loc[common, "generated_force_mN"]).to_numpy(),
    })


@register_extractor("fig7a-force-difference-115mn", depends_on=("force_frequency",))
def _fig7a_difference(results, reading) -> float:
    frequency = float(reading["force_frequency"])
    if np.isclose(frequency, FORCE_FREQUENCY):
        diff = force_difference(results["fig7a"], 0.8)
    else:  # the frequency panel holds the full-stroke runs at the other frequencies
        if "fig7freq" not in results:
            raise NotEvaluable("needs results: fig7freq")
        table = results["fig7freq"]
        rows = table[np.isclose(table["frequency_Hz"], frequency) & np.isclose(table["radius_mm"], 1.0)]
        diff = force_difference(rows.assign(amplitude_fraction=1.0), 0.8)
    full = diff[np.isclose(diff["amplitude_nm"], PANELS_FULL_STROKE_NM["fig7a"])]
    if full.empty:
        raise NotEvaluable(f"no stalled pair of runs at 202 nm and 0.8 N at {frequency:g} Hz")
    return float(full["difference_mN"].iloc[0])


@register_extractor("sec4-2-friction-and-actuator-dynamics-cause-discrepancy")
def _causes(results) -> dict:
    cycle = results["fig7cycle"]
    force = {}
    for model, mu in (("rigid", 0.3), ("rigid", 0.2), ("flexible", 0.2)):
        rows = cycle[(cycle["actuator_model"] == model) & np.isclose(cycle["friction_coefficient"], mu)]
        if rows.empty:
            raise NotEvaluable(f"no stall period of {model} actuators with μ = {mu:g}")
        force[model, mu] = float(rows["generated_force_mN"].iloc[0])
    friction = force["rigid", 0.3] - force["rigid", 0.2]
    actuators = force["rigid", 0.2] - force["flexible", 0.2]
    return {"lhs": np.array([friction, actuators]), "rhs": np.zeros(2)}


@register_evidence("sec4-2-friction-and-actuator-dynamics-cause-discrepancy")
def _causes_evidence(results) -> list:
    lhs = _causes(results)["lhs"]
    return [f"μ 0.3 → 0.2 with rigid actuators lowers F_gen by {lhs[0]:.4g} mN; rigid → flexible actuators "
            f"at μ = 0.2 lowers it by {lhs[1]:.4g} mN (together {lhs.sum():.4g} mN; 202 nm, 0.8 N, R = 1 mm)"]


@register_extractor("sec4-2-other-preloads-same-trend")
def _other_preloads(results) -> dict:
    grid = results["fig7grid"]
    full = grid[np.isclose(grid["amplitude_fraction"], 1.0)]
    earlier, this = [], []
    for (radius, preload), rows in full.groupby(["radius_mm", "preload_N"]):
        pair = [rows[(rows["actuator_model"] == m) & np.isclose(rows["friction_coefficient"], mu)]
                for m, mu in (_EARLIER, _THIS)]
        if any(p.empty or not bool(p["converged"].iloc[0]) for p in pair):
            raise NotEvaluable(f"no stalled pair of runs at R = {radius:g} mm, {preload:g} N")
        earlier.append(float(pair[0]["generated_force_mN"].iloc[0]))
        this.append(float(pair[1]["generated_force_mN"].iloc[0]))
    if not earlier:
        raise NotEvaluable("no full-stroke runs on the preload grids")
    lhs, rhs = np.array(earlier), np.array(this)
    # 'other preload levels' means every preload: a pass needs all of them, a failure needs one
    computed = {(round(r, 9), round(p, 9)) for r, p in zip(full["radius_mm"], full["preload_N"], strict=True)}
    missing = [(r * 1e3, p) for r, grid in PRELOAD_GRIDS.items() for p in grid
               if (round(r * 1e3, 9), round(float(p), 9)) not in computed]
    if missing and np.all(lhs > rhs):
        raise NotEvaluable(f"holds at the {len(lhs)} preloads computed on this profile; "
                           f"{len(missing)} preloads of the grids are not computed, e.g. "
                           f"{missing[0][1]:g} N at R = {missing[0][0]:g} mm")
    return {"lhs": lhs, "rhs": rhs}


def _trend(results, name: str) -> dict:
    table = results[name]
    out = {}
    for preload in PANELS[name][1]:
        diff = force_difference(table, preload)
        if len(diff) < 2:
            raise NotEvaluable(f"{name}: fewer than two stalled amplitudes at {preload:g} N")
        out[f"{preload:g} N"] = {"x": diff["amplitude_nm"].to_numpy(), "y": diff["difference_mN"].to_numpy()}
    return out


@register_extractor("fig7a-discrepancy-grows-with-amplitude")
def _fig7a_trend(results) -> dict:
    return _trend(results, "fig7a")


@register_extractor("fig7b-discrepancy-grows-with-amplitude")
def _fig7b_trend(results) -> dict:
    return _trend(results, "fig7b")


@register_extractor("fig7-critical-amplitude-both-models")
def _fig7_onsets(results) -> dict:
    lhs, rhs = [], []
    for name in ("fig7a", "fig7b"):
        table = results[name]
        for preload in PANELS[name][1]:
            onset = {}
            for model in (_EARLIER, _THIS):
                rows = _model_rows(table, model, preload)
                if rows.empty:
                    raise NotEvaluable(f"{name}: no runs for {model} at {preload:g} N")
                if not np.isfinite(rows["onset_nm"].iloc[0]):
                    raise ClaimFails(f"{name}: no force generation up to the full stroke for {model} at "
                                     f"{preload:g} N")
                onset[model] = float(rows["onset_nm"].iloc[0])
            lhs.append(onset[_EARLIER])
            rhs.append(onset[_THIS])
    return {"lhs": np.array(lhs), "rhs": np.array(rhs)}
