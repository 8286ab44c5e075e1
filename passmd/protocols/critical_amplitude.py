"""The critical-amplitude search of Section 4.1: a pure function of a drive.

Below a critical amplitude A_c a saw-tooth moves the runner by "no measurable step" — the
runner "only oscillates around its initial position without step generation" (Section 1).
The paper does not say how A_c was read off its simulations; the protocol below is ours
(``ASSUMPTIONS``), and the critical-amplitude chapters show how much each choice moves
the result.

Two critical amplitudes, both found by bisection on the amplitude
-----------------------------------------------------------------
``"steady"`` — steady-state A_c (the primary one, checked by the ledger)
    Saw-tooth runs from rest (virgin contacts) of :data:`STEADY_PERIODS` periods at the
    drive frequency f (default ``PROTOCOL.drive_frequency``); the step that counts is the
    *last* one (settled position of the last period minus that of the one before,
    :attr:`passmd.solver.results.SimulationResult.step_sizes`), by when the transient of the first
    fly-backs has died out. A_c is the smallest amplitude whose last step exceeds the
    "measurable step" :data:`STEP_THRESHOLD`. After a full slide the contact is left
    pre-strained and the runner keeps a residual micro-vibration, so this A_c depends on the
    drive frequency; the figures show its spread over ``PROTOCOL.critical_amplitude_band``.
``"first"`` — onset of full sliding in the first fly-back
    From rest and virgin contacts, one saw-tooth ramp and its fly-back: the smallest
    amplitude at which every contact slides fully (the share of slipping MDR springs
    reaches 1 in every contact group) during that fly-back or the actuator ringing after
    it. No step threshold is involved, and every integrator step is inspected.

Search: bisection on the reproducible bracket [0, A_max] (A_max: the actuator's full
stroke, Table 2). A = 0 makes no step and no slip, so only A_max is simulated to open the
bracket; it halves until narrower than the tolerance, and reports the final bracket, its
midpoint as A_c and the number of runs. The steady-state search finds bisection's final
bracket with fewer runs (:func:`search_amplitude`): above A_c the last step grows about 1 nm
per nm of amplitude, so its linear extrapolation tells which of bisection's decisions need a
run; whenever the step switches once on [0, A_max] the bracket is bisection's to the last bit.
Grids, figures and claims of Section 4.1 are in :mod:`passmd.experiments.critical_amplitude_one.figures` and
:mod:`passmd.experiments.critical_amplitude_six.figures`.
"""

from __future__ import annotations

import math

import numpy as np

from passmd.model import waveforms
from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import Drive
from passmd.model.tables import Assumption
from passmd.runtime.validation import check_choice, check_positive, check_range
from passmd.solver import simulation

__all__ = [
    "ASSUMPTIONS",
    "BISECTION_FLOOR_SPACINGS",
    "PROTOCOLS",
    "STEADY_PERIODS",
    "STEP_THRESHOLD",
    "bisect_amplitude",
    "critical_amplitude",
    "first_flyback_slip",
    "rested_sawtooth",
    "search_amplitude",
    "steady_step",
]

#: "Measurable step" of the steady-state search (m; the protocol default).
STEP_THRESHOLD = PROTOCOL.step_threshold
#: Periods of a steady-state run; the last of its steps counts (the protocol default).
STEADY_PERIODS = PROTOCOL.steady_periods
#: Time after the first fly-back during which slip is still looked for (actuator ringing) (s).
FIRST_FLYBACK_HOLD = 20e-6
#: |T|/μF_N counted as full sliding (the exact MDR contact gives exactly μF_N when sliding).
FULL_SLIDING_SHARE = 1.0 - 1e-9
#: Protocols of :func:`critical_amplitude`.
PROTOCOLS = ("steady", "first")
#: Narrowest bisection bracket, in float spacings of the upper amplitude: the midpoint of a
#: narrower bracket rounds onto one of its ends and the halving stops making progress.
BISECTION_FLOOR_SPACINGS = 16

_BAND = PROTOCOL.critical_amplitude_band

