"""Desired piezo position x_p(t) as piecewise-linear breakpoints (Fig. 1d, Fig. 3c, Fig. 8b).

A :class:`Waveform` holds the breakpoints of the whole run, the period, and per
period the phase marks the measures of :mod:`passmd.solver.simulation` need:

* the *settle window* — the last part of the stick phase, over which the runner's
  position is averaged (the runner has no damping besides contact micro-slip and is
  still vibrating at the end of a stick phase, so one instant is not a position);
* the *slip mark* — the start of the fast edge, from which the back-step is measured.

Conventions (decided here, documented in the model chapter): the run starts at t = 0
at rest with virgin contacts and x_p = 0, with the slow ramp first.

Constructors here are pure: they take parameters and never simulate. The optimized
waveform of Section 5.1 (Fig. 8b, Eq. 15) is :mod:`passmd.model.optimized_waveform`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from passmd.model.parameters import PLAUSIBLE_RANGES, Drive, check_drive
from passmd.model.tables import Assumption, check_flyback_rule
from passmd.runtime.validation import (
    InputError,
    check_count,
    check_positive,
    check_range,
    shown,
)

#: Fraction of the stick phase (at its end) over which the settled position is averaged.
SETTLE_FRACTION = 0.2

ASSUMPTIONS: tuple[Assumption, ...] = (
    Assumption(
        key="settled_position",
        symbol="x̄_r",
        value=f"mean of x_r − x_p over the last {SETTLE_FRACTION:.0%} of each stick phase, + x_p at its end",
        unit="m",
        rationale=(
            "The runner has no damping but contact micro-slip and still vibrates (nm) at the end of a "
            "stick phase; the paper reads positions 'after n periods' (Fig. 9a) without saying how. "
            "Positions are the runner's at the end of each stick phase with the vibration averaged out; "
            "a step is the change of that position from one period to the next."
        ),
        sensitivity="Model chapter: step sizes for settle fractions 0.1–0.4.",
    ),
    Assumption(
        key="flyback_duration",
        symbol="t_fb",
        value="slew-rate limited: (A / A_max) · 300 V / (150 V/µs)",
        unit="s",
        rationale=(
            "Section 2 gives 300 V_pp and 150 V/µs; a fly-back of amplitude A needs A/A_max of the "
            "full 2 µs stroke. The alternatives, a fixed 2 µs or a stated time, are a drive's choice "
            "(the drive file's amplifier.flyback, --flyback) and move the critical amplitude by several nm."
        ),
        sensitivity="Critical-amplitude chapters: A_c with both fly-back rules.",
    ),
)


@dataclass(frozen=True)
class Waveform:
    """Piecewise-linear piezo trajectory over a whole run.

    Attributes
    ----------
    times, positions : ndarray
        Breakpoints (s, m), strictly increasing times starting at 0.
    period : float
        Driving period T = 1/f in s.
    periods : int
        Number of periods in the run.
    settle_windows : ndarray, shape (periods, 2)
        Start and end time of each period's settle window (both breakpoints).
    slip_marks : ndarray, shape (periods,)
        Time at which each period's fast (slip) edge starts (a breakpoint).
    kind : str
        ``"sawtooth"``, ``"optimized"`` or ``"custom"``.
    amplitude : float
        Actuation amplitude A in m (the largest |x_p|).
    """

    times: np.ndarray
    positions: np.ndarray
    period: float
    periods: int
    settle_windows: np.ndarray
    slip_marks: np.ndarray
    kind: str = "custom"
    amplitude: float = 0.0

    def __post_init__(self):
        t = np.asarray(self.times, dtype=float)
        x = np.asarray(self.positions, dtype=float)
        if t.ndim != 1 or t.shape != x.shape or t.size < 2:
            raise ValueError(
                f"times/positions must be 1-D arrays of equal length >= 2, got shapes {t.shape}, {x.shape}"
            )
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(x))):
            raise ValueError("waveform times and positions must be finite numbers")
        if t[0] != 0.0:
            raise InputError(f"times[0] = {shown(t[0])} is not allowed: a waveform starts at t = 0",
                             name="times", value=t[0])
        steps = np.diff(t)
        if np.any(steps <= 0):
            i = int(np.flatnonzero(steps <= 0)[0])
            raise InputError(f"waveform times must increase strictly: times[{i + 1}] = {shown(t[i + 1])} <= "
                             f"times[{i}] = {shown(t[i])}", name="times", value=t[i + 1])
        check_positive("period", self.period, "s")
        check_count("periods", self.periods)
        w = np.asarray(self.settle_windows, dtype=float).reshape(-1, 2)
        m = np.asarray(self.slip_marks, dtype=float).reshape(-1)
        if w.shape[0] != self.periods or m.shape[0] != self.periods:
            raise ValueError("settle_windows and slip_marks need one entry per period")
        tset = set(t.tolist())
        for value in np.concatenate([w.ravel(), m]):
            if float(value) not in tset:
                raise InputError(f"phase mark t = {shown(value)} is not a breakpoint of the waveform",
                                 name="settle_windows, slip_marks", value=value)
        if not isinstance(self.kind, str):
            raise InputError(f"kind = {shown(self.kind)} is not allowed: must be a str", name="kind",
                             value=self.kind)
        check_range("amplitude", self.amplitude, 0.0, unit="m")
        object.__setattr__(self, "times", t)
        object.__setattr__(self, "positions", x)
        object.__setattr__(self, "settle_windows", w)
        object.__setattr__(self, "slip_marks", m)
        object.__setattr__(self, "periods", int(self.periods))

    @property
    def duration(self) -> float:
        """Length of the run in s."""
        return float(self.times[-1])

    @property
    def frequency(self) -> float:
        """Driving frequency f = 1/T in Hz."""
        return 1.0 / self.period

    def position(self, t):
        """x_p(t) by linear interpolation (m)."""
        return np.interp(t, self.times, self.positions)

    def velocity(self, t):
        """dx_p/dt (m/s), right-continuous at breakpoints."""
        t = np.asarray(t, dtype=float)
        slopes = np.diff(self.positions) / np.diff(self.times)
        idx = np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, slopes.size - 1)
        return slopes[idx]

    def mirrored(self) -> Waveform:
        """The same waveform with x_p → −x_p (drives the runner the other way)."""
        return Waveform(self.times, -self.positions, self.period, self.periods, self.settle_windows,
                        self.slip_marks, self.kind, self.amplitude)


def flyback_rule(drive: Drive, flyback=None) -> str | float:
    """The fly-back rule a run of ``drive`` uses: ``flyback`` if given (an explicit override), else the
    drive's own (:attr:`passmd.model.tables.Amplifier.flyback`): ``"slew"``, ``"fixed"`` or a time in s."""
    return drive.amplifier.flyback if flyback is None else check_flyback_rule("flyback", flyback)


