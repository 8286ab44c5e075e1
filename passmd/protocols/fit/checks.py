"""Every measurement row checked against the drive before anything is simulated.

A row the drive cannot run is refused in one line naming the file, the row (and its line), the
column and its value as the file gives it, and the drive's limit: an amplitude beyond the
actuator's full stroke, a frequency whose period cannot hold the fly-back (with the longest
fly-back the fit may try, when the fly-back is free), a preload or radius outside its plausible
range (:data:`passmd.model.parameters.PLAUSIBLE_RANGES`; soft limits lifted by the drive's
``allow_extrapolation``), and a measured step (or velocity) no drive could make: beyond
:data:`TRAVEL_FACTOR` times the amplitude plus the contacts' presliding and the actuators'
deformation (Eqs. 7–10; per period, × f for a velocity) — refused before minutes of fitting.
"""

from __future__ import annotations

import math
from dataclasses import replace

from passmd.model.parameters import PLAUSIBLE_RANGES, Drive
from passmd.model.waveforms import flyback_rule
from passmd.protocols.fit.measurements import MeasurementError, Measurements
from passmd.protocols.fit.prediction import _row_drive
from passmd.runtime.validation import InputError

__all__ = ["TRAVEL_FACTOR", "check_rows"]

#: A runner advances per period at most the actuator's travel A plus what the contacts and the
#: actuators give elastically before sliding (u_x,max + u_x,a, Eqs. 7–10); flexible actuators that
#: ring can carry it a little beyond that at high frequency. A measured step (velocity / f) beyond
#: this many times A + u_x,max + u_x,a, at the free parameters' most permissive bounds, is refused.
TRAVEL_FACTOR = 2.0


def _where(data: Measurements, i: int, column: str, value: float) -> str:
    return f"{data.name} row {i + 1} (line {data.line[i]}), column {column} = {value:.10g}"


def _longest_flyback(drive: Drive, amplitude: float, box: dict) -> tuple[float, str]:
    """The longest fly-back the fit may simulate at ``amplitude`` (s), and how it is set."""
    amp = drive.amplifier
    full = amp.full_stroke_time
    if "flyback_time" in box:
        full = box["flyback_time"][1]
    elif "amplifier.slew_rate" in box:
        full = amp.peak_to_peak_voltage / box["amplifier.slew_rate"][0]
    rule = flyback_rule(drive)
    if rule == "fixed":
        return full, "the fixed full-stroke fly-back V_pp/SR"
    if rule == "slew":
        return (amplitude / drive.actuator.full_stroke_amplitude * full,
                "the slew-limited fly-back (A/A_max)·V_pp/SR")
    return float(rule), "the drive's stated fly-back"


