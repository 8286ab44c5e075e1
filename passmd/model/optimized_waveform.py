"""The optimized driving waveform of Section 5.1 (Fig. 8b, Eq. 15).

After the fly-back the hemispheres wait a settling time t_s = 1/(2 f_s) for the runner's
micro-vibration to turn forward, then accelerate it within the stick limit,
(V_a − V_r) t_a = u_x,max, then stop so the runner slips forward.

This module builds the waveform from a given design (:class:`OptimizedDesign`) and never
simulates. The design from a simulated saw-tooth response of the drive (f_s and V_r
measured, Eq. 15 applied) is :func:`passmd.protocols.eq15.optimized_design`.

Eq. 15's period needs t_s + t_a, the fly-back and a slow ramp: above
:func:`highest_fitting_frequency` it does not fit. :func:`optimized` then refuses (one line
naming that frequency) unless a truncated waveform is asked for by name (``short_period="cut"``
or ``"skip"``, the velocity chapter's study of Fig. 9b above 110 kHz), whose ``kind``
says it is truncated.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import Drive, check_drive
from passmd.model.tables import Assumption
from passmd.model.waveforms import (
    SETTLE_FRACTION,
    Waveform,
    _flyback_time,
    check_flyback_fits,
    flyback_rule,
    piecewise_linear,
    sawtooth,
)
from passmd.runtime.validation import (
    InputError,
    check_choice,
    check_count,
    check_positive,
    check_range,
    shown,
)

#: Saw-tooth frequency whose response the optimized waveform is designed from (Fig. 9a's 100 Hz,
#: the protocol's driving frequency; :func:`passmd.protocols.eq15.optimized_design`).
RESPONSE_FREQUENCY = PROTOCOL.drive_frequency
#: Shortest share of T − t_fb that the slow ramp of an optimized period keeps when the settling
#: time has to be cut (high frequencies).
MIN_RAMP_FRACTION = 0.5
#: What :func:`optimized` does when Eq. 15's period does not fit: refuse (the default), or build
#: a truncated study waveform with t_s cut or skipped (assumption ``optimized_short_period``).
SHORT_PERIOD_RULES = ("refuse", "cut", "skip")

ASSUMPTIONS: tuple[Assumption, ...] = (
    Assumption(
        key="optimized_response",
        symbol="f_s, V_r",
        value=(
            f"two saw-tooth periods at {RESPONSE_FREQUENCY:g} Hz from rest; f_s = 1/(z₃ − z₁), z_i the "
            "zero crossings of ẋ_r − ẋ_p after the first fly-back; V_r = ẋ_r at the end of t_s"
        ),
        unit="Hz, m/s",
        rationale=(
            "Section 5.1 measures f_s and V_r 'by analyzing the movement of the runner' under the "
            "saw-tooth (Fig. 8a) without saying at which frequency or how. The first full cycle of "
            "the free micro-vibration after the slip is the one the waveform exploits; V_r is the "
            "runner's velocity where the acceleration starts (point 4). The design is made once "
            "per drive and used at every driving frequency ('when these influencing parameters "
            "were varied, the input parameters for the optimized waveform were respectively changed'). "
            "The command line designs the same way by default and says so; --design-response driving "
            "reads the response at the driving frequency instead, whose vibration cycle the next "
            "fly-back cuts short as f approaches f_s."
        ),
        sensitivity="Chapter Beyond Eq. (15): step at 100 Hz against t_s over two vibration periods.",
    ),
    Assumption(
        key="optimized_free_parameter",
        symbol="V_a, u_x,max",
        value=(
            "V_a = amplifier limit A_max·SR/V_pp (0.101 m/s for R = 1 mm); u_x,max = the smallest "
            "presliding displacement of the contacts (Eq. 10, side 2)"
        ),
        unit="m/s, m",
        rationale=(
            "Eq. 15 fixes only (V_a − V_r)·t_a = u_x,max; the text asks for the largest V_a that keeps "
            "the stick condition, which Eq. 15 meets for any V_a, so the largest V_a the amplifier "
            "can deliver (slew-rate limit) is taken. With rigid actuators every hemisphere moves "
            "with x_p, so all contacts share u; the side with the smaller normal force slips "
            "first, hence its u_x,max."
        ),
        sensitivity="Chapter Beyond Eq. (15): scipy optimisation over t_s, t_a, Δ_a.",
    ),
    Assumption(
        key="optimized_first_period",
        symbol="–",
        value="period 1 is a saw-tooth (ramp 0 → A, fly-back); periods 2… are optimized",
        unit="–",
        rationale=(
            "'Because the optimization was started after the first period' (Section 5.2): there is "
            "no micro-vibration to exploit before the first slip."
        ),
        sensitivity="Only the first period; steps are compared from period 2 on.",
    ),
    Assumption(
        key="optimized_short_period",
        symbol="t_s, t_a",
        value=(
            f"the slow ramp keeps ≥ {MIN_RAMP_FRACTION:g}·(T − t_fb) and ≥ A/V_max; above the highest "
            "frequency at which t_s + t_a then fit, a designer's waveform is refused; the study of "
            "Fig. 9b, short_period='cut': t_s is cut to the time left, then t_a (at constant V_a); "
            "'skip': t_s = 0"
        ),
        unit="s",
        rationale=(
            "The paper says only that above 110 kHz there is 'not enough time for settling' and that "
            "the optimized waveform's velocity then 'began decreasing'. Cutting the settling time "
            "(default) is the reading that makes the velocity decrease; skipping it is the "
            "alternative. Both never violate the slew-rate limit and never fail."
        ),
        sensitivity="Velocity chapter: Fig. 9b and the settling-fits flag per frequency.",
    ),
)


def max_piezo_velocity(drive: Drive) -> float:
    """Fastest hemisphere velocity the amplifier allows, V_max = A_max · SR / V_pp (m/s), Section 2."""
    return check_drive(drive).actuator.full_stroke_amplitude / drive.amplifier.full_stroke_time


@dataclass(frozen=True)
class OptimizedDesign:
    """Parameters of the optimized waveform (Eq. 15, Fig. 8b) and what they were derived from.

    Attributes
    ----------
    settling_time : float
        t_s = 1/(2 f_s) in s: hemispheres frozen after the fly-back.
    acceleration_time : float
        t_a in s: duration of the fast forward segment.
    acceleration_amplitude : float
        Δ_a in m: its amplitude; V_a = Δ_a / t_a.
    micro_vibration_frequency : float
        f_s in Hz, measured from the saw-tooth response.
    runner_velocity : float
        V_r in m/s, the runner's velocity at the end of t_s in the saw-tooth response.
    presliding : float
        u_x,max in m used in Eq. 15.
    response_frequency : float
        Frequency (Hz) of the saw-tooth whose response was analysed (0 if given by hand).
    """

    settling_time: float
    acceleration_time: float
    acceleration_amplitude: float
    micro_vibration_frequency: float = float("nan")
    runner_velocity: float = 0.0
    presliding: float = float("nan")
    response_frequency: float = 0.0

    def __post_init__(self):
        check_range("settling_time", self.settling_time, 0.0, unit="s")
        check_positive("acceleration_time", self.acceleration_time, "s")
        check_positive("acceleration_amplitude", self.acceleration_amplitude, "m")

    @property
    def acceleration_velocity(self) -> float:
        """V_a = Δ_a / t_a in m/s."""
        return self.acceleration_amplitude / self.acceleration_time

    def as_dict(self) -> dict:
        """Fields and V_a in SI units, keys carrying the unit (JSON-ready)."""
        return {
            "settling_time_s": self.settling_time,
            "acceleration_time_s": self.acceleration_time,
            "acceleration_amplitude_m": self.acceleration_amplitude,
            "acceleration_velocity_m_per_s": self.acceleration_velocity,
            "micro_vibration_frequency_Hz": self.micro_vibration_frequency,
            "runner_velocity_m_per_s": self.runner_velocity,
            "presliding_m": self.presliding,
            "response_frequency_Hz": self.response_frequency,
        }


def highest_fitting_frequency(design: OptimizedDesign, amplitude: float, drive: Drive, *,
                              flyback=None, min_ramp_fraction: float = MIN_RAMP_FRACTION) -> float:
    """Highest driving frequency (Hz) at which one Eq. 15 period fits whole (Fig. 8b).

    A period holds t_s, t_a, the slow ramp and the fly-back t_fb; the slow ramp keeps at least
    ``min_ramp_fraction``·(T − t_fb) and A/V_max (:func:`optimized_timing`). So Eq. 15 fits when

        T − t_fb >= max((t_s + t_a) / (1 − min_ramp_fraction), t_s + t_a + A/V_max),  T >= 2 t_fb,

    and this is 1/T at equality. At or below it :func:`optimized_timing` reports
    ``settling_fits``; above it the settling time would have to be cut.

    Parameters
    ----------
    design : OptimizedDesign
        The Eq. 15 design (t_s, t_a).
    amplitude : float
        Actuation amplitude A in m (sets the fly-back's duration).
    drive : Drive
        The drive (its amplifier's slew-rate limit).
    flyback : {"slew", "fixed"} or float, optional
        Overrides the drive's fly-back rule (default None: the drive's;
        :func:`passmd.model.waveforms.flyback_time`).
    min_ramp_fraction : float
        Least share of T − t_fb the slow ramp keeps (assumption ``optimized_short_period``).
    """
    if not isinstance(design, OptimizedDesign):
        raise InputError(f"design = {shown(design)} is not an OptimizedDesign", name="design", value=design)
    a_max = check_drive(drive).actuator.full_stroke_amplitude
    A = check_range("amplitude", amplitude, 0.0, a_max, lower_open=True, unit="m")
    frac = check_range("min_ramp_fraction", min_ramp_fraction, 0.0, 1.0, lower_open=True, upper_open=True)
    t_fb = _flyback_time(A, drive, flyback_rule(drive, flyback))
    need = design.settling_time + design.acceleration_time
    period = t_fb + max(need / (1.0 - frac), need + A / max_piezo_velocity(drive))
    return 1.0 / max(period, 2.0 * t_fb)


def check_fits(design: OptimizedDesign, amplitude: float, frequency: float, drive: Drive, *,
               flyback=None, min_ramp_fraction: float = MIN_RAMP_FRACTION) -> float:
    """``frequency`` if one Eq. 15 period fits whole at it, else a one-line refusal naming the
    highest frequency that fits (:func:`highest_fitting_frequency`).

    Raises
    ------
    InputError
        A ``ValueError`` named ``frequency``, its limit the highest fitting frequency.
    """
    f = check_positive("frequency", frequency, "Hz")
    f_max = highest_fitting_frequency(design, amplitude, drive, flyback=flyback,
                                      min_ramp_fraction=min_ramp_fraction)
    timing = optimized_timing(design, amplitude, f, drive, flyback=flyback,
                              min_ramp_fraction=min_ramp_fraction)
    if timing["settling_fits"]:
        return f
    why = (f"Eq. 15: the settling time t_s = {design.settling_time * 1e6:.4g} µs and the acceleration "
           f"t_a = {design.acceleration_time * 1e6:.4g} µs, with the fly-back "
           f"({timing['flyback_time_s'] * 1e6:.3g} µs) and the slow ramp (at least {min_ramp_fraction:.0%} "
           f"of the rest of the period), need a period of {1e6 / f_max:.4g} µs")
    raise InputError(
        f"frequency = {shown(f)} is out of range for the Eq. 15 waveform: must be <= {f_max:.4g} Hz, the "
        f"highest frequency at which it fits this drive at A = {amplitude * 1e9:.4g} nm ({why}); a truncated "
        "waveform is short_period='cut' or 'skip'", name="frequency", value=f, unit="Hz",
        limits=(("<=", f_max),), why=why)


def optimized_timing(
    design: OptimizedDesign,
    amplitude: float,
    frequency: float,
    drive: Drive,
    *,
    flyback=None,
    min_ramp_fraction: float = MIN_RAMP_FRACTION,
    short_period: str = "cut",
) -> dict:
    """Fit one optimized period (Fig. 8b) into T = 1/f: the times actually used.

    One period runs: hold x_p = 0 for t_s, rise by Δ_a in t_a, slow ramp to A, fly-back to 0
    in t_fb (slew-rate limited like the saw-tooth's). The slow ramp keeps at least
    ``min_ramp_fraction``·(T − t_fb) and at least A/V_max (so no segment is faster than the
    amplifier allows). When t_s + t_a does not fit in the rest (assumption
    ``optimized_short_period``):

    * ``short_period="cut"`` (default): t_s is cut to what is left (down to 0);
    * ``short_period="skip"``: t_s = 0 (waiting part of a vibration cycle lands at a
      phase the design did not choose);
    * ``short_period="refuse"``: :func:`check_fits` refuses the frequency;

    then, if t_a alone does not fit, t_a is cut keeping V_a (so Δ_a shrinks). At high
    frequencies the waveform turns into a saw-tooth with a fast first segment.

    Returns
    -------
    dict
        ``period_s``, ``flyback_time_s``, ``settling_time_s``, ``acceleration_time_s``,
        ``acceleration_amplitude_m``, ``ramp_time_s``, ``settling_fits`` (the full t_s fits),
        ``acceleration_fits`` (the full t_a fits).

    Raises
    ------
    ValueError
        Bad input, or a fly-back longer than half a period (as :func:`~passmd.model.waveforms.sawtooth`).
    """
    if not isinstance(design, OptimizedDesign):
        raise InputError(f"design = {shown(design)} is not an OptimizedDesign", name="design", value=design)
    check_choice("short_period", short_period, SHORT_PERIOD_RULES)
    a_max = check_drive(drive).actuator.full_stroke_amplitude
    A = check_range("amplitude", amplitude, 0.0, a_max, lower_open=True, unit="m")
    f = check_positive("frequency", frequency, "Hz")
    frac = check_range("min_ramp_fraction", min_ramp_fraction, 0.0, 1.0, lower_open=True, upper_open=True)
    rule = flyback_rule(drive, flyback)
    T = 1.0 / f
    t_fb = _flyback_time(A, drive, rule)
    check_flyback_fits(t_fb, f)
    if design.acceleration_amplitude >= A:
        d_a = design.acceleration_amplitude
        raise InputError(
            f"acceleration_amplitude = {shown(d_a)} is out of range: must be < the actuation amplitude "
            f"A = {shown(A)} m (Eq. 15: the fast segment Δ_a = V_a t_a ends below A)",
            name="acceleration_amplitude", value=d_a, unit="m", limits=(("<", A),),
            why="Eq. 15: the fast segment Δ_a = V_a t_a must end below the actuation amplitude A",
            quantity="the Eq. 15 acceleration amplitude Δ_a = V_a t_a", source="amplitude", source_value=A,
            source_limits=((">", d_a),))
    ramp_min = max(frac * (T - t_fb), A / max_piezo_velocity(drive))
    room = T - t_fb - ramp_min  # > 0: t_fb < T/2 and A/V_max <= t_fb (slew) or < 2 µs (fixed)
    t_s, t_a, d_a = design.settling_time, design.acceleration_time, design.acceleration_amplitude
    settling_fits = t_s + t_a <= room
    acceleration_fits = t_a <= room
    if short_period == "refuse" and not settling_fits:
        check_fits(design, A, f, drive, flyback=flyback, min_ramp_fraction=frac)
    if not acceleration_fits:
        t_a = room
        d_a = design.acceleration_velocity * t_a
    t_s = min(t_s, room - t_a) if (settling_fits or short_period == "cut") else 0.0
    return {
        "period_s": T,
        "flyback_time_s": t_fb,
        "settling_time_s": t_s,
        "acceleration_time_s": t_a,
        "acceleration_amplitude_m": d_a,
        "ramp_time_s": T - t_fb - t_s - t_a,
        "settling_fits": bool(settling_fits),
        "acceleration_fits": bool(acceleration_fits),
    }


def optimized(
    amplitude: float,
    frequency: float,
    drive: Drive,
    periods: int = 3,
    *,
    design: OptimizedDesign | None = None,
    first_period: str = "sawtooth",
    flyback=None,
    settle_fraction: float = SETTLE_FRACTION,
    min_ramp_fraction: float = MIN_RAMP_FRACTION,
    short_period: str = "refuse",
) -> Waveform:
    """The optimized driving waveform of Section 5.1 (Fig. 8b, Eq. 15).

    Each optimized period: after the fly-back the hemispheres are frozen for the settling
    time t_s = 1/(2 f_s) while the runner's micro-vibration turns forward, then moved
    forward by Δ_a in t_a with (V_a − V_r) t_a = u_x,max (sub-phase I), then slowed down to a
    slow ramp up to A, during which the runner slips forward and is carried (sub-phase II),
    and flown back to 0. The first period is a saw-tooth (the optimization starts after the
    first slip, Section 5.2) unless ``first_period="optimized"``.

    Parameters
    ----------
    amplitude : float
        Actuation amplitude A in m.
    frequency : float
        Driving frequency f in Hz.
    drive : Drive
        The drive; supplies the amplifier/slew-rate limits.
    periods : int
        Number of periods.
    design : OptimizedDesign
        t_s, t_a, Δ_a to use (required): designed from the drive's simulated response by
        :func:`passmd.protocols.eq15.optimized_design` (e.g. once per drive and reused over
        frequencies) or chosen by hand.
    first_period : {"sawtooth", "optimized"}
        Shape of the first period.
    flyback : {"slew", "fixed"} or float, optional
        Fly-back rule overriding the drive's (default None: the drive's;
        :func:`~passmd.model.waveforms.flyback_time`).
    settle_fraction : float
        Part of each period's slow ramp, at its end, used as the settle window.
    min_ramp_fraction : float
        Share of T − t_fb the slow ramp keeps when t_s + t_a must be cut
        (:func:`optimized_timing`).
    short_period : {"refuse", "cut", "skip"}
        What to do when t_s + t_a does not fit in a period: refuse the frequency, naming the
        highest that fits (:func:`check_fits`), or build a truncated study waveform with t_s
        cut or skipped (:func:`optimized_timing`).

    Returns
    -------
    Waveform
        ``kind="optimized"`` (``"optimized, t_s cut"`` / ``"optimized, t_s skipped"`` when
        truncated: not Eq. 15's waveform); slip marks at the start of each fly-back; settle windows at the
        end of each (slow) ramp, as for :func:`~passmd.model.waveforms.sawtooth`, so positions compare
        directly.

    Raises
    ------
    ValueError
        No ``design`` (this function never simulates), bad input, or (``short_period="refuse"``)
        a period Eq. 15 does not fit.
    """
    if design is None:
        raise ValueError(
            "design = None is not allowed: the optimized waveform is built from an OptimizedDesign; "
            "derive one from the drive's simulated saw-tooth response with "
            "passmd.protocols.eq15.optimized_design(amplitude, drive) or give t_s, t_a, Δ_a by hand"
        )
    check_choice("first_period", first_period, ("sawtooth", "optimized"))
    frac = check_range("settle_fraction", settle_fraction, 0.0, 1.0, lower_open=True, upper_open=True)
    periods = check_count("periods", periods)
    timing = optimized_timing(
        design, amplitude, frequency, drive, flyback=flyback, min_ramp_fraction=min_ramp_fraction,
        short_period=short_period,
    )
    A, T = float(amplitude), timing["period_s"]
    t_s, t_a = timing["settling_time_s"], timing["acceleration_time_s"]
    d_a = timing["acceleration_amplitude_m"]
    ramp_end = T - timing["flyback_time_s"]
    kind = "optimized" if timing["settling_fits"] else \
        f"optimized, t_s {dict(cut='cut', skip='skipped')[short_period]}"  # truncated: not Eq. 15's
    pt = ([0.0, t_s] if t_s > 0 else [0.0]) + [t_s + t_a, ramp_end, T]
    px = ([0.0, 0.0] if t_s > 0 else [0.0]) + [d_a, A, 0.0]
    window = (ramp_end - frac * timing["ramp_time_s"], ramp_end)
    n_opt = periods - 1 if first_period == "sawtooth" else periods
    parts_t, parts_x, windows, marks = [np.array([0.0])], [np.array([0.0])], [], []
    offset = 0.0
    if first_period == "sawtooth":
        first = sawtooth(A, 1.0 / T, drive, periods=1, flyback=flyback, settle_fraction=frac)
        parts_t.append(first.times[1:])
        parts_x.append(first.positions[1:])
        windows.append(first.settle_windows)
        marks.append(first.slip_marks)
        offset = T
    if n_opt > 0:
        rest = piecewise_linear(
            pt, px, 1.0 / T, n_opt, settle_window=window, slip_mark=ramp_end, kind=kind
        )
        parts_t.append(offset + rest.times[1:])
        parts_x.append(rest.positions[1:])
        windows.append(offset + rest.settle_windows)
        marks.append(offset + rest.slip_marks)
    return Waveform(np.concatenate(parts_t), np.concatenate(parts_x), T, periods, np.concatenate(windows),
                    np.concatenate(marks), kind, A)