def flyback_time(amplitude: float, drive: Drive, flyback=None) -> float:
    """Duration of the fast edge of a saw-tooth (Section 2).

    Parameters
    ----------
    amplitude : float
        Actuation amplitude A in m.
    drive : Drive
        Supplies the amplifier (300 V_pp, 150 V/µs, its fly-back rule) and the actuator's
        full-stroke amplitude.
    flyback : {"slew", "fixed"} or float, optional
        Overrides the drive's rule (:attr:`passmd.model.tables.Amplifier.flyback`; default None:
        the drive's). ``"slew"``: slew-rate limited, (A / A_max) · V_pp / SR (shorter at small A);
        ``"fixed"``: the full-stroke time V_pp / SR (2 µs) at every amplitude; a number: that
        time in s at every amplitude.
    """
    check_drive(drive)
    rule = flyback_rule(drive, flyback)
    return _flyback_time(check_range("amplitude", amplitude, 0.0, unit="m"), drive, rule)


def _flyback_time(amplitude: float, drive: Drive, flyback) -> float:
    """:func:`flyback_time` of arguments its caller has checked (A >= 0 in m, a Drive, a rule or None)."""
    rule = drive.amplifier.flyback if flyback is None else flyback
    full = drive.amplifier.full_stroke_time
    if rule == "fixed":
        return full
    if rule == "slew":
        return amplitude / drive.actuator.full_stroke_amplitude * full
    return float(rule)