ASSUMPTIONS: tuple[Assumption, ...] = (
    Assumption(
        key="critical_amplitude_protocol",
        symbol="A_c",
        value=(
            f"steady state: smallest saw-tooth amplitude whose last step of a {STEADY_PERIODS}-period run "
            f"from rest exceeds the measurable step, at f = {PROTOCOL.drive_frequency:g} Hz (band "
            f"{_BAND[0]:g}–{_BAND[-1]:g} Hz), slew-rate fly-back; also the onset of full "
            "sliding of every contact in the first fly-back from virgin contacts"
        ),
        unit="nm",
        rationale=(
            "Section 4.1 does not say how A_c was read off the simulations. Section 1 defines A_c as the "
            "amplitude below which 'no measurable step' is obtained and the runner 'only oscillates "
            "around its initial position', i.e. no steps in continued operation: the last step of a run "
            "long enough for the start-up transient to die out (it has by the 8th period in every "
            "configuration tried). 100 Hz is the saw-tooth frequency of Section 5.2 (Fig. 9a)."
        ),
        sensitivity=(
            "Critical-amplitude chapters: both protocols side by side, the steady-state A_c over "
            "50–200 Hz as a band and from 20 Hz to 1 kHz, both fly-back rules."
        ),
    ),
    Assumption(
        key="critical_amplitude_step_threshold",
        symbol="δ",
        value=f"{STEP_THRESHOLD * 1e9:g}",
        unit="nm",
        rationale=(
            "'No measurable step' needs a number. Above the onset the steady step grows about 1 nm "
            "per nm of amplitude (Fig. 5a), so δ raises A_c by about δ: 0.5 nm is 0.5 % of the largest "
            "A_c on the preload grids and 10 % of the smallest (six flexible contacts at 0.1 N), yet "
            "well above the simulator's step convergence (0.05 nm) and the creep the start-up "
            "transient still leaves at the last period below A_c (tested at 0.8 A_c)."
        ),
        sensitivity="Shifts the steady-state A_c by about δ; the first-fly-back onset uses none.",
    ),
)


def steady_step(
    drive: Drive,
    amplitude: float,
    frequency: float = PROTOCOL.drive_frequency,
    *,
    periods: int = STEADY_PERIODS,
    flyback=None,
    rest: float = 0.0,
) -> dict:
    """Step sizes of a saw-tooth run from rest; the last one is the steady-state step.

    Parameters
    ----------
    drive : Drive
        The drive.
    amplitude : float
        Actuation amplitude A (m), 0 ≤ A ≤ A_max.
    frequency : float
        Drive frequency f (Hz).
    periods : int
        Periods of the run (>= 2); the steps are the changes of the settled position from
        one period to the next.
    flyback : {"slew", "fixed"} or float, optional
        Fly-back rule overriding the drive's (default None: the drive's;
        :func:`passmd.model.waveforms.flyback_time`).
    rest : float
        Time (s) x_p rests at 0 after each fly-back before the next ramp starts (default 0: the
        saw-tooth); long enough, the runner's ringing has died out when the next fly-back comes
        (the counterfactual of :mod:`passmd.protocols.diagnosis`).

    Returns
    -------
    dict
        ``steps_m`` (the ``periods − 1`` steps), ``first_step_m`` (across the first
        fly-back), ``last_step_m`` (across the last one), ``wall_time_s``.
    """
    if int(periods) != periods or periods < 2:
        raise ValueError(f"periods = {periods!r} is out of range: must be an integer >= 2")
    if rest:
        wave = rested_sawtooth(drive, amplitude, frequency, check_positive("rest", rest, "s"), int(periods),
                               flyback)
    else:
        wave = waveforms.sawtooth(amplitude, frequency, drive, periods=int(periods), flyback=flyback)
    result = simulation.simulate(drive, wave, max_points=2)
    steps = result.step_sizes
    return {
        "steps_m": steps.tolist(),
        "first_step_m": float(steps[0]),
        "last_step_m": float(steps[-1]),
        "wall_time_s": result.wall_time,
    }


def rested_sawtooth(drive: Drive, amplitude: float, frequency: float, rest: float, periods: int,
                    flyback=None) -> waveforms.Waveform:
    """The saw-tooth at ``frequency`` (ramp, fly-back) with x_p resting at 0 for ``rest`` s after each
    fly-back: the same ramp and fly-back, the runner left to settle before the next ramp."""
    A = check_range("amplitude", amplitude, 0.0, drive.actuator.full_stroke_amplitude, lower_open=True,
                    unit="m")
    t_fb = waveforms.flyback_time(A, drive, flyback)
    waveforms.check_flyback_fits(t_fb, frequency)
    t_ramp = 1.0 / frequency - t_fb
    settle = (1.0 - waveforms.SETTLE_FRACTION) * t_ramp
    period = t_ramp + t_fb + rest
    return waveforms.piecewise_linear([0.0, settle, t_ramp, t_ramp + t_fb, period],
                                      [0.0, A * settle / t_ramp, A, 0.0, 0.0], 1.0 / period, periods,
                                      settle_window=(settle, t_ramp), slip_mark=t_ramp,
                                      kind="saw-tooth with rests")


