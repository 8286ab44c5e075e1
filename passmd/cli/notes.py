"""What the commands say and draw beside their values: the Eq. 15 design's source and where it fits,
why a sweep's cells have no value, and the runner's ringing where it explains a non-monotone answer."""

from __future__ import annotations

import math

__all__ = ["diagnosis_rows", "eq15_rows", "hz", "missing_rows", "resolution", "ringing_notes", "ringing_text",
           "sweep_figure", "sweep_title", "turn_rows", "uses_eq15"]


def hz(frequency: float, *, down: bool = False) -> str:
    """A frequency as a reader writes it: ``100 Hz``, ``4.908 kHz``; ``down``: rounded down to its
    four digits (an upper limit, which typed back must stay within it)."""
    value, unit = (frequency, "Hz") if frequency < 1e3 else (frequency / 1e3, "kHz")
    if down and value > 0 and math.isfinite(value):
        step = 10.0 ** (math.floor(math.log10(value)) - 3)
        value = math.floor(value / step * (1 + 1e-12)) * step
    return f"{value:.4g} {unit}"


def uses_eq15(args) -> bool:
    """Whether the sweep runs the Eq. 15 waveform (gain, or velocity/step/back-step of it)."""
    return args.quantity == "gain" or (args.quantity in ("velocity", "step", "back-step")
                                       and args.waveform == "optimized")


def missing_rows(args, table, count: int) -> list[tuple[str, str]]:
    """Why cells have no value: by the notes' kinds for Eq. 15, the full stroke for A_c."""
    if not uses_eq15(args):
        return [("no value", f"{count} point{'s' * (count > 1)} (no onset up to the full stroke)")]
    notes = [n for n in table.get("note", []) if isinstance(n, str)]
    fit = sum(n.startswith("Eq. 15 does not fit") for n in notes)
    kinds = ([f"{fit} where Eq. 15 does not fit the period"] if fit else []) + (
        [f"{len(notes) - fit} where Eq. 15 gives no waveform at the amplitude"] if len(notes) > fit else [])
    return [("no value", f"{count} point{'s' * (count > 1)}: {', '.join(kinds)} (see the note column)")]


def _finite(column) -> list[float]:
    """The finite numbers of a result column (``None``/NaN: no value)."""
    return [float(v) for v in column if v is not None and math.isfinite(float(v))]


def eq15_rows(args, table) -> list[tuple[str, str]]:
    """Which response the Eq. 15 design comes from and up to which frequency it fits."""
    if not uses_eq15(args) or "eq15_highest_frequency_Hz" not in table:
        return []
    limits = _finite(table["eq15_highest_frequency_Hz"])
    source = ", ".join(hz(f) for f in sorted(set(_finite(table["response_frequency_Hz"])))) or "–"
    varies = limits and max(limits) > min(limits)
    spread = f" … {hz(max(limits), down=True)} (by drive and amplitude)" if varies else ""
    fits = f"fits up to {hz(min(limits), down=True)}{spread}" if limits else "–"
    return [("Eq. 15 design", f"from the saw-tooth response at {source}; {fits}")]


def turn_rows(axis, spec, table, resolution, shown, diagnosed: bool) -> list[tuple[str, str]]:
    """Where a one-axis curve turns (changes beyond each point's ``resolution``, SI): one row, which
    names the turns and points to the computed causes (``diagnosed``) rather than guessing one."""
    from passmd.protocols import ringing

    values = table[spec.column]
    turns = ringing.turns(values, resolution)
    if not turns:
        return []
    near = [k for k in (turns[0] - 1, turns[0], turns[0] + 1) if 0 <= k < len(values)]
    where = ", ".join(f"{float(values.iloc[k]) / spec.scale:.4g} {spec.unit} at "
                      f"{shown(axis, table[axis.column].iloc[k])}" for k in near)
    times = f"{len(turns)} time{'s' * (len(turns) > 1)}"
    why = ("its causes are computed below (why rows)" if diagnosed else
           "its cause is computed where the sweep has one axis and a diagnosis (velocity, step, A_c, gain)")
    return [("not monotone", f"the {spec.label} turns {times} over {axis.name} ({where}); {why}")]


