"""How fast a waveform drives the runner (Section 5.2): step and steady velocity of a drive.

Two measurements, as pure functions of a :class:`~passmd.model.parameters.Drive` and a waveform:

* **Steps at low frequency** (Fig. 9a): a few periods from rest; the settled positions and
  the mean step from period 2 on (across the optimized slips), × f for a velocity.
* **Steady velocity at kHz frequencies** (Figs. 9b, 10; assumption ``steady_velocity``): at
  100 kHz a period lasts 10 µs, a tenth of the runner's micro-vibration period: there is no
  stick phase to average over, and from rest the runner needs about a millisecond (hundreds
  of periods) to reach its steady velocity. A run lasts ``max(MIN_PERIODS, f·STEADY_TIME)``
  periods from rest; the velocity is the slope of the runner's period-mean position
  (``period_mean_position`` of :class:`passmd.solver.results.SimulationResult`, no stick phase
  assumed) over the run's second half, and ``velocity_drift`` compares its third and fourth
  quarter. For the optimized waveform the run also reports whether the contacts stick while
  the hemispheres accelerate (assumption ``stick_during_acceleration``).

* **Steady step of a running drive** (:func:`settled_step`, what a test stand measures as "the
  step" at low frequency): a saw-tooth from rest, period after period, until the run repeats
  itself: its state at the end of a period (runner, actuators, contact memory) is the state at
  the end of the period before moved on by one step, to within :data:`STATE_SHARE` ×
  :data:`STEP_ACCURACY` (:func:`passmd.solver.periodicity.mismatch`); the step is that shift.
  Where the contact memory changes its structure from period to period (a stuck drive's growing
  stack of micro-reversals) the last :data:`SETTLED_STEPS` steps must agree to
  :data:`STEP_ACCURACY` instead. The first step from rest differs from the steady one by the
  start-up transient (0.5–2 nm for the six-contact flexible drive at 100 Hz), so a run from rest
  is a different measurement.

Nothing here knows of figures, grids or the ledger.
"""

from __future__ import annotations

import math

import numpy as np

from passmd.model import optimized_waveform, waveforms
from passmd.runtime.validation import check_choice
from passmd.solver import simulation
from passmd.solver.results import SimulationError

__all__ = [
    "FULL_SLIDING_SHARE",
    "MAX_RECORD",
    "MAX_SETTLE_PERIODS",
    "MIN_PERIODS",
    "SAMPLES_PER_ACCELERATION",
    "SETTLED_STEPS",
    "STATE_SHARE",
    "STEADY_DRIFT_LIMIT",
    "STEADY_TIME",
    "STEP_ACCURACY",
    "STEP_PERIODS",
    "STEP_PROTOCOL_BELOW",
    "make_waveform",
    "settled_step",
    "settled_value",
    "steady_periods",
    "steady_run",
    "steady_velocity",
    "step_run",
    "waveform_velocity",
]

#: Simulated time of a steady-velocity run (s) and its least number of periods.
STEADY_TIME = 5e-3
MIN_PERIODS = 20
#: Largest |velocity_drift| (fourth quarter's velocity minus the third's, over the velocity) of a
#: run counted as steady; beyond it the velocity still changes (or is so small that noise of the
#: period means dominates it) and a map marks the point as not steady.
STEADY_DRIFT_LIMIT = 0.05
#: Record spacing inside the acceleration segment: a slip share sample every t_a / this.
SAMPLES_PER_ACCELERATION = 8
#: Largest record of a steady run (rows); bounds memory at low frequencies.
MAX_RECORD = 300_000
#: Slip share counted as full sliding (the exact MDR contact reports exactly 1).
FULL_SLIDING_SHARE = 1.0 - 1e-9
#: Periods from rest of the step measurement (Fig. 9a: "after three periods").
STEP_PERIODS = 3
#: Below this frequency a velocity is measured from the steps (STEP_PERIODS periods, mean step × f),
#: above it by the steady-velocity protocol (Hz).
STEP_PROTOCOL_BELOW = 1e3
#: Accuracy of a settled step (m): a fifth of the simulator's step convergence (0.05 nm, the
#: integrator's stated accuracy), far below a measured step's scatter (≥ 0.1 nm).
STEP_ACCURACY = 0.01e-9
#: Consecutive steps that must agree to STEP_ACCURACY where the states cannot be compared (the
#: contact memory changes its structure): three, so that one small change between two steps of a
#: slowly turning transient is not taken for a settled step.
SETTLED_STEPS = 3
#: Largest mismatch of two end-of-period states, as a share of the step accuracy, of a run counted
#: as repeating itself: below, with a margin, the largest share whose steps all stayed within
#: STEP_ACCURACY of a 40-period run's on random drives, and checked on as many others
#: (``benchmarks/bench_settling.py``, its record in ``passmd/data/benchmarks/settling.json``; the
#: calibration chapter shows it).
STATE_SHARE = 0.2
#: Most periods a settling run takes; a step still changing then is reported unsettled (the mean
#: step of the run's second half, as the steady-velocity protocol measures it).
MAX_SETTLE_PERIODS = 60


