"""The runner's ringing in the stick phase after a fly-back: its frequency, size and decay.

After a fly-back the runner sticks again and swings on the contacts' tangential stiffness
(Section 5.1's micro-vibration, Fig. 8a). Its only damping is the contacts' micro-slip (and,
through the contacts, the actuators' viscosity), which removes energy in proportion to the swing
cubed (Cattaneo–Mindlin hysteresis): the swing decays slower the smaller it gets, and for a heavy
runner it can outlast a 100 Hz period. Then the next fly-back meets a runner still moving, and the
step it makes depends on where in its swing the runner is: steps, back-steps and the critical
amplitude are not monotone in frequency, amplitude or preload. That is the model's physics, not
numerical noise; this module measures the ringing so that an answer affected by it can name it.

The measurement is post hoc, on a simulated record (:func:`passmd.solver.simulation.simulate`):
one saw-tooth period from rest (ramp, fly-back) followed by a hold at x_p = 0, recorded densely;
the runner's turning points after the fly-back give the swings (half the change of x_r between
two turning points), their spacing the frequency, their decay the decay time.
"""

from __future__ import annotations

import math

import numpy as np

from passmd.model import theory, waveforms
from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import Drive, check_drive
from passmd.runtime.validation import check_positive, check_range
from passmd.solver import simulation

__all__ = ["HOLD", "MEASURABLE", "SAMPLES_PER_CYCLE", "at_frequency", "left_after", "ringing_point",
           "stick_ringing", "turns"]

#: Least time (s) the hemispheres are held after the fly-back while the ringing is recorded: two
#: 100 Hz periods (Section 4.1's and Fig. 9a's saw-tooth).
HOLD = 2.0 / PROTOCOL.drive_frequency
#: Recorded samples per cycle of the linear runner-on-contacts vibration
#: (:func:`passmd.model.theory.runner_frequency`): the turning points land within 1/40 of a cycle,
#: a swing within (π/40)²/2 ≈ 0.3 %.
SAMPLES_PER_CYCLE = 40
#: A swing left at the next fly-back counts when it exceeds the measurable step of the
#: critical-amplitude search (:data:`passmd.model.defaults.PROTOCOL`): below it no step read to
#: that resolution can depend on it.
MEASURABLE = PROTOCOL.step_threshold
#: Fewest turning points after the fly-back for a frequency (two whole swings).
_MIN_TURNS = 3


def stick_ringing(drive: Drive, amplitude: float, frequency: float = PROTOCOL.drive_frequency, *,
                  flyback=None, hold: float | None = None) -> dict:
    """The ringing after the first fly-back of a saw-tooth from rest (module docstring).

    Parameters
    ----------
    drive : Drive
        The drive.
    amplitude : float
        Saw-tooth amplitude A (m), 0 < A <= A_max.
    frequency : float
        Frequency of the saw-tooth period before the fly-back (Hz).
    flyback : {"slew", "fixed"} or float, optional
        Overrides the drive's fly-back rule (default None: the drive's;
        :func:`passmd.model.waveforms.flyback_time`).
    hold : float, optional
        Time (s) recorded after the fly-back; default max(:data:`HOLD`, 2/f).

    Returns
    -------
    dict
        ``ringing_frequency_Hz`` (from the first three turning points, as Eq. 15's f_s),
        ``ringing_amplitude_m`` (the first swing), ``ringing_decay_time_s`` (time after the
        fly-back's end until the swing falls to 1/e of the first; NaN if not within the hold),
        ``ringing_hold_s``, ``flyback_time_s``, ``ringing_linear_frequency_Hz`` (the linear estimate,
        :func:`passmd.model.theory.runner_frequency` with the actuators in series, which the first
        swings' micro-slip pulls the measured frequency below), and the envelope: ``swing_times_s``
        (after the fly-back's end) and ``swing_amplitudes_m``. Without turning points (no ringing) the
        frequency is NaN and the swings empty.
    """
    check_drive(drive)
    A = check_range("amplitude", amplitude, 0.0, drive.actuator.full_stroke_amplitude, lower_open=True,
                    unit="m")
    f = check_positive("frequency", frequency, "Hz")
    hold = max(HOLD, 2.0 / f) if hold is None else check_positive("hold", hold, "s")
    t_fb = waveforms.flyback_time(A, drive, flyback)
    waveforms.check_flyback_fits(t_fb, f)
    t_ramp = 1.0 / f - t_fb
    end = t_ramp + t_fb
    wave = waveforms.piecewise_linear([0.0, 0.8 * t_ramp, t_ramp, end, end + hold],
                                      [0.0, 0.8 * A, A, 0.0, 0.0], 1.0 / (end + hold), 1,
                                      settle_window=(0.8 * t_ramp, t_ramp), slip_mark=t_ramp,
                                      kind="ringing probe")
    samples = int(math.ceil(wave.duration * theory.runner_frequency(drive) * SAMPLES_PER_CYCLE)) + 1
    result = simulation.simulate(drive, wave, max_points=max(samples, 1000))
    turns, times, swings = _swings(result.time, result.runner_position, result.runner_velocity, end)
    out = {"ringing_frequency_Hz": math.nan, "ringing_amplitude_m": 0.0, "ringing_decay_time_s": math.nan,
           "ringing_hold_s": hold, "flyback_time_s": t_fb, "swing_times_s": times,
           "swing_amplitudes_m": swings,
           "ringing_linear_frequency_Hz": theory.runner_frequency(drive, in_series=True)}
    if turns.size >= _MIN_TURNS:
        out["ringing_frequency_Hz"] = float(1.0 / (turns[_MIN_TURNS - 1] - turns[0]))
    if swings.size:
        out["ringing_amplitude_m"] = float(swings[0])
        below = np.flatnonzero(swings <= swings[0] / math.e)
        if below.size:
            out["ringing_decay_time_s"] = float(times[below[0]])
    return out


