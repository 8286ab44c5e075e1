"""Desired piezo position x_p(t) as piecewise-linear breakpoints (Fig. 1d, Fig. 3c, Fig. 8b).

A :class:`Waveform` holds the breakpoints of the whole run, the period, and per
period the phase marks the measures of :mod:`passmd.dynamics` need:

* the *settle window* — the last part of the stick phase, over which the runner's
  position is averaged (the runner has no damping besides contact micro-slip and is
  still vibrating at the end of a stick phase, so one instant is not a position);
* the *slip mark* — the start of the fast edge, from which the back-step is measured.

Conventions (decided here, documented in the model chapter): the run starts at t = 0
at rest with virgin contacts and x_p = 0, with the slow ramp first.

Constructors here are pure: they take parameters and never simulate. The optimized
waveform of Section 5.1 (Fig. 8b, Eq. 15) is :mod:`passmd.optimized_waveform`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from passmd._validation import check_choice, check_count, check_positive, check_range
from passmd.parameters import PLAUSIBLE_RANGES, Assumption, Drive

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
            "full 2 µs stroke. The alternative, a fixed 2 µs, is available (flyback='fixed') and "
            "moves the critical amplitude by several nm."
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
            raise ValueError(f"times[0] = {t[0]!r} is not allowed: a waveform starts at t = 0")
        steps = np.diff(t)
        if np.any(steps <= 0):
            i = int(np.flatnonzero(steps <= 0)[0])
            raise ValueError(
                f"waveform times must increase strictly: times[{i + 1}] = {t[i + 1]!r} <= "
                f"times[{i}] = {t[i]!r}"
            )
        check_positive("period", self.period, "s")
        check_count("periods", self.periods)
        w = np.asarray(self.settle_windows, dtype=float).reshape(-1, 2)
        m = np.asarray(self.slip_marks, dtype=float).reshape(-1)
        if w.shape[0] != self.periods or m.shape[0] != self.periods:
            raise ValueError("settle_windows and slip_marks need one entry per period")
        tset = set(t.tolist())
        for value in np.concatenate([w.ravel(), m]):
            if float(value) not in tset:
                raise ValueError(f"phase mark t = {value!r} is not a breakpoint of the waveform")
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
        return Waveform(
            self.times,
            -self.positions,
            self.period,
            self.periods,
            self.settle_windows,
            self.slip_marks,
            self.kind,
            self.amplitude,
        )


def flyback_time(amplitude: float, drive: Drive, flyback: str = "slew") -> float:
    """Duration of the fast edge of a saw-tooth (Section 2).

    Parameters
    ----------
    amplitude : float
        Actuation amplitude A in m.
    drive : Drive
        Supplies the amplifier (300 V_pp, 150 V/µs) and the actuator's full-stroke amplitude.
    flyback : {"slew", "fixed"}
        ``"slew"``: slew-rate limited, (A / A_max) · V_pp / SR (shorter at small A);
        ``"fixed"``: the full-stroke time V_pp / SR (2 µs) at every amplitude.
    """
    check_choice("flyback", flyback, ("slew", "fixed"))
    full = drive.amplifier.full_stroke_time
    if flyback == "fixed":
        return full
    return amplitude / drive.actuator.full_stroke_amplitude * full


def sawtooth(
    amplitude: float,
    frequency: float,
    drive: Drive,
    periods: int = 3,
    flyback: str = "slew",
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
    flyback : {"slew", "fixed"}
        Fly-back rule, see :func:`flyback_time`.
    settle_fraction : float
        Part of the ramp, at its end, used as the settle window.
    """
    a_max = drive.actuator.full_stroke_amplitude
    A = check_range("amplitude", amplitude, 0.0, a_max, unit="m")
    f = PLAUSIBLE_RANGES["frequency"].check("frequency", frequency,
                                            allow_extrapolation=drive.allow_extrapolation)
    frac = check_range("settle_fraction", settle_fraction, 0.0, 1.0, lower_open=True, upper_open=True)
    periods = check_count("periods", periods)
    periods = int(periods)
    T = 1.0 / f
    t_fb = flyback_time(A, drive, flyback)
    if A == 0.0:
        t_fb = min(drive.amplifier.full_stroke_time, 0.5 * T)  # any edge: x_p stays 0
    if t_fb >= 0.5 * T:
        f_max = 0.5 / t_fb
        raise ValueError(
            f"frequency = {f!r} is out of range: the fly-back of {t_fb * 1e6:.3g} µs must take less than "
            f"half a period, so frequency must be < {f_max:.6g} Hz"
        )
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
    return Waveform(
        np.array(times),
        np.array(positions),
        T,
        periods,
        np.array(windows),
        np.array(marks),
        "sawtooth",
        A,
    )


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
    pt = np.asarray(period_times, dtype=float)
    px = np.asarray(period_positions, dtype=float)
    if pt.ndim != 1 or pt.shape != px.shape or pt.size < 2:
        raise ValueError("period_times and period_positions must be 1-D arrays of equal length >= 2")
    if not np.isclose(pt[0], 0.0, atol=0) or not np.isclose(pt[-1], T, rtol=1e-12):
        raise ValueError(
            f"period_times must run from 0 to the period T = {T!r} s, got {pt[0]!r} … {pt[-1]!r}"
        )
    if np.any(np.diff(pt) <= 0):
        raise ValueError("period_times must increase strictly (a waveform must be monotone in time)")
    if px[0] != px[-1]:
        raise ValueError(
            f"period_positions[0] = {px[0]!r} != period_positions[-1] = {px[-1]!r}: not periodic"
        )
    periods = check_count("periods", periods)
    ws, we = (check_range("settle_window", v, 0.0, T, unit="s") for v in settle_window)
    if not ws < we:
        raise ValueError(f"settle_window = {settle_window!r} is not allowed: start must be < end")
    check_range("slip_mark", slip_mark, 0.0, T, unit="s")
    if not np.any(pt == slip_mark):
        raise ValueError(f"slip_mark = {slip_mark!r} is not a breakpoint of the period")
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

