"""The stall criterion and the onset of force generation (Section 4.2), as functions of a drive.

The runner starts at rest, touching the load cell (a linear spring k, Table 1) at its free
length, with virgin contacts, and is driven by a saw-tooth until its steps stall: the load
cell then pushes back, on average over a period, as hard as the contacts carry the runner
forward. The force at stall is the *generated force* F_gen = k·x̄_r, x̄_r the runner's mean
position over the last period (:attr:`passmd.solver.results.SimulationResult.generated_force`).

Coulomb bound
    Over one period m_r (v_end − v_start) = T (F̄_fric − k·x̄_r), and every contact's friction
    is at most μF_N (Eq. 1), so F̄_fric ≤ μΣF_N. A stall is periodic (v_end = v_start): the
    stall force, and the force any credible extrapolation predicts, are at most μΣF_N
    (:func:`coulomb_bound`). Only the runner's inertia lets the load cell's period mean pass
    the bound, in a transient after the runner has reached it (it then swings on the load
    cell), never at stall. :func:`check_force_bounds` enforces this on every result, allowing
    the integrator's accuracy (:func:`bound_margin`).

Stall criterion (assumption ``force_stall_criterion``)
    F_n is k times the runner's mean position over period n. Near stall each step is a
    fixed fraction of the previous one (the step shrinks in proportion to the force still
    missing), so F_n approaches its limit geometrically. With D₁ and D₂ the changes of F
    over the two halves of the last :data:`STALL_WINDOW` periods, the rise still to come
    is estimated as the geometric tail D₂·r/(1 − r), r = D₂/D₁; the run has stalled when
    that tail and the spread of F over the window are both below the tolerance
    max(min(:data:`STALL_ABS_TOLERANCE`, :data:`STALL_BOUND_FRACTION`·μΣF_N),
    :data:`STALL_REL_TOLERANCE`·F) and F is within the Coulomb bound (a mean force above it is
    the runner swinging, not a stall). The tolerance is scaled by the contacts' own force
    scale μΣF_N: at the paper's preloads (≥ 0.1 N, μΣF_N ≥ 57 mN) the absolute 0.2 mN is the
    smaller and governs, at a preload of 1 mN (μΣF_N = 0.57 mN) it would be a third of every
    force the drive can make, so a swing of the runner would pass for a stall.
    A run that has not stalled is lengthened (by a number of periods predicted from the
    geometric rate) up to :data:`MAX_PERIODS`; if it still has not stalled the result says
    ``converged = False``. A longer run from rest begins with the shorter one (the
    saw-tooth's first periods do not depend on how many follow), so the run is continued,
    not repeated: the criterion sees the forces of a run of each length from rest, and each
    period is integrated once.

Rise still to come
    Reported only where it is credible (:func:`credible_tail`): for a stalled run, or for a
    run whose force approaches its limit geometrically (0 < r < 1, every change over the
    window of one sign), and only if F plus the tail stays within the Coulomb bound.
    Otherwise the result says why in one line instead.

Onset of force generation (assumption ``force_onset``)
    The runner generates force only if it steps at all from the free length, so the onset
    is the critical amplitude of the drive with the load cell engaged, found by the
    critical-amplitude search (steady-state protocol at the same frequency).

One period at stall, the physics of the stall force, is :func:`stall_cycle`
(:mod:`passmd.protocols.stall_period`). Everything here takes a :class:`~passmd.model.parameters.Drive`
and SI values; it knows nothing of figures, grids or the ledger.
"""

from __future__ import annotations

import math
import time

import numpy as np

from passmd.model import waveforms
from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import Drive
from passmd.model.tables import Assumption
from passmd.model.theory import friction_limit
from passmd.protocols.critical_amplitude import critical_amplitude
from passmd.protocols.stall_period import stall_cycle as stall_cycle
from passmd.runtime.validation import check_positive, check_range
from passmd.solver import simulation
from passmd.solver.steps import CONVERGED_ACCURACY