def _span(values, factor) -> str:
    """``lo–hi`` of ``values × factor`` to 3 digits, one number when they agree."""
    lo, hi = f"{min(values) * factor:.3g}", f"{max(values) * factor:.3g}"
    return lo if lo == hi else f"{lo}–{hi}"


def resolution(spec, frequencies) -> list[float]:
    """Each point's value resolution (SI): the measurable step δ of the critical-amplitude search for
    a length (step, back-step, A_c), δ·f for a velocity; 0 otherwise."""
    from passmd.model.defaults import PROTOCOL

    delta = PROTOCOL.step_threshold
    if spec.unit == "nm":
        return [delta] * len(frequencies)
    return [delta * float(f) for f in frequencies] if spec.unit == "mm/s" else [0.0] * len(frequencies)


def ringing_text(ring: dict, what: str, *, diagnosed: bool = False) -> str:
    """One line on the runner's ringing after a fly-back (:func:`passmd.protocols.ringing.at_frequency`)
    and whether it is still there, beyond the measurable step, when the next fly-back starts;
    ``what``: the answer it affects (e.g. ``"the step"``)."""
    from passmd.protocols.ringing import MEASURABLE

    if ring["ringing_frequency_Hz"] is None or not math.isfinite(ring["ringing_frequency_Hz"]):
        return "none: the runner makes no swing after the fly-back"
    decay = ring["ringing_decay_time_s"]
    decays = f"decaying to 1/e in {decay * 1e3:.3g} ms" if decay is not None and math.isfinite(decay) else \
        "decaying by less than 1/e while recorded"
    linear = ring.get("ringing_linear_frequency_Hz")
    estimate = ""
    if linear is not None and math.isfinite(linear):
        estimate = (" (the linear estimate, each contact in series with its actuator: "
                    f"{linear / 1e3:.3g} kHz; the first swings micro-slip)")
    text = (f"after a fly-back the runner rings at {ring['ringing_frequency_Hz'] / 1e3:.3g} kHz{estimate}, "
            f"±{ring['ringing_amplitude_m'] * 1e9:.3g} nm, {decays}; "
            f"±{ring['ringing_at_next_flyback_m'] * 1e9:.3g} nm is left when the next fly-back starts "
            f"{ring['next_flyback_after_s'] * 1e3:.3g} ms later")
    if ring["ringing_affects_steps"] and diagnosed:
        return (f"{text}, more than the {MEASURABLE * 1e9:g} nm measurable step; how much it moves {what} is "
                "computed below (runner ringing)")
    if ring["ringing_affects_steps"]:
        return (f"{text}, more than the {MEASURABLE * 1e9:g} nm measurable step: {what} depends on where in "
                "its swing the runner is then, so it is not monotone in frequency, amplitude or preload (the "
                "model's physics, not numerical noise)")
    return f"{text}, below the {MEASURABLE * 1e9:g} nm measurable step: {what} does not depend on it"


def ringing_notes(table) -> list[str]:
    """The legend line of a map whose values the runner's ringing affects (else none)."""
    if "ringing_affects_steps" not in table or not any(bool(v) for v in table["ringing_affects_steps"]):
        return []
    left = max(_finite(table["ringing_at_next_flyback_m"]))
    f = _span(_finite(table["ringing_frequency_Hz"]), 1e-3)
    count = sum(bool(v) for v in table["ringing_affects_steps"])
    return [f"at {count} of {len(table)} points up to ±{left * 1e9:.3g} nm of the runner's swing ({f} kHz) "
            "is left at\nthe next fly-back: a value there can depend on its phase (the causes of a turn: "
            "passmd sweep's output)"]