def first_flyback_slip(
    drive: Drive,
    amplitude: float,
    frequency: float = PROTOCOL.drive_frequency,
    *,
    flyback=None,
    hold: float = FIRST_FLYBACK_HOLD,
) -> dict:
    """Whether every contact group slides fully in the first fly-back from virgin contacts.

    The first period of the saw-tooth at ``frequency`` (ramp 0 → A, fly-back A → 0),
    followed by ``hold`` at x_p = 0 for the actuators' ringing, from rest. The simulator
    inspects every integrator step from the fly-back on for |T|/μF_N
    (``SimulationResult.peak_force_ratio``), which is 1 exactly in full sliding. The ramp
    starts with a jump of x_p's velocity, which leaves the runner vibrating with an
    amplitude of about A·f/ω_r (ω_r the runner-on-contacts frequency, 4–11 kHz): ≤ 0.2 nm at
    100 Hz, but nm at 1 kHz, so the onset is only frequency-independent at low f.

    Returns
    -------
    dict
        ``peak_force_ratio`` (largest |T|/μF_N, one per contact group: side 1 and side 2
        for six contacts), ``full_sliding`` (every group reached full sliding), ``wall_time_s``.
    """
    A = check_range(
        "amplitude", amplitude, 0.0, drive.actuator.full_stroke_amplitude, lower_open=True, unit="m"
    )
    check_positive("hold", hold, "s")
    t_fb = waveforms.flyback_time(A, drive, flyback)
    t_ramp = 1.0 / check_positive("frequency", frequency, "Hz") - t_fb
    if t_ramp <= t_fb:
        raise ValueError(
            f"frequency = {frequency!r} is out of range: the fly-back of {t_fb:.3g} s must "
            "take less than half a period"
        )
    period = t_ramp + t_fb + hold
    wave = waveforms.piecewise_linear([0.0, 0.8 * t_ramp, t_ramp, t_ramp + t_fb, period],
                                      [0.0, 0.8 * A, A, 0.0, 0.0], 1.0 / period, 1,
                                      settle_window=(0.8 * t_ramp, t_ramp), slip_mark=t_ramp,
                                      kind="first fly-back")
    result = simulation.simulate(drive, wave, max_points=2)
    peak = result.peak_force_ratio[0]  # every integrator step from the fly-back on
    return {
        "peak_force_ratio": peak.tolist(),
        "full_sliding": bool(np.all(peak >= FULL_SLIDING_SHARE)),
        "wall_time_s": result.wall_time,
    }


def _check_bracket(upper: float, tolerance: float) -> float:
    """``upper`` (m) after checking that a bracket of width ``tolerance`` can be represented below it."""
    hi = check_positive("upper", upper, "m")
    check_positive("tolerance", tolerance, "m")
    floor = BISECTION_FLOOR_SPACINGS * float(np.spacing(hi))
    if tolerance < floor:
        raise ValueError(
            f"tolerance (--tolerance) = {tolerance!r} m is out of range: must be >= {floor:.3g} m, "
            f"{BISECTION_FLOOR_SPACINGS} float spacings of the amplitude {hi!r} m (a narrower bracket "
            "cannot be represented)"
        )
    return hi



def bisect_amplitude(moves, upper: float, tolerance: float) -> dict:
    """Smallest amplitude in (0, upper] at which ``moves(A)`` turns true, by bisection.

    ``moves(0)`` is false by definition (no drive, no motion) and is not evaluated; the
    bracket [0, upper] is opened by evaluating ``moves(upper)`` and then halved until it
    is at most ``tolerance`` wide. If ``moves`` switches more than once in the bracket,
    the bisection finds one of the switches; the runs of Fig. 5a show where that matters.
    ``tolerance`` must be at least ``BISECTION_FLOOR_SPACINGS`` float spacings of
    ``upper`` (the resolution of the amplitude), so the halving always ends.

    Returns
    -------
    dict
        ``critical_amplitude_m`` (midpoint of the final bracket; NaN when
        ``moves(upper)`` is false), ``bracket_low_m``, ``bracket_high_m`` (NaN when
        ``moves(upper)`` is false), ``runs`` (evaluations of ``moves``).
    """
    lo, hi = 0.0, _check_bracket(upper, tolerance)
    runs = 1
    if not moves(hi):
        return {
            "critical_amplitude_m": math.nan,
            "bracket_low_m": hi,
            "bracket_high_m": math.nan,
            "runs": runs,
        }
    while hi - lo > tolerance:
        mid = 0.5 * (lo + hi)
        runs += 1
        if moves(mid):
            hi = mid
        else:
            lo = mid
    return {"critical_amplitude_m": 0.5 * (lo + hi), "bracket_low_m": lo, "bracket_high_m": hi, "runs": runs}