def check_rows(drive: Drive, data: Measurements, box: dict[str, tuple[float, float]]) -> None:
    """Refuse (:class:`~passmd.protocols.fit.measurements.MeasurementError`, one line) the first row the
    drive cannot run (module docstring); ``box``: the free parameters' bounds (SI)."""
    lift = drive.allow_extrapolation
    lifted = replace(drive, allow_extrapolation=True)
    for i in range(len(data)):
        given = (("preload_N", data.preload[i], "preload", 1.0, "N"),
                 ("radius_mm", data.radius[i], "hemisphere_radius", 1e-3, "mm"))
        for column, value, key, scale, unit in given:
            if not math.isfinite(value):
                continue
            try:
                PLAUSIBLE_RANGES[key].check(column, value, allow_extrapolation=lift)
            except InputError as exc:
                limits = " and ".join(f"{op} {bound / scale:.4g} {unit}" for op, bound in exc.limits)
                hint = " (allow_extrapolation lifts it)" if exc.soft else ""
                kind = "soft" if exc.soft else "hard"
                raise MeasurementError(f"{_where(data, i, column, value / scale)} is out of range: must be "
                                       f"{limits}, the {key.replace('_', ' ')}'s {kind} limit{hint}",
                                       name=column, value=value) from None
        f = float(data.frequency[i])
        try:
            PLAUSIBLE_RANGES["frequency"].check("frequency_Hz", f, allow_extrapolation=lift)
        except InputError as exc:
            limits = " and ".join(f"{op} {bound:.4g} Hz" for op, bound in exc.limits)
            raise MeasurementError(f"{_where(data, i, 'frequency_Hz', f)} is out of range: must be {limits} "
                                   f"({exc.why})", name="frequency_Hz", value=f) from None
        try:
            row = _row_drive(lifted, data, i)
        except InputError as exc:
            raise MeasurementError(f"{data.name} row {i + 1} (line {data.line[i]}): the drive at this row's "
                                   f"conditions is refused: {exc}", name=exc.name, value=exc.value) from None
        a_max = row.actuator.full_stroke_amplitude
        amplitude = float(data.amplitude[i]) if math.isfinite(data.amplitude[i]) else a_max
        if data.kind[i] != "critical_amplitude" and amplitude > a_max:
            where = _where(data, i, "amplitude_nm", amplitude * 1e9)
            raise MeasurementError(f"{where} is out of range: must be <= {a_max * 1e9:.4g} nm, the row's "
                                   "full-stroke amplitude A_max (actuator.full_stroke_amplitude)",
                                   name="amplitude_nm", value=amplitude)
        if data.kind[i] == "critical_amplitude":
            amplitude = a_max  # the bisection opens its bracket at the full stroke
        _check_travel(data, i, row, amplitude, f, box)
        t_fb, how = _longest_flyback(row, amplitude, box)
        if not t_fb < 0.5 / f:
            raise MeasurementError(f"{_where(data, i, 'frequency_Hz', f)} is out of range: must be < "
                                   f"{0.5 / t_fb:.4g} Hz, for {how} of {t_fb * 1e6:.4g} µs at A = "
                                   f"{amplitude * 1e9:.4g} nm to take less than half a period",
                                   name="frequency_Hz", value=f)


def _largest_travel(drive: Drive, amplitude: float, box: dict) -> float | None:
    """A + u_x,max + u_x,a (m) of the row's drive with the free parameters at the bounds that make it
    largest (μ at its high bound, k_p and the contact stiffness at their low ones), or None where the
    closed forms do not apply (then nothing is refused)."""
    from passmd.model.theory import drive_theory

    changes = {}
    if "friction_coefficient" in box:
        changes["friction_coefficient"] = box["friction_coefficient"][1]
    actuator = drive.actuator
    if "actuator.stiffness" in box:
        actuator = replace(actuator, stiffness=box["actuator.stiffness"][0])
    if "contact_stiffness_scale" in box:
        s = box["contact_stiffness_scale"][0]
        changes["hemisphere_material"] = replace(drive.hemisphere_material,
                                                 youngs_modulus=s * drive.hemisphere_material.youngs_modulus)
        changes["runner_material"] = replace(drive.runner_material,
                                             youngs_modulus=s * drive.runner_material.youngs_modulus)
    try:
        theory = drive_theory(replace(drive, actuator=actuator, allow_extrapolation=True, **changes))
        elastic = max(u + (ua if drive.actuator_model == "flexible" else 0.0)
                      for u, ua in zip(theory["presliding_m"], theory["actuator_deformation_m"], strict=True))
    except (InputError, ValueError, ArithmeticError):
        return None
    return amplitude + float(elastic)


def _check_travel(data: Measurements, i: int, row: Drive, amplitude: float, f: float, box: dict) -> None:
    """Refuse a step or velocity row beyond :data:`TRAVEL_FACTOR` (A + u_x,max + u_x,a) per period."""
    if data.kind[i] not in ("step", "velocity"):
        return
    travel = _largest_travel(row, amplitude, box)
    if travel is None:
        return
    limit = TRAVEL_FACTOR * travel * (f if data.kind[i] == "velocity" else 1.0)
    value = float(data.value[i])
    if abs(value) > limit:
        scale, unit = data.display(i)
        per = " × f" if data.kind[i] == "velocity" else ""
        raise MeasurementError(
            f"{_where(data, i, data.column[i], value / scale)} is out of range: must be at most "
            f"{limit / scale:.4g} {unit} in magnitude, {TRAVEL_FACTOR:g} × (A + u_x,max + u_x,a) = "
            f"{TRAVEL_FACTOR:g} × {travel * 1e9:.4g} nm per period{per} "
            f"at A = {amplitude * 1e9:.4g} nm: no stick–slip drive moves that far (check the column's unit)",
            name=data.column[i], value=value)