__all__ = [
    "ASSUMPTIONS",
    "INITIAL_PERIODS",
    "MAX_PERIODS",
    "ONSET_TOLERANCE",
    "STALL_ABS_TOLERANCE",
    "STALL_BOUND_FRACTION",
    "STALL_REL_TOLERANCE",
    "STALL_WINDOW",
    "ForceBoundError",
    "bound_margin",
    "check_force_bounds",
    "coulomb_bound",
    "credible_tail",
    "force_onset",
    "generated_force",
    "stall_cycle",
    "stall_estimate",
]

#: Periods over which the stall criterion looks at the force (two halves of 8).
STALL_WINDOW = 16
#: Absolute stall tolerance on the remaining rise and on the spread of F_gen (N).
STALL_ABS_TOLERANCE = 0.2e-3
#: Relative stall tolerance (fraction of F_gen).
STALL_REL_TOLERANCE = 2e-3
#: The absolute stall tolerance is at most this fraction of the Coulomb bound μΣF_N: the
#: criterion resolves the force on the contacts' own scale whatever the preload. At the
#: paper's preloads (μΣF_N ≥ 57 mN) 0.5 % is above :data:`STALL_ABS_TOLERANCE`, which governs.
STALL_BOUND_FRACTION = 5e-3
#: Periods of the first run of a point (the protocol default).
INITIAL_PERIODS = PROTOCOL.stall_periods
#: Most periods a point may take (the protocol default).
MAX_PERIODS = PROTOCOL.stall_max_periods
#: Default width of the final bracket of the onset (critical-amplitude) search (m).
ONSET_TOLERANCE = 0.2e-9

