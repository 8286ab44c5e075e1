"""The quantities a design map evaluates at one point: a drive, an amplitude, a frequency.

Each quantity is a pure point function of a :class:`~passmd.model.parameters.Drive` and the
waveform's parameters, built from the protocols the book uses (nothing is re-derived here):

* ``velocity``, ``step``, ``back-step``: the steady-velocity protocol
  (:func:`passmd.protocols.velocity.steady_run`: a run of ``max(20, f · 5 ms)`` periods
  from rest, the slope of the period-mean position over its second half; step = velocity / f,
  back-step the mean over the second half), one run giving all three;
* ``critical-amplitude``: the bisection of :func:`passmd.protocols.critical_amplitude.critical_amplitude`
  with the reading ``steady`` (the last step of a run of saw-tooth periods exceeds the
  measurable step: the amplitude a drive in continuous operation needs) or ``first`` (full
  sliding of every contact in the first fly-back from rest: the amplitude that moves a
  drive once), plus the closed form (Eqs. 7–8, 11–12, :func:`passmd.model.theory.drive_theory`);
* ``stall-force``: the generated force at stall against the load cell
  (:func:`passmd.protocols.stall.generated_force`, Section 4.2);
* ``gain``: the steady velocity of the optimized waveform (Eq. 15, designed from this drive's
  own saw-tooth response at this amplitude, :func:`passmd.protocols.eq15.optimized_design`)
  minus that of the saw-tooth, both by the steady-velocity protocol. Where Eq. 15 gives no
  waveform (no micro-vibration in the saw-tooth response, or Δ_a ≥ A at small amplitudes) the
  point's gain is ``None`` and ``note`` says why.

All values are SI, keys carrying the unit, and the cache stores them as they are.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from passmd.model import theory
from passmd.model.parameters import Drive
from passmd.protocols import critical_amplitude as ca
from passmd.protocols import eq15, stall, velocity
from passmd.runtime.validation import InputError, check_choice

__all__ = ["MAP_QUANTITIES", "READINGS", "MapQuantity", "critical_amplitude_point", "gain_point",
           "stall_point", "steady_point"]

#: Readings of the simulated critical amplitude (:data:`passmd.protocols.critical_amplitude.PROTOCOLS`).
READINGS = ca.PROTOCOLS


def steady_point(drive: Drive, amplitude: float, frequency: float, waveform: str = "sawtooth") -> dict:
    """Steady velocity, step and back-step of one waveform (:func:`~passmd.protocols.velocity.steady_run`).

    ``waveform="optimized"``: the Eq. 15 waveform designed from this drive's saw-tooth
    response at this amplitude.
    """
    check_choice("waveform", waveform, ("sawtooth", "optimized"))
    design = eq15.optimized_design(amplitude, drive) if waveform == "optimized" else None
    return velocity.steady_run(drive, amplitude, frequency, waveform, "cut", design)


def critical_amplitude_point(drive: Drive, frequency: float, reading: str = "steady") -> dict:
    """Simulated A_c (``reading``: ``steady`` or ``first``) and the closed form of the drive.

    ``critical_amplitude_m`` is ``None`` when no amplitude up to the full stroke moves the runner.
    """
    found = ca.critical_amplitude(drive, protocol=reading, frequency=frequency)
    for key in ("critical_amplitude_m", "bracket_high_m"):  # NaN: no onset up to the full stroke
        if math.isnan(found[key]):
            found[key] = None
    closed_form = theory.drive_theory(drive)["analytic_critical_amplitude_m"]
    found["analytic_critical_amplitude_m"] = float(closed_form)
    return found


def stall_point(drive: Drive, amplitude: float, frequency: float) -> dict:
    """Generated force at stall (:func:`passmd.protocols.stall.generated_force`)."""
    return stall.generated_force(drive, amplitude, frequency)


def gain_point(drive: Drive, amplitude: float, frequency: float) -> dict:
    """Steady velocity of the Eq. 15 waveform minus that of the saw-tooth (m/s), both measured.

    ``gain_m_per_s`` and the design's times are ``None`` with a ``note`` where Eq. 15 gives no
    waveform: no micro-vibration in the saw-tooth response at this amplitude, or an
    acceleration segment Δ_a not below the amplitude.
    """
    saw = velocity.steady_run(drive, amplitude, frequency, "sawtooth", "cut")
    out = {"sawtooth_velocity_m_per_s": saw["velocity_m_per_s"], "optimized_velocity_m_per_s": None,
           "gain_m_per_s": None, "settling_time_s": None, "acceleration_time_s": None,
           "acceleration_amplitude_m": None, "note": None}
    try:
        design = eq15.optimized_design(amplitude, drive)
        opt = velocity.steady_run(drive, amplitude, frequency, "optimized", "cut", design)
    except InputError as exc:  # no micro-vibration to design from, or Δ_a ≥ A (Eq. 15)
        out["note"] = f"no Eq. 15 waveform at this amplitude: {exc.detail or exc}"
        return out
    out.update(optimized_velocity_m_per_s=opt["velocity_m_per_s"],
               gain_m_per_s=opt["velocity_m_per_s"] - saw["velocity_m_per_s"],
               settling_time_s=design.settling_time, acceleration_time_s=design.acceleration_time,
               acceleration_amplitude_m=design.acceleration_amplitude)
    return out


@dataclass(frozen=True)
class MapQuantity:
    """One quantity of a map: its point function, the column it shows, and how to show it."""

    name: str
    function: object
    column: str
    unit: str
    #: the SI value of one ``unit`` (the column is SI)
    scale: float
    label: str
    #: whether the point takes an amplitude (the critical amplitude searches over it)
    amplitude: bool = True
    #: further columns drawn on a one-axis curve (e.g. the closed form)
    also: tuple[str, ...] = ()


#: The quantities of a map by name (``passmd sweep QUANTITY``).
MAP_QUANTITIES = {q.name: q for q in (
    MapQuantity("velocity", steady_point, "velocity_m_per_s", "mm/s", 1e-3, "steady velocity"),
    MapQuantity("step", steady_point, "step_m", "nm", 1e-9, "steady step (velocity / f)"),
    MapQuantity("back-step", steady_point, "back_step_m", "nm", 1e-9, "back-step"),
    MapQuantity("critical-amplitude", critical_amplitude_point, "critical_amplitude_m", "nm", 1e-9,
                "critical amplitude A_c", amplitude=False, also=("analytic_critical_amplitude_m",)),
    MapQuantity("stall-force", stall_point, "generated_force_N", "N", 1.0, "stall force"),
    MapQuantity("gain", gain_point, "gain_m_per_s", "mm/s", 1e-3, "Eq. 15 velocity gain over the saw-tooth"),
)}