#: Fewest spacings of double-precision time (at the run's end) a fly-back must last, so
#: that its start and end are distinct breakpoints in every period (rounding of k·T + t).
FLYBACK_SPACINGS = 4


def _check_flyback_resolved(t_fb: float, amplitude: float, drive: Drive, period: float, periods: int) -> None:
    """Refuse a slew-limited fly-back too short to be told from its period's end in double precision."""
    duration = periods * period
    t_min = FLYBACK_SPACINGS * float(np.spacing(duration))
    if not t_fb >= t_min:
        per = drive.actuator.full_stroke_amplitude / drive.amplifier.full_stroke_time  # amplitude per second
        raise InputError(
            f"amplitude = {shown(amplitude)} is out of range: its fly-back (A/A_max)·V_pp/SR = {t_fb:.4g} s "
            f"is shorter than {t_min:.4g} s, which double-precision time cannot resolve over the "
            f"{duration:.4g} s run; amplitude must be >= {t_min * per:.4g} m",
            name="fly-back time", value=t_fb, unit="s", limits=((">=", t_min),),
            why=f"hard limit: double-precision time cannot resolve a shorter fly-back over the "
                f"{duration:.4g} s run",
        ).derived_from("amplitude", amplitude, per, "the slew-limited fly-back time (A/A_max)·V_pp/SR")


def sawtooth(
    amplitude: float,
    frequency: float,
    drive: Drive,
    periods: int = 3,
    flyback=None,
    settle_fraction: float = SETTLE_FRACTION,
) -> Waveform:
    """Standard saw-tooth: slow ramp 0 → A (stick), fast fly-back A → 0 (slip) (Fig. 1d, 3c).

    Parameters
    ----------
    amplitude : float
        Actuation amplitude A in m, 0 ≤ A ≤ the actuator's full-stroke amplitude (300 V_pp).
    frequency : float
        Driving frequency f in Hz; the fly-back must fit in the period.
    drive : Drive
        The drive (amplifier and actuator limits).
    periods : int
        Number of periods.
    flyback : {"slew", "fixed"} or float, optional
        Fly-back rule overriding the drive's (default None: the drive's), see :func:`flyback_time`.
    settle_fraction : float
        Part of the ramp, at its end, used as the settle window.
    """
    a_max = check_drive(drive).actuator.full_stroke_amplitude
    A = check_range("amplitude", amplitude, 0.0, a_max, unit="m")
    f = PLAUSIBLE_RANGES["frequency"].check("frequency", frequency,
                                            allow_extrapolation=drive.allow_extrapolation)
    frac = check_range("settle_fraction", settle_fraction, 0.0, 1.0, lower_open=True, upper_open=True)
    periods = check_count("periods", periods)
    rule = flyback_rule(drive, flyback)
    T = 1.0 / f
    t_fb = _flyback_time(A, drive, rule)
    if A == 0.0:
        t_fb = min(drive.amplifier.full_stroke_time, 0.5 * T)  # any edge: x_p stays 0
    check_flyback_fits(t_fb, f)
    if A > 0.0 and rule == "slew":
        _check_flyback_resolved(t_fb, A, drive, T, periods)
    t_ramp = T - t_fb
    times, positions, windows, marks = [0.0], [0.0], [], []
    for k in range(periods):
        t0 = k * T
        ws = t0 + (1.0 - frac) * t_ramp
        we = t0 + t_ramp
        times += [ws, we, t0 + T]
        positions += [A * (1.0 - frac), A, 0.0]
        windows.append((ws, we))
        marks.append(we)
    return Waveform(np.array(times), np.array(positions), T, periods, np.array(windows), np.array(marks),
                    "sawtooth", A)


def check_flyback_fits(t_fb: float, frequency: float) -> None:
    """Refuse a frequency whose half period is not longer than the fly-back ``t_fb`` (s)."""
    if t_fb >= 0.5 * (1.0 / frequency):  # as the callers' period T = 1/f
        f_max = 0.5 / t_fb
        raise InputError(
            f"frequency = {shown(frequency)} is out of range: the fly-back of {t_fb * 1e6:.3g} µs must take "
            f"less than half a period, so frequency must be < {f_max:.6g} Hz",
            name="frequency", value=frequency, unit="Hz", limits=(("<", f_max),),
            why=f"the fly-back of {t_fb * 1e6:.3g} µs must take less than half a period")