def sweep_figure(args, axes, spec, table, title):
    """The curve or heat map of the sweep: values apart from the points with no value, not steady or
    below the resolution (:func:`passmd.plots.sweep_map.cell_marks`), named in the legend."""
    from passmd.plots.sweep_map import MapAxis, cell_marks, map_figure

    shown = [MapAxis(a.column, a.name, a.quantity.unit, a.spacing == "log") for a in axes]
    reading = f", {args.reading or 'steady'} reading" if args.quantity == "critical-amplitude" else ""
    value = MapAxis(spec.column, f"{spec.label}{reading}", spec.unit, scale=spec.scale)
    also = [MapAxis(c, "closed form (Eqs. 7–8, 11–12)" if c.startswith("analytic") else c, spec.unit,
                    scale=spec.scale) for c in spec.also]
    if "running_max_critical_amplitude_m" in table:
        also.append(MapAxis("running_max_critical_amplitude_m",
                            f"moves the runner at every {axes[0].name} up to here (running maximum)",
                            spec.unit, scale=spec.scale))
    from passmd.model.defaults import PROTOCOL

    step = f"{PROTOCOL.step_threshold * 1e9:g} nm" + ("" if spec.unit == "nm" else " × f")
    missing = {"gain": "no value: Eq. 15 gives no waveform or does not fit the period (note column)",
               "critical-amplitude": "no onset up to the full stroke"}.get(
        args.quantity, "no value (note column)" if uses_eq15(args) else "no value")
    marks = cell_marks(table, value, resolution(spec, table["frequency_Hz"]) if spec.unit != "N" else None,
                       missing_label=missing,
                       resolution_label=f"|value| below the measurable step ({step}): no measurable "
                       + ("difference" if args.quantity == "gain" else "motion"))
    return map_figure(table, shown, value, title, also=also if len(axes) == 1 else (), marks=marks,
                      notes=ringing_notes(table), color_scale=getattr(args, "color_scale", "auto"),
                      band=_band(spec, table))


def _band(spec, table):
    """The fitted drive's band of a sweep (:func:`passmd.cli.sweep_rows.add_band`), for the figure."""
    low, high = f"{spec.column}_band_low", f"{spec.column}_band_high"
    if low not in table:
        return None
    return low, high, (f"fit's 95 % region ({table.attrs.get('band_points', 0)} points of it and the "
                       "estimate)")


def sweep_title(spec, axes, drive) -> str:
    """A sweep's title: the quantity, what varies, and the base drive without the varied values."""
    from passmd.cli.output import describe

    varied = [a.name for a in axes]
    return f"{spec.label} over {' × '.join(varied)}\n{describe(drive, omit=varied)}"


def _value_text(value, unit: str, scale: float | None = None) -> str:
    from passmd.cli.output import fmt

    if value is None:
        return "none"
    return f"{value / scale:.4g} {unit}" if scale is not None else fmt(value, unit)


def diagnosis_rows(found: dict, symptom: str, unit: str, what: str, *,
                   scale: float | None = None) -> list[tuple[str, str]]:
    """The computed "why" of a departure (:func:`passmd.protocols.diagnosis.diagnose`): the symptom,
    each cause's counterfactual value and share, best explanation first, and the causes it names.
    ``unit``: the display unit of the values (``scale``: the SI value of one unit, else the unit's own);
    ``what``: the result's name (``"A_c"``)."""
    from passmd.protocols.diagnosis import EXPLAINS

    rows = [("why (computed)", f"{symptom}; re-run with one candidate cause removed at a time:")]
    for c in found["causes"]:
        if c["share"] is None:
            state = "no value" if c.get("tried") else "not tried"
            rows.append((f"  {c['cause']}", f"{state}: {c['changed']}"))
            continue
        values = c["counterfactual_values"]
        at = (f"{what} = {_value_text(values[-1], unit, scale)}" if len(values) == 1 else
              f"{what} = {' → '.join(_value_text(v, unit, scale) for v in values)}")
        closed = "" if c.get("counterfactual_expected") is None or c["key"] != "actuator" else \
            f" (its closed form, Eq. 7/11: {_value_text(c['counterfactual_expected'], unit, scale)})"
        why = f": {c['why']}" if c.get("why") else ""
        past = (" (past what is expected: a cause acting the other way remains)"
                if c["share"] > 2 - EXPLAINS else "")
        rows.append((f"  {c['cause']}", f"{100 * c['share']:.0f} % of it{past}: with {c['changed']} {at}"
                     f"{closed}{why}"))
    named = found["named"]
    which = "it" if len(named) == 1 else "each"
    rows.append(("cause", ", ".join(named) + f" (removing {which} takes away at "
                 f"least {100 * EXPLAINS:.0f} % of the departure)" if named else
                 f"none of the candidates: removing each takes away less than {100 * EXPLAINS:.0f} % of the "
                 "departure"))
    return rows