def _swings(time, position, velocity, after: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The turning points after ``after`` (zero crossings of ẋ_r, interpolated) and the swings
    between them: (turning times, swing times, swing sizes), a swing being half the change of x_r
    between successive turning points, timed at their midpoint; times from ``after``."""
    t, x, v = (np.asarray(a, dtype=float) for a in (time, position, velocity))
    keep = t > after
    t, x, v = t[keep], x[keep], v[keep]
    sign = np.sign(v)
    i = np.flatnonzero((sign[:-1] != 0) & (sign[:-1] != sign[1:]))
    w = v[i] / (v[i] - v[i + 1])  # linear interpolation of the crossing
    turn_t = t[i] + w * (t[i + 1] - t[i]) - after
    turn_x = x[i] + w * (x[i + 1] - x[i])
    return turn_t, 0.5 * (turn_t[1:] + turn_t[:-1]), 0.5 * np.abs(np.diff(turn_x))


def left_after(ringing: dict, delay) -> np.ndarray:
    """The swing left ``delay`` s after the fly-back's end (m; interpolated on the envelope).

    Before the first swing: the first swing; after the recorded hold: the last swing recorded (an
    upper bound, the swing only decays). ``delay`` may be an array.
    """
    times, swings = np.asarray(ringing["swing_times_s"]), np.asarray(ringing["swing_amplitudes_m"])
    delay = np.asarray(delay, dtype=float)
    if swings.size == 0:
        return np.zeros_like(delay)
    return np.interp(delay, times, swings)


def at_frequency(ringing: dict, frequency: float) -> dict:
    """What the ringing of :func:`stick_ringing` means for driving at ``frequency``: the swing left
    when the next fly-back starts, one period minus the fly-back after the last one.

    Returns ``ringing_frequency_Hz``, ``ringing_linear_frequency_Hz``, ``ringing_amplitude_m``,
    ``ringing_decay_time_s`` (as measured), ``next_flyback_after_s``, ``ringing_at_next_flyback_m``
    (:func:`left_after`; an upper bound beyond the recorded hold) and ``ringing_affects_steps`` (that
    swing exceeds :data:`MEASURABLE`: a step read at that resolution depends on the ringing's phase).
    """
    delay = 1.0 / check_positive("frequency", frequency, "Hz") - ringing["flyback_time_s"]
    left = float(left_after(ringing, delay))
    return {"ringing_frequency_Hz": ringing["ringing_frequency_Hz"],
            "ringing_linear_frequency_Hz": ringing.get("ringing_linear_frequency_Hz", math.nan),
            "ringing_amplitude_m": ringing["ringing_amplitude_m"],
            "ringing_decay_time_s": ringing["ringing_decay_time_s"], "next_flyback_after_s": delay,
            "ringing_at_next_flyback_m": left, "ringing_affects_steps": bool(left > MEASURABLE)}


def ringing_point(drive: Drive, amplitude: float, frequency: float = PROTOCOL.drive_frequency) -> dict:
    """:func:`stick_ringing` for a sweep: scalars, and the envelope as arrays (for the cache)."""
    out = stick_ringing(drive, amplitude, frequency)
    return {**out, "swing_times_s": np.asarray(out["swing_times_s"]),
            "swing_amplitudes_m": np.asarray(out["swing_amplitudes_m"])}


def turns(values, resolution) -> list[int]:
    """Indices i where a curve turns: the change into point i and the change out of it have opposite
    signs, each larger than the resolution (the larger of its two points'); NaN points are skipped."""
    y = [float("nan") if v is None else float(v) for v in values]
    res = [float(r) for r in resolution]
    keep = [i for i, v in enumerate(y) if math.isfinite(v)]
    found, last = [], None  # last: (index, sign) of the last change larger than the resolution
    for a, b in zip(keep, keep[1:], strict=False):
        change = y[b] - y[a]
        if abs(change) <= max(res[a], res[b]):
            continue
        sign = 1 if change > 0 else -1
        if last is not None and sign != last[1]:
            found.append(last[0])  # where the last change ended: the extremum
        last = (b, sign)
    return found