def _bisection_cell(known: dict, upper: float, tolerance: float, guess: float):
    """Bisection's final bracket on [0, upper], its decisions taken from ``known`` (evaluated
    amplitudes), from monotonicity where an evaluated amplitude implies them, else predicted by
    ``guess`` (the estimated switch). Returns ``(lo, hi, predicted)``: the final bracket with the
    float values bisection computes, and the amplitudes whose decision was only predicted."""
    resting = max((a for a, moved in known.items() if not moved), default=0.0)
    moving = min((a for a, moved in known.items() if moved), default=upper)
    lo, hi, predicted = 0.0, upper, []
    while hi - lo > tolerance:
        mid = 0.5 * (lo + hi)
        if mid in known:
            moved = known[mid]
        elif mid <= resting or mid >= moving:
            moved = mid >= moving
        else:
            moved = mid >= guess
            predicted.append(mid)
        lo, hi = (lo, mid) if moved else (mid, hi)
    return lo, hi, predicted


def _estimate_switch(measured: dict, lo: float, hi: float, slope: float | None) -> float:
    """Where the measure crosses 0, from the two evaluated amplitudes nearest the bracket (lo, hi)
    on the side where it is informative, or from one and the prior ``slope``; the midpoint when
    neither gives a point strictly inside the bracket."""
    sides = (sorted(a for a in measured if a >= hi), sorted((a for a in measured if a <= lo), reverse=True))
    for near in sides:
        points = [(a, measured[a]) for a in near if measured[a] is not None and math.isfinite(measured[a])]
        if len(points) >= 2 and points[0][1] != points[-1][1]:  # the nearest and the farthest: a robust slope
            (a0, m0), (a1, m1) = points[0], points[-1]
            guess = a0 - m0 * (a1 - a0) / (m1 - m0)
        elif len(points) == 1 and slope is not None and near is sides[0]:
            guess = points[0][0] - points[0][1] / slope
        else:
            continue
        if lo < guess < hi:
            return guess
    return 0.5 * (lo + hi)


def search_amplitude(probe, upper: float, tolerance: float, *, slope: float | None = None) -> dict:
    """The final bracket of :func:`bisect_amplitude`, found with fewer runs where the switch is single.

    ``probe(A)`` returns ``(moves, measure)``: whether the drive moves at A, and a number that
    crosses 0 near the switch, roughly linearly in A (e.g. the last step minus the measurable
    step, positive above the switch; None where it says nothing). The search walks bisection's
    path on [0, upper] and evaluates only the amplitudes whose decision it cannot infer: those
    between the largest amplitude that rests and the smallest that moves, choosing them where the
    measure's linear extrapolation (from two evaluated amplitudes on one side of the switch, or
    one and the prior ``slope``) puts the switch. Whenever ``moves`` switches once on [0, upper]
    (monotone in A) every decision of bisection's path is then the one bisection takes, so the
    bracket, and the critical amplitude, are bisection's to the last bit; where it switches more
    than once the result is one of the switches, with the same guarantee (rests at the bracket's
    low end, moves at its high end, width ≤ ``tolerance``). ``runs`` counts the evaluations:
    typically 4–6 instead of bisection's 1 + log2(upper/tolerance).
    """
    lo, hi = 0.0, _check_bracket(upper, tolerance)
    known, measured = {}, {}

    def evaluate(amplitude):
        known[amplitude], measured[amplitude] = probe(amplitude)

    evaluate(upper)
    if not known[upper]:
        return {"critical_amplitude_m": math.nan, "bracket_low_m": upper, "bracket_high_m": math.nan,
                "runs": 1}
    known[0.0], measured[0.0] = False, None  # A = 0: no drive, no motion (never simulated)
    widths = []
    while True:
        resting = max(a for a, moved in known.items() if not moved)
        moving = min(a for a, moved in known.items() if moved)
        widths.append(moving - resting)
        if len(widths) > 2 and widths[-1] > 0.5 * widths[-3]:  # extrapolation stalls: halve instead
            guess = 0.5 * (resting + moving)
        else:
            guess = _estimate_switch(measured, resting, moving, slope)
        lo, hi, predicted = _bisection_cell(known, upper, tolerance, guess)
        if not predicted:
            return {"critical_amplitude_m": 0.5 * (lo + hi), "bracket_low_m": lo, "bracket_high_m": hi,
                    "runs": len(known) - 1}
        # the predicted ends of the final bracket settle every decision: first the end on the side
        # where the measure is informative (if the prediction is wrong, it improves the estimate)
        informative_moving = any(known[a] and measured[a] is not None for a in known)
        ends = [a for a in ((hi, lo) if informative_moving else (lo, hi)) if a in predicted]
        evaluate(ends[0])