ASSUMPTIONS: tuple[Assumption, ...] = (
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


class ForceBoundError(RuntimeError):
    """A force result above the Coulomb bound μΣF_N by more than the integrator's accuracy."""


def coulomb_bound(drive: Drive) -> float:
    """μΣF_N (N, Eq. 1): the most friction all contacts together exert, the ceiling of every stall force."""
    if not isinstance(drive, Drive):
        raise ValueError(f"drive = {drive!r} is not a Drive")
    return friction_limit(drive)


def bound_margin(drive: Drive) -> float:
    """How far above μΣF_N a computed period-mean force may lie from integration error alone (N).

    The integrator's settled runner positions are accurate to
    :data:`passmd.solver.steps.CONVERGED_ACCURACY`, so k·x̄_r is accurate to k times that;
    1e-12·μΣF_N covers the rounding of the force sums.
    """
    if not isinstance(drive, Drive):
        raise ValueError(f"drive = {drive!r} is not a Drive")
    return drive.load_cell_stiffness * CONVERGED_ACCURACY + 1e-12 * friction_limit(drive)


def _stalled(estimate: dict, force: float, abs_tol: float, rel_tol: float, ceiling: float = math.inf) -> bool:
    """The stall criterion; ``ceiling`` (μΣF_N plus the integrator's accuracy) caps a stall force."""
    tol = max(abs_tol, rel_tol * abs(force))
    return estimate["remaining_N"] <= tol and estimate["spread_N"] <= tol and abs(force) <= ceiling


def credible_tail(forces, estimate: dict, converged: bool, limit: float, margin: float,
                  window: int = STALL_WINDOW) -> tuple[float | None, str | None]:
    """The rise still to come if the estimate is credible, else ``None`` and one line saying why.

    Parameters
    ----------
    forces : array_like
        F_n, one value per period (N).
    estimate : dict
        :func:`stall_estimate` of ``forces`` over ``window``.
    converged : bool
        Whether the stall criterion holds (its tail is then below the stall tolerance).
    limit, margin : float
        The Coulomb bound μΣF_N (:func:`coulomb_bound`) and the integrator's accuracy
        (:func:`bound_margin`), N.
    window : int
        Periods the estimate examined.

    Returns
    -------
    (float or None, str or None)
        ``(remaining_N, None)`` when credible; ``(None, reason)`` when it is not: too few
        periods, a force still rising at an undiminished rate, a run that has not stalled and
        whose force swings or changes erratically over the window (the geometric model does
        not describe it), or a tail that would carry |F| above μΣF_N (no stall force can be).
    """
    f = np.asarray(forces, dtype=float)
    remaining, ratio = estimate["remaining_N"], estimate["ratio"]
    if f.size < window + 1:
        return None, f"only {f.size} periods: too few to extrapolate (at least {window + 1})"
    if not math.isfinite(remaining):
        return None, f"the force still rises at an undiminished rate over the last {window} periods"
    if not converged:
        if ratio < 0:
            return None, (f"the force swings over the last {window} periods (D2/D1 = {ratio:.2g}): "
                          "no steady approach to extrapolate")
        changes = np.diff(f[-1 - window :])
        if np.any(changes > 0) and np.any(changes < 0):
            return None, (f"the force rises and falls over the last {window} periods: "
                          "no steady approach to extrapolate")
    if abs(f[-1]) + remaining > limit + margin:
        return None, (f"extrapolating the last {window} periods geometrically would pass the Coulomb bound "
                      f"mu*sum(F_N) = {limit:.4g} N, which no stall force can")
    return float(remaining), None


def check_force_bounds(found: dict, drive: Drive) -> None:
    """Raise :class:`ForceBoundError` if a result of :func:`generated_force` breaks the Coulomb bound.

    Checked against μΣF_N plus :func:`bound_margin`: the stall force of a stalled run, the
    last period's mean friction of any run (each contact's friction is at most μF_N), and the
    force a reported rise still to come leads to. The load-cell force of a run that has not
    stalled may pass the bound by the runner's inertia (see the module docstring) and is
    reported as such.
    """
    keys = ("generated_force_N", "converged", "mean_friction_N", "remaining_force_N")
    if not isinstance(found, dict) or not all(key in found for key in keys):
        raise ValueError(f"found = {found!r} is not a result of generated_force: must be a dict with "
                         f"the keys {', '.join(keys)}")
    limit, margin = coulomb_bound(drive), bound_margin(drive)
    ceiling = limit + margin
    force = abs(float(found["generated_force_N"]))
    what = (f"the Coulomb bound mu*sum(F_N) = {limit:.6g} N by more than the integrator's accuracy "
            f"({margin:.2g} N)")
    if found["converged"] and force > ceiling:
        raise ForceBoundError(f"stall force {force:.6g} N exceeds {what}: the stall criterion stopped on "
                              "a transient")
    friction = abs(float(found["mean_friction_N"]))
    if friction > ceiling:
        raise ForceBoundError(f"mean friction {friction:.6g} N exceeds {what}: the contact law was violated")
    remaining = found["remaining_force_N"]
    if remaining is not None and force + float(remaining) > ceiling:
        raise ForceBoundError(f"the force still to come ({float(remaining):.6g} N) would carry the force to "
                              f"{force + float(remaining):.6g} N, above {what}: the extrapolation is "
                              "not credible")


def _next_periods(periods: int, estimate: dict, force: float, window: int, abs_tol: float, rel_tol: float,
                  max_periods: int) -> int:
    """Periods of the next (longer) run.

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
    flyback=None,
    initial_periods: int = INITIAL_PERIODS,
    max_periods: int = MAX_PERIODS,
    abs_tolerance: float = STALL_ABS_TOLERANCE,
    rel_tolerance: float = STALL_REL_TOLERANCE,
    window: int = STALL_WINDOW,
    progress: bool | str | None = None,
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
    flyback : {"slew", "fixed"} or float, optional
        Fly-back rule overriding the drive's (default None: the drive's;
        :func:`passmd.model.waveforms.sawtooth`).
    initial_periods, max_periods : int
        Periods of the first run, lengthened until stall or until ``max_periods``.
    abs_tolerance, rel_tolerance : float
        Stall tolerance max(min(abs, :data:`STALL_BOUND_FRACTION`·μΣF_N), rel·F_gen) (N,
        fraction) on the remaining rise and the spread of the per-period force (see the
        module docstring).
    window : int
        Periods examined by the stall criterion.
    progress : bool or "long", optional
        The run's progress on stderr (:class:`passmd.solver.simulation.Simulation`).

    Returns
    -------
    dict
        SI values, keys carrying the unit: ``generated_force_N`` (k·x̄_r over the last
        period: the stall force if ``converged``, else a transient reading, which the
        runner's inertia may carry above μΣF_N), ``converged`` (stall criterion met),
        ``coulomb_bound_N`` (μΣF_N), ``periods`` (of the run reported),
        ``periods_simulated`` (periods integrated: the run is continued, so ``periods``),
        ``remaining_force_N`` (estimated rise still to come, ``None`` if not credible:
        :func:`credible_tail`), ``remaining_force_note`` (why not, else ``None``),
        ``force_spread_N`` (over the window), ``mean_friction_N`` (mean
        total friction on the runner over the last period), ``no_slip_reference_force_N`` (k
        times the mean piezo position x̄_p: what the load cell would read if the runner followed
        the piezo without slipping; a reference for the generated force, never a force on the
        runner, so not bounded by μΣF_N, which the contacts cannot exceed), ``last_step_m``,
        ``net_displacement_m`` (x̄_r − x̄_p over the last period), ``wall_time_s`` (integration
        time), ``cpu_time_s`` (CPU time of the whole call).

    Raises
    ------
    ValueError
        Bad input (names the parameter, its value and the allowed range).
    passmd.solver.results.SimulationError
        A run diverged.
    ForceBoundError
        A result breaks the Coulomb bound (:func:`check_force_bounds`).
    """
    cpu = time.process_time()
    if not isinstance(drive, Drive):
        raise ValueError(f"drive = {drive!r} is not a Drive")
    check_positive("frequency", frequency, "Hz")
    flyback = waveforms.flyback_rule(drive, flyback)
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
    limit, margin = coulomb_bound(drive), bound_margin(drive)
    abs_tolerance = min(abs_tolerance, STALL_BOUND_FRACTION * limit)  # the contacts' force scale
    # One run continued period by period: its first n periods are the run of n periods from
    # rest (the saw-tooth's breakpoints of period j do not depend on the number of periods),
    # so each check sees the forces a run of that length from rest would give.
    longest = waveforms.sawtooth(amplitude, frequency, drive, periods=int(max_periods), flyback=flyback)
    run = simulation.Simulation(drive, longest, max_points=2, progress=progress)
    periods = int(initial_periods)
    while True:
        run.run_to(periods)
        result = run.result()
        forces = k * result.period_mean_position
        estimate = stall_estimate(forces, window)
        converged = _stalled(estimate, float(forces[-1]), abs_tolerance, rel_tolerance, limit + margin)
        if converged or periods >= max_periods:
            break
        periods = _next_periods(periods, estimate, float(forces[-1]), window, abs_tolerance, rel_tolerance,
                                int(max_periods))
    wave = result.waveform
    T = wave.period
    piezo_mean = float(np.mean(wave.position(np.linspace((periods - 1) * T, periods * T, 4001))))
    remaining, note = credible_tail(forces, estimate, converged, limit, margin, window)
    out = {
        "generated_force_N": float(forces[-1]),
        "converged": bool(converged),
        "coulomb_bound_N": limit,
        "periods": int(periods),
        "periods_simulated": int(run.periods_done),
        "remaining_force_N": remaining,
        "remaining_force_note": note,
        "force_spread_N": estimate["spread_N"],
        "mean_friction_N": float(result.period_mean_friction[-1]),
        "no_slip_reference_force_N": k * piezo_mean,
        "last_step_m": float(result.step_sizes[-1]),
        "net_displacement_m": float(result.period_mean_position[-1] - piezo_mean),
        "wall_time_s": float(result.wall_time),
        "cpu_time_s": float(time.process_time() - cpu),
    }
    check_force_bounds(out, drive)
    return out


def force_onset(drive: Drive, frequency: float = PROTOCOL.drive_frequency,
                tolerance: float = ONSET_TOLERANCE) -> dict:
    """Onset of force generation: the critical amplitude with the load cell engaged (m).

    Calls :func:`passmd.protocols.critical_amplitude.critical_amplitude` (steady-state
    protocol) on ``drive`` with its load cell engaged. Returns its dict
    (``critical_amplitude_m`` — ``None`` if even the full stroke makes no step —,
    ``bracket_low_m``, ``bracket_high_m``, ``runs``, ``wall_time_s``).
    """
    if not isinstance(drive, Drive):
        raise ValueError(f"drive = {drive!r} is not a Drive")
    return critical_amplitude(drive if drive.load_cell else drive.replace(load_cell=True),
                              frequency=frequency, tolerance=tolerance)