def make_waveform(drive, amplitude, frequency, periods, waveform, short_period, design):
    """A ``"sawtooth"`` or ``"optimized"`` (with ``design`` and ``short_period``) waveform."""
    if waveform == "sawtooth":
        return waveforms.sawtooth(amplitude, frequency, drive, periods=periods)
    return optimized_waveform.optimized(amplitude, frequency, drive, periods=periods, design=design,
                                        short_period=short_period)


def steady_periods(frequency: float, steady_time: float = STEADY_TIME, min_periods: int = MIN_PERIODS) -> int:
    """Periods of a steady-velocity run: ``max(min_periods, ceil(f · steady_time))``."""
    return int(max(min_periods, math.ceil(frequency * steady_time - 1e-9)))


def steady_velocity(result) -> dict:
    """Steady velocity from the period-mean positions of a run's second half (m/s).

    Returns ``velocity_m_per_s`` (slope between the period means at n/2 and n − 1) and
    ``velocity_drift`` (velocity over the fourth quarter minus that over the third, over
    |velocity|; 0 for a steady run).
    """
    means = result.period_mean_position
    n = means.size
    period = result.waveform.period
    half = n // 2
    quarter = max(1, (n - 1 - half) // 2)
    v = (means[-1] - means[half]) / ((n - 1 - half) * period)
    v3 = (means[half + quarter] - means[half]) / (quarter * period)
    v4 = (means[-1] - means[-1 - quarter]) / (quarter * period)
    drift = (v4 - v3) / abs(v) if v != 0 else math.inf
    return {"velocity_m_per_s": float(v), "velocity_drift": float(drift)}


def step_run(drive, amplitude: float, frequency: float, waveform: str, design=None,
             periods: int = STEP_PERIODS) -> dict:
    """Fig. 9a protocol: ``periods`` periods from rest; settled positions and their steps.

    Returns ``settled_positions_m``, ``mean_step_m`` (mean over the steps from period 2 on,
    i.e. across the optimized slips), ``final_position_m`` and ``wall_time_s``.
    """
    wave = make_waveform(drive, amplitude, frequency, periods, waveform, "cut", design)
    result = simulation.simulate(drive, wave, max_points=2)
    return {"settled_positions_m": result.settled_positions, "mean_step_m": float(np.mean(result.step_sizes)),
            "final_position_m": result.final_position, "wall_time_s": result.wall_time}


def settled_value(steps, mismatch: float, shift: float, accuracy: float = STEP_ACCURACY,
                  share: float | None = None) -> float | None:
    """The settled step once a run has repeated itself (:func:`settled_step`'s rule), else None.

    ``steps``: the steps so far (m); ``mismatch``, ``shift``: of the last two end-of-period states
    (:func:`passmd.solver.periodicity.mismatch`). The state rule at ``share`` × ``accuracy``; where
    the memory changed its structure (infinite mismatch), the last :data:`SETTLED_STEPS` steps
    agreeing to ``accuracy``. ``share`` None: :data:`STATE_SHARE` (read when called).
    """
    if mismatch <= (STATE_SHARE if share is None else share) * accuracy:
        return float(shift)
    last = steps[-SETTLED_STEPS:]
    agree = steps.size >= SETTLED_STEPS and float(np.max(last) - np.min(last)) <= accuracy
    if math.isinf(mismatch) and agree:
        return float(steps[-1])
    return None


def settled_step(drive, amplitude: float, frequency: float, *, accuracy: float = STEP_ACCURACY,
                 max_periods: int = MAX_SETTLE_PERIODS, flyback=None) -> dict:
    """Steady step of a running saw-tooth drive: periods from rest until the run repeats itself.

    The run is continued period by period (:class:`passmd.solver.simulation.Simulation`) until its
    state at the end of a period is that at the end of the period before, moved on by the runner's
    advance, to within :data:`STATE_SHARE` × ``accuracy``
    (:func:`passmd.solver.periodicity.mismatch`); the step is that advance. While a contact's
    memory changes its structure between two periods the states cannot be compared, and the last
    :data:`SETTLED_STEPS` steps (changes of the settled position from one period to the next) must
    lie within ``accuracy`` of each other; the step is then the last one. A run that has not
    settled after ``max_periods`` periods reports the mean step of its second half (the
    steady-velocity protocol's reading) with ``settled`` False.

    Parameters
    ----------
    drive : Drive
        The drive (its fly-back rule unless ``flyback`` overrides it).
    amplitude, frequency : float
        Saw-tooth amplitude A (m) and frequency f (Hz).
    accuracy : float
        Accuracy of the step (m).
    max_periods : int
        Most periods of the run (> :data:`SETTLED_STEPS`).
    flyback : {"slew", "fixed"} or float, optional
        Fly-back rule overriding the drive's.

    Returns
    -------
    dict
        ``step_m``, ``settled``, ``mismatch_m`` (of the last two end-of-period states; inf where
        the memory changed its structure), ``spread_m`` (of the last :data:`SETTLED_STEPS` steps, or
        of all steps when fewer), ``periods``, ``first_step_m`` (the step across the first
        fly-back, from rest), ``wall_time_s``.
    """
    from passmd.runtime.validation import check_count, check_positive
    from passmd.solver import periodicity

    check_positive("accuracy", accuracy, "m")
    max_periods = check_count("max_periods", max_periods, SETTLED_STEPS + 2)
    wave = waveforms.sawtooth(amplitude, frequency, drive, periods=max_periods, flyback=flyback)
    run = simulation.Simulation(drive, wave, max_points=2)
    run.run_to(1)
    earlier = run.boundary_state()
    for periods in range(2, max_periods + 1):
        run.run_to(periods)
        later = run.boundary_state()
        mismatch, shift = periodicity.mismatch(earlier, later)
        steps = np.diff(run.settled_positions())
        last = steps[-SETTLED_STEPS:]
        spread = float(np.max(last) - np.min(last))
        step = settled_value(steps, mismatch, shift, accuracy)
        if step is not None:
            break
        earlier = later
    settled = step is not None
    if not settled:
        step = float(np.mean(steps[(steps.size - 1) // 2:]))
    return {"step_m": float(step), "settled": settled, "mismatch_m": float(mismatch), "spread_m": spread,
            "periods": periods, "first_step_m": float(steps[0]), "wall_time_s": run.wall_time}


def steady_run(drive, amplitude: float, frequency: float, waveform: str, short_period: str,
               design=None) -> dict:
    """Steady velocity of one drive, waveform and frequency (module docstring).

    For the optimized waveform the run is recorded densely enough to sample the slip share
    inside every acceleration segment (assumption ``stick_during_acceleration``).

    Returns
    -------
    dict
        ``velocity_m_per_s``, ``velocity_drift``, ``step_m`` (velocity / f),
        ``back_step_m`` (mean over the second half), ``periods``,
        ``simulator_mean_velocity_m_per_s``, ``wall_time_s`` and, for the optimized
        waveform, the times actually used (:func:`passmd.model.optimized_waveform.optimized_timing`),
        ``max_slip_share_acceleration`` and ``stick_during_acceleration``.
    """
    periods = steady_periods(frequency)
    out = {}
    max_points = 2
    if waveform == "optimized":
        timing = optimized_waveform.optimized_timing(design, amplitude, frequency, drive,
                                                     short_period=short_period)
        out.update({k: v for k, v in timing.items() if k != "period_s"})
        duration = periods / frequency
        spacing = timing["acceleration_time_s"] / SAMPLES_PER_ACCELERATION
        max_points = int(min(MAX_RECORD, math.ceil(duration / spacing) + 1))
    else:
        check_choice("waveform", waveform, ("sawtooth", "optimized"))
    wave = make_waveform(drive, amplitude, frequency, periods, waveform, short_period, design)
    result = simulation.simulate(drive, wave, max_points=max_points)
    out.update(steady_velocity(result))
    half = periods // 2
    out["step_m"] = out["velocity_m_per_s"] / frequency
    out["back_step_m"] = float(np.mean(result.back_steps[half:]))
    out["periods"] = periods
    out["simulator_mean_velocity_m_per_s"] = result.mean_velocity
    out["wall_time_s"] = result.wall_time
    if waveform == "optimized":
        start = np.arange(half, periods) / frequency + timing["settling_time_s"]
        t = result.time
        k = np.searchsorted(start, t, side="right") - 1
        inside = (k >= 0) & (t <= start[np.clip(k, 0, None)] + timing["acceleration_time_s"])
        if not np.any(inside):
            raise SimulationError("no recorded sample falls inside an acceleration segment")
        share = float(result.slip_share[:, inside].max())
        out["max_slip_share_acceleration"] = share
        out["stick_during_acceleration"] = bool(share < FULL_SLIDING_SHARE)
    return out


def waveform_velocity(drive, amplitude: float, frequency: float, waveform: str, design=None,
                      short_period: str = "cut") -> float:
    """Velocity of one waveform (m/s): from the steps below :data:`STEP_PROTOCOL_BELOW`, else steady.

    Below: :data:`STEP_PERIODS` periods from rest, mean step (from period 2 on) × f (Fig. 9a);
    above: the steady velocity (:func:`steady_velocity`).
    """
    if frequency < STEP_PROTOCOL_BELOW:
        wave = make_waveform(drive, amplitude, frequency, STEP_PERIODS, waveform, short_period, design)
        return float(np.mean(simulation.simulate(drive, wave, max_points=2).step_sizes) * frequency)
    periods = steady_periods(frequency)
    wave = make_waveform(drive, amplitude, frequency, periods, waveform, short_period, design)
    return steady_velocity(simulation.simulate(drive, wave, max_points=2))["velocity_m_per_s"]

