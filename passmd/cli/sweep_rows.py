"""What a sweep prints beside its values: a short curve in full (a gain with its %, an A_c with its
running maximum) or a map's extremes, each warning once as one line with the points it covers, and
the computed cause of each departure of a curve (:mod:`passmd.protocols.diagnosis`)."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["DIAGNOSED", "add_band", "check_values", "curve_rows", "derived_columns", "diagnose_sweep",
           "extreme_rows", "point_range", "sweep_diagnosis_rows", "warnings_of"]

#: The sweep quantities a diagnosis covers, by the name :mod:`passmd.protocols.diagnosis` knows them.
DIAGNOSED = {"critical-amplitude": "critical-amplitude", "velocity": "velocity", "step": "step",
             "gain": "gain"}


def _finite(values) -> list[float]:
    return [float(v) for v in values if v is not None and math.isfinite(float(v))]


def point_range(axes, table, chosen, shown) -> str:
    """The range each axis spans over the ``chosen`` points (``shown(axis, value)`` writes a value)."""
    parts = []
    for a in axes:
        values = sorted({float(v) for v, c in zip(table[a.column], chosen, strict=True) if c})
        if not values:
            continue
        parts.append(f"{a.name} {shown(a, values[0])}" if len(values) == 1 else
                     f"{a.name} {shown(a, values[0])} … {shown(a, values[-1])}")
    return ", ".join(parts)


def warnings_of(axes, spec, table, shown) -> list[dict]:
    """Each warning of the sweep once: ``kind``, ``points`` affected, ``of`` (all points), ``range``
    (the axes' span over them) and ``text`` (one line)."""
    from passmd.protocols.ringing import MEASURABLE
    from passmd.protocols.velocity import STEADY_DRIFT_LIMIT

    found, total = [], len(table)
    if "ringing_affects_steps" in table:
        chosen = [bool(v) for v in table["ringing_affects_steps"]]
        left = [v for v, c in zip(table["ringing_at_next_flyback_m"], chosen, strict=True) if c]
        f = _finite(table["ringing_frequency_Hz"])
        if any(chosen) and f:
            rings = f"{min(f) / 1e3:.3g}" if f"{min(f):.3g}" == f"{max(f):.3g}" else \
                f"{min(f) / 1e3:.3g}–{max(f) / 1e3:.3g}"
            text = (f"up to ±{max(_finite(left)) * 1e9:.3g} nm of the runner's swing ({rings} kHz) is left "
                    f"when the next fly-back starts (more than the {MEASURABLE * 1e9:g} nm measurable step): "
                    f"the {spec.label} can depend on its phase; what it moves is computed where a value "
                    "departs from its trend (why rows)")
            found.append({"kind": "runner ringing", "points": sum(chosen), "of": total,
                          "range": point_range(axes, table, chosen, shown), "text": text})
    if "velocity_drift" in table:
        drift = [None if v is None else float(v) for v in table["velocity_drift"]]
        chosen = [d is not None and math.isfinite(d) and abs(d) > STEADY_DRIFT_LIMIT for d in drift]
        if any(chosen):
            found.append({"kind": "not steady", "points": sum(chosen), "of": total,
                          "range": point_range(axes, table, chosen, shown),
                          "text": f"the velocity still drifts by more than {100 * STEADY_DRIFT_LIMIT:.0f} % "
                                  "between the run's last two quarters (hatched in the PNG)"})
    return found


def _point(table, points, spec, i) -> dict:
    point = points[i]
    amplitude = (float(table[spec.column].iloc[i]) if spec.name == "critical-amplitude"
                 else float(point["amplitude"]))
    return {"drive": point["drive"], "frequency": float(point["frequency"]), "amplitude": amplitude}


def diagnose_sweep(args, axes, spec, table, points, config) -> list[dict]:
    """The computed causes of a one-axis sweep's departures (jumps of A_c, turns of a step or velocity,
    an Eq. 15 gain below 0): one dict per departure with the points (``at``, their indices) and
    :func:`passmd.protocols.diagnosis.diagnose`'s result; none for maps, other quantities or
    --no-diagnosis."""
    from passmd.cli.notes import resolution
    from passmd.model.theory import drive_theory
    from passmd.protocols import diagnosis

    quantity = DIAGNOSED.get(args.quantity)
    if quantity is None or len(axes) != 1 or getattr(args, "no_diagnosis", False):
        return []
    if quantity == "velocity" and (args.waveform or "sawtooth") != "sawtooth":
        return []
    values = list(table[spec.column])
    expected = [drive_theory(p["drive"])["analytic_critical_amplitude_m"] for p in points]
    frequencies = list(table["frequency_Hz"])
    found = []
    for at in diagnosis.sweep_departures(quantity, values, expected, frequencies,
                                         resolution(spec, frequencies)):
        chosen = [_point(table, points, spec, i) for i in at]
        out = diagnosis.diagnose(quantity, chosen, [float(values[i]) for i in at],
                                 reading=args.reading or "steady", config=config)
        found.append({"at": list(at), **out})
    return found


def _symptom(found: dict, axis, spec, table, shown) -> str:
    at, values = found["at"], found["values"]
    where = [shown(axis, table[axis.column].iloc[i]) for i in at]
    v = [f"{x / spec.scale:.4g} {spec.unit}" for x in values]
    if len(at) == 1:
        return f"the {spec.label} is {v[0]} at {axis.name} {where[0]}, below 0"
    trends = {"critical-amplitude": "the closed form's scaling", "velocity": "a constant step (velocity ∝ f)"}
    trend = trends.get(found["quantity"], "a constant value")
    return (f"the {spec.label} goes from {v[0]} at {axis.name} {where[0]} to {v[1]} at {where[1]}, "
            f"{found['departure'] / spec.scale:+.3g} {spec.unit} off {trend}")


def sweep_diagnosis_rows(diagnoses, axis, spec, table, shown) -> list[tuple[str, str]]:
    """The rows of each diagnosis (:func:`passmd.cli.notes.diagnosis_rows`)."""
    from passmd.cli.notes import diagnosis_rows

    rows = []
    for found in diagnoses:
        what = spec.label.split(" (")[0]
        symptom = _symptom(found, axis, spec, table, shown)
        rows += diagnosis_rows(found, symptom, spec.unit, what, scale=spec.scale)
    return rows


def curve_rows(axes, spec, table, _shown) -> list[tuple[str, str]]:
    """A short curve in full: one row per value of its axis (a gain with its %, an A_c with the running
    maximum up to it)."""
    (axis,) = axes
    low = table[f"{spec.column}_band_low"] if f"{spec.column}_band_low" in table else None
    high = table[f"{spec.column}_band_high"] if low is not None else None
    beside = {"gain_percent": lambda p: f" ({p:+.3g} %)",
              "running_max_critical_amplitude_m":
                  lambda m: f" (at every {axis.name} up to here: {m * 1e9:.6g} nm)"}
    rows = []
    for i, (x, v) in enumerate(zip(table[axis.column], table[spec.column], strict=True)):
        empty = v is None or (isinstance(v, float) and math.isnan(v))
        text = "–" if empty else f"{v / spec.scale:.6g} {spec.unit}"
        for column, say in beside.items():
            extra = table[column].iloc[i] if column in table else None
            if text != "–" and extra is not None and math.isfinite(float(extra)):
                text += say(float(extra))
        if low is not None and text != "–" and low.iloc[i] is not None and math.isfinite(float(low.iloc[i])):
            text += (f" (fit's 95 % region: {float(low.iloc[i]) / spec.scale:.4g}–"
                     f"{float(high.iloc[i]) / spec.scale:.4g} {spec.unit})")
        rows.append((f"{axis.name} {_shown(axis, x)}", text))
    return rows


def extreme_rows(axes, spec, table, _shown) -> list[tuple[str, str]]:
    values = np.array([np.nan if v is None else float(v) for v in table[spec.column]], dtype=float)
    if not np.isfinite(values).any():
        return [(spec.label, "no value (see the note column)")]
    from passmd.protocols.velocity import STEADY_DRIFT_LIMIT

    rows = []
    drift = table["velocity_drift"] if "velocity_drift" in table else None
    for word, i in (("min", int(np.nanargmin(values))), ("max", int(np.nanargmax(values)))):
        where = ", ".join(f"{a.name} {_shown(a, table[a.column].iloc[i])}" for a in axes)
        unsteady = drift is not None and abs(float(drift.iloc[i])) > STEADY_DRIFT_LIMIT
        rows.append((f"{word} {spec.label}", f"{values[i] / spec.scale:.6g} {spec.unit} at {where}"
                     + (f" (not steady: velocity_drift {float(drift.iloc[i]):.2g})" if unsteady else "")))
    return rows


def derived_columns(args, axes, table) -> None:
    """A gain in % of the saw-tooth's velocity; over one axis, A_c's running maximum (in place)."""
    if args.quantity == "gain":
        table["gain_percent"] = [None if g is None or s is None or not math.isfinite(g) else 100.0 * g / s
                                 for g, s in zip(table["gain_m_per_s"], table["sawtooth_velocity_m_per_s"],
                                                 strict=True)]
    if args.quantity == "critical-amplitude" and len(axes) == 1:
        from passmd.protocols.diagnosis import running_max

        table["running_max_critical_amplitude_m"] = running_max(table["critical_amplitude_m"])


def add_band(args, spec, table, points_with, config) -> None:
    """The band a fitted --drive file's region gives each point (in place): ``<column>_band_low`` and
    ``_band_high``, the least and largest value over the estimate and the region's points.

    ``points_with(build)``: the sweep's points with each drive made by ``build(args, **fixed)``; the region's
    drives come from :func:`passmd.cli.drive.region_drives` (none: no band)."""
    from passmd.cli.drive import region_drives
    from passmd.protocols.maps import compute_map

    count = len(region_drives(args))
    if not count:
        return
    values = [list(table[spec.column])]
    for k in range(count):
        points = points_with(lambda probe, k=k, **fixed: region_drives(probe, **fixed)[k])
        other = compute_map(args.quantity, points, reading=args.reading or "steady",
                            waveform=args.waveform or "sawtooth",
                            design_response=args.design_response or "paper", config=config,
                            description=f"fit region {k + 1}/{count}")
        values.append(list(other[spec.column]))
    spans = [_finite(column) for column in zip(*values, strict=True)]
    table[f"{spec.column}_band_low"] = [min(s) if s else None for s in spans]
    table[f"{spec.column}_band_high"] = [max(s) if s else None for s in spans]
    table.attrs["band_points"] = count


def check_values(args, column: str, table) -> None:
    """The quantity is finite at every point; only an Eq. 15 quantity without an Eq. 15 waveform
    and a critical amplitude above the full stroke may be missing (``None``, said in the output)."""
    from passmd.cli.notes import uses_eq15
    from passmd.cli.output import check_results

    values = [v for v in table[column] if v is not None]
    if args.quantity == "critical-amplitude" or uses_eq15(args):
        values = [v for v in values if not (isinstance(v, float) and math.isnan(v))]
    check_results({column: values})