def critical_amplitude(
    drive: Drive,
    *,
    protocol: str = "steady",
    frequency: float = PROTOCOL.drive_frequency,
    flyback=None,
    periods: int = STEADY_PERIODS,
    threshold: float = STEP_THRESHOLD,
    tolerance: float = PROTOCOL.search_tolerance,
    progress: bool | str | None = None,
    rest: float = 0.0,
) -> dict:
    """Simulated critical amplitude A_c of a drive (protocols: see the module docstring).

    Parameters
    ----------
    drive : Drive
        The drive (one or six contacts, rigid or flexible actuators).
    protocol : {"steady", "first"}
        Steady-state A_c (the last step of a ``periods``-period run at ``frequency``
        exceeds ``threshold``) or the onset of full sliding in the first fly-back.
    frequency : float
        Drive frequency f of the saw-tooth (Hz).
    flyback : {"slew", "fixed"} or float, optional
        Fly-back rule overriding the drive's (default None: the drive's;
        :func:`passmd.model.waveforms.flyback_time`).
    periods : int
        Periods of a steady-state run (>= 2).
    threshold : float
        Measurable step δ (m) of the steady-state protocol.
    tolerance : float
        Largest width of the final bracket (m).
    progress : bool or "long", optional
        The bisection's runs on stderr (:mod:`passmd.runtime.progress`): None on a terminal only,
        ``"long"`` also elsewhere, each once the search has taken a few seconds.
    rest : float
        Steady protocol: x_p rests this long (s) after each fly-back (:func:`steady_step`); 0, the
        default, is the saw-tooth.

    Returns
    -------
    dict
        ``critical_amplitude_m``, ``bracket_low_m``, ``bracket_high_m``, ``runs``,
        ``wall_time_s`` (integration time of all runs).
    """
    if not isinstance(drive, Drive):
        raise ValueError(f"drive = {drive!r} is not a Drive")
    check_choice("protocol", protocol, PROTOCOLS)
    flyback = waveforms.flyback_rule(drive, flyback)
    check_positive("frequency", frequency, "Hz")
    check_positive("tolerance", tolerance, "m")
    check_range("threshold", threshold, 0.0, lower_open=True, unit="m")
    if int(periods) != periods or periods < 2:
        raise ValueError(f"periods = {periods!r} is out of range: must be an integer >= 2")
    check_range("rest", rest, 0.0, unit="s")
    if not (progress is None or isinstance(progress, bool) or progress == "long"):
        raise ValueError(f"progress = {progress!r} is not allowed: must be True, False, None or 'long'")
    wall = [0.0]
    upper = drive.actuator.full_stroke_amplitude
    bar = _bisection_bar(upper, tolerance, progress)

    def probe(amplitude):
        if protocol == "steady":  # the last step grows about 1 nm per nm of amplitude above A_c
            out = steady_step(drive, amplitude, frequency, periods=int(periods), flyback=flyback, rest=rest)
            wall[0] += out["wall_time_s"]
            moved = out["last_step_m"] > threshold
            measure = out["last_step_m"] - threshold if moved else None
        else:  # a run is short: plain bisection (the slip ratio's approach to 1 guides no better)
            out = first_flyback_slip(drive, amplitude, frequency, flyback=flyback)
            wall[0] += out["wall_time_s"]
            moved, measure = out["full_sliding"], None
        if bar is not None:
            bar.update(1)
        return moved, measure

    try:
        if protocol == "steady":
            found = search_amplitude(probe, upper, tolerance, slope=1.0)
        else:
            found = bisect_amplitude(lambda amplitude: probe(amplitude)[0], upper, tolerance)
    finally:
        if bar is not None:
            bar.close()
    found["wall_time_s"] = wall[0]
    return found


def _bisection_bar(upper: float, tolerance: float, show: bool | str | None):
    """A progress bar over the bisection's runs (1 + halvings of ``upper`` down to ``tolerance``)."""
    import sys

    from passmd.runtime import progress

    if show is False or sys.stderr is None or progress.in_worker():
        return None
    if show is None and not progress.is_terminal(sys.stderr):
        return None
    runs = 1 + max(0, math.ceil(math.log2(upper / tolerance)))
    return progress.bar(runs, unit="run", desc="critical amplitude")
