"""Eq. 15 design of the optimized waveform from a simulated saw-tooth response (Section 5.1).

Section 5.1 measures the micro-vibration frequency f_s and the runner velocity V_r "by
analyzing the movement of the runner" under the saw-tooth (Fig. 8a) and derives the
optimized waveform's settling time, acceleration time and amplitude from them (Eq. 15).
Here the response is simulated (:func:`passmd.solver.simulation.simulate`); the waveform itself is
built from the resulting :class:`~passmd.model.optimized_waveform.OptimizedDesign` by
:func:`passmd.model.optimized_waveform.optimized`, which never simulates.
"""

from __future__ import annotations

import numpy as np

from passmd.model import theory
from passmd.model.optimized_waveform import (
    RESPONSE_FREQUENCY,
    OptimizedDesign,
    highest_fitting_frequency,
    max_piezo_velocity,
)
from passmd.model.parameters import Drive, check_drive
from passmd.model.waveforms import sawtooth
from passmd.runtime.validation import InputError, check_choice, check_positive, check_range, shown
from passmd.solver import simulation

__all__ = ["DESIGN_RESPONSES", "MIN_SAMPLES", "SAMPLES_PER_VIBRATION", "design_at",
           "micro_vibration_frequency", "optimized_design", "response_frequency"]

#: Recorded samples per period of the linear runner-on-contacts vibration
#: (:func:`passmd.model.theory.runner_frequency`) in the design run: enough to place the zero
#: crossings of ẋ_r − ẋ_p by linear interpolation.
SAMPLES_PER_VIBRATION = 200
#: Fewest recorded samples of the design run, whatever the vibration frequency.
MIN_SAMPLES = 1000
#: Which saw-tooth response a design for a driving frequency f is made from: ``"paper"``, the
#: 100 Hz response of Section 5.2 (one design per drive, used at every f: the default, and the
#: ledger's), or ``"driving"``, the response at f itself.
DESIGN_RESPONSES = ("paper", "driving")


def response_frequency(frequency: float, response: str = "paper") -> float:
    """Frequency of the saw-tooth response a design for driving at ``frequency`` is made from (Hz).

    ``"paper"``: :data:`~passmd.model.optimized_waveform.RESPONSE_FREQUENCY` (100 Hz, Section 5.2),
    whose free micro-vibration after the first fly-back is not cut short by the next one;
    ``"driving"``: ``frequency`` itself (the runner before the fly-back then moves at the ramp's
    A·f, which enters V_r; near f_s the next fly-back cuts into the vibration cycle Eq. 15 reads).
    """
    check_choice("response", response, DESIGN_RESPONSES)
    return RESPONSE_FREQUENCY if response == "paper" else check_positive("frequency", frequency, "Hz")


def design_at(amplitude: float, frequency: float, drive: Drive, *, response: str = "paper",
              flyback=None) -> tuple[OptimizedDesign, float]:
    """The Eq. 15 design for driving ``drive`` at ``amplitude`` and ``frequency``, and the highest
    frequency at which its period fits (:func:`~passmd.model.optimized_waveform.highest_fitting_frequency`).

    The design is :func:`optimized_design` of the saw-tooth response :func:`response_frequency`
    names. Whether ``frequency`` is at most the returned one is the caller's to check
    (:func:`~passmd.model.optimized_waveform.check_fits` refuses it in one line).
    """
    design = optimized_design(amplitude, drive, response_frequency=response_frequency(frequency, response),
                              flyback=flyback)
    return design, highest_fitting_frequency(design, amplitude, drive, flyback=flyback)


def micro_vibration_frequency(
    time, runner_velocity, piezo_velocity, after: float
) -> tuple[float, np.ndarray]:
    """Frequency of the runner's micro-vibration after ``after`` (Section 5.1, Fig. 8a).

    The turning points of the runner relative to the hemispheres are the zero crossings
    z₁, z₂, z₃, … of ẋ_r − ẋ_p after ``after`` (linearly interpolated between samples);
    f_s = 1 / (z₃ − z₁), the first full cycle.

    Parameters
    ----------
    time, runner_velocity, piezo_velocity : array_like
        Recorded samples (s, m/s, m/s), e.g. of a :class:`passmd.solver.results.SimulationResult`.
    after : float
        Start of the free vibration (s), e.g. the end of a fly-back.

    Returns
    -------
    (float, ndarray)
        f_s in Hz and the crossing times (s).

    Raises
    ------
    ValueError
        If fewer than three turning points follow ``after`` (no vibration, e.g. an amplitude
        below the critical amplitude, or a record too short).
    """
    t = np.asarray(time, dtype=float)
    w = np.asarray(runner_velocity, dtype=float) - np.asarray(piezo_velocity, dtype=float)
    keep = t > after
    t, w = t[keep], w[keep]
    sign = np.sign(w)
    idx = np.flatnonzero((sign[:-1] != 0) & (sign[:-1] != sign[1:]))
    crossings = t[idx] - w[idx] * (t[idx + 1] - t[idx]) / (w[idx + 1] - w[idx])
    if crossings.size < 3:
        found = f"found {crossings.size} turning point(s) of the runner, need 3"
        raise InputError(
            f"no micro-vibration after t = {shown(after)} s: {found} (is the amplitude above the critical "
            "amplitude, and the record long enough?)", name="after", value=after, detail=found)
    return float(1.0 / (crossings[2] - crossings[0])), crossings