def piecewise_linear(
    period_times,
    period_positions,
    frequency: float,
    periods: int,
    settle_window: tuple[float, float],
    slip_mark: float,
    kind: str = "custom",
) -> Waveform:
    """A user-given periodic piecewise-linear waveform.

    Parameters
    ----------
    period_times, period_positions : array_like
        Breakpoints of one period, times in [0, T] strictly increasing from 0 to T, positions
        in m with ``period_positions[0] == period_positions[-1]`` (periodic).
    frequency : float
        f = 1/T in Hz.
    periods : int
        Number of periods.
    settle_window : (float, float)
        Settle window of each period, times within the period (added as breakpoints).
    slip_mark : float
        Start of the slip edge within the period (must be a breakpoint).
    kind : str
        Label.
    """
    f = check_positive("frequency", frequency, "Hz")
    T = 1.0 / f
    try:
        pt = np.asarray(period_times, dtype=float)
        px = np.asarray(period_positions, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"period_times = {shown(period_times)}, period_positions = "
                         f"{shown(period_positions)}: must be arrays of numbers",
                         name="period_times, period_positions") from None
    if pt.ndim != 1 or pt.shape != px.shape or pt.size < 2:
        raise ValueError("period_times and period_positions must be 1-D arrays of equal length >= 2")
    if not np.isclose(pt[0], 0.0, atol=0) or not np.isclose(pt[-1], T, rtol=1e-12):
        raise ValueError(
            f"period_times must run from 0 to the period T = {shown(T)} s, got {shown(pt[0])} … "
            f"{shown(pt[-1])}"
        )
    if np.any(np.diff(pt) <= 0):
        raise ValueError("period_times must increase strictly (a waveform must be monotone in time)")
    if px[0] != px[-1]:
        raise ValueError(
            f"period_positions[0] = {shown(px[0])} != period_positions[-1] = {shown(px[-1])}: not periodic"
        )
    periods = check_count("periods", periods)
    if not isinstance(kind, str):
        raise InputError(f"kind = {shown(kind)} is not allowed: must be a str", name="kind", value=kind)
    if np.ndim(settle_window) != 1 or np.size(settle_window) != 2:
        raise InputError(f"settle_window = {shown(settle_window)} is not allowed: must be a (start, end) "
                         "pair of times within the period", name="settle_window", value=settle_window)
    ws, we = (check_range("settle_window", v, 0.0, T, unit="s") for v in settle_window)
    if not ws < we:
        raise InputError(f"settle_window = {shown(settle_window)} is not allowed: start must be < end",
                         name="settle_window", value=settle_window)
    check_range("slip_mark", slip_mark, 0.0, T, unit="s")
    if not np.any(pt == slip_mark):
        raise InputError(f"slip_mark = {shown(slip_mark)} is not a breakpoint of the period",
                         name="slip_mark", value=slip_mark)
    extra = [v for v in (ws, we) if not np.any(np.isclose(pt, v, rtol=0, atol=1e-15 * T))]
    if extra:
        pt_full = np.sort(np.concatenate([pt, extra]))
        px = np.interp(pt_full, pt, px)
        pt = pt_full
    ws = pt[np.argmin(np.abs(pt - ws))]
    we = pt[np.argmin(np.abs(pt - we))]
    times, positions = [pt[0]], [px[0]]
    for k in range(int(periods)):
        times += list(k * T + pt[1:])
        positions += list(px[1:])
    windows = np.array([(k * T + ws, k * T + we) for k in range(int(periods))])
    marks = np.array([k * T + slip_mark for k in range(int(periods))])
    times = np.array(times)
    # snap marks onto the breakpoints they were computed from (rounding of k*T + t)
    windows = times[np.searchsorted(times, windows - 1e-12 * T)]
    marks = times[np.searchsorted(times, marks - 1e-12 * T)]
    amplitude = float(np.max(np.abs(px)))
    return Waveform(times, np.array(positions), T, int(periods), windows, marks, kind, amplitude)