def optimized_design(
    amplitude: float,
    drive: Drive,
    *,
    acceleration_velocity: float | None = None,
    presliding: float | None = None,
    response_frequency: float = RESPONSE_FREQUENCY,
    flyback=None,
) -> OptimizedDesign:
    """Derive t_s, t_a and Δ_a of the optimized waveform from a simulated saw-tooth response (Eq. 15).

    Simulates two saw-tooth periods of amplitude A at ``response_frequency`` from rest
    (Fig. 8a), measures the micro-vibration frequency f_s after the first fly-back
    (:func:`micro_vibration_frequency`) and the runner velocity V_r at the end of the
    settling time, and applies Eq. 15::

        t_s = 1 / (2 f_s),     (V_a − V_r) t_a = u_x,max,     Δ_a = V_a t_a.

    Eq. 15 leaves V_a free; it is ``acceleration_velocity``, by default the fastest the
    amplifier allows (:func:`~passmd.model.optimized_waveform.max_piezo_velocity`, slew-rate limit).

    Parameters
    ----------
    amplitude : float
        Actuation amplitude A in m.
    drive : Drive
        The drive (the paper: six contacts, rigid actuators). Its own response is analysed.
    acceleration_velocity : float, optional
        V_a in m/s, V_r < V_a ≤ V_max. Default V_max.
    presliding : float, optional
        u_x,max in m. Default the smallest presliding displacement of the drive's contacts
        (Eq. 7 / Eq. 10).
    response_frequency : float
        Saw-tooth frequency of the analysed response (Hz); default the protocol's driving
        frequency (:data:`passmd.model.defaults.PROTOCOL`).
    flyback : {"slew", "fixed"} or float, optional
        Fly-back rule of that saw-tooth, overriding the drive's (default None: the drive's;
        :func:`~passmd.model.waveforms.flyback_time`).

    Raises
    ------
    ValueError
        Bad input, V_a ≤ V_r, or no micro-vibration in the response.
    """
    v_max = max_piezo_velocity(check_drive(drive))
    if acceleration_velocity is None:
        v_a = v_max
    else:
        v_a = check_range(
            "acceleration_velocity", acceleration_velocity, 0.0, v_max, lower_open=True, unit="m/s"
        )
    if presliding is None:
        u_max = float(min(theory.drive_theory(drive)["presliding_m"]))
    else:
        u_max = check_positive("presliding", presliding, "m")
    f_ref = check_positive("response_frequency", response_frequency, "Hz")
    wave = sawtooth(amplitude, f_ref, drive, periods=2, flyback=flyback)
    samples = int(np.ceil(wave.duration * theory.runner_frequency(drive) * SAMPLES_PER_VIBRATION)) + 1
    result = simulation.simulate(drive, wave, max_points=max(samples, MIN_SAMPLES))
    flyback_end = wave.period  # the first fly-back ends with the first period
    try:
        f_s, _ = micro_vibration_frequency(
            result.time, result.runner_velocity, wave.velocity(result.time), flyback_end
        )
    except InputError as exc:  # the response of this amplitude: name the amplitude
        detail = (f"the saw-tooth response Eq. 15 is designed from shows no micro-vibration after the first "
                  f"fly-back ({exc.detail}): the amplitude must be above the critical amplitude")
        raise InputError(f"amplitude = {shown(amplitude)} m: {detail}", name="amplitude", value=amplitude,
                         unit="m", sources=("amplitude",), detail=detail) from None
    t_s = 0.5 / f_s
    v_r = float(np.interp(flyback_end + t_s, result.time, result.runner_velocity))
    if not v_a > v_r:
        raise InputError(
            f"acceleration_velocity = {shown(v_a)} is out of range: must exceed the runner velocity "
            f"V_r = {v_r:.3g} m/s (Eq. 15)", name="acceleration_velocity", value=v_a, unit="m/s",
            limits=((">", v_r),))
    t_a = u_max / (v_a - v_r)
    return OptimizedDesign(t_s, t_a, v_a * t_a, f_s, v_r, u_max, f_ref)
