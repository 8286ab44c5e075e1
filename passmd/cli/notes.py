"""What the commands say and draw beside their values: the Eq. 15 design's source and where it fits,
why a sweep's cells have no value, and the runner's ringing where it explains a non-monotone answer."""

from __future__ import annotations

import math

__all__ = ["eq15_rows", "hz", "missing_rows", "resolution", "ringing_notes", "ringing_rows",
           "ringing_text", "sweep_figure", "sweep_title", "uses_eq15"]


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


def ringing_rows(axes, spec, table, resolution, shown) -> list[tuple[str, str]]:
    """The runner's ringing where it affects a sweep's values (``ringing_*`` columns of
    :func:`passmd.protocols.maps.compute_map`), and the turns of a curve it explains.

    ``spec``: the quantity (its column, label, unit, scale); ``resolution``: each point's value
    resolution (SI); ``shown(axis, value)``: an axis value as the sweep writes it.
    """
    from passmd.protocols.ringing import MEASURABLE

    if "ringing_affects_steps" not in table:
        return []
    affected = [bool(v) for v in table["ringing_affects_steps"]]
    f, a = _finite(table["ringing_frequency_Hz"]), _finite(table["ringing_amplitude_m"])
    decay, left = _finite(table["ringing_decay_time_s"]), _finite(table["ringing_at_next_flyback_m"])
    if not (any(affected) and f and a and left):
        return []
    decays = f"decaying to 1/e in {_span(decay, 1e3)} ms" if decay else \
        "decaying by less than 1/e while recorded"
    rows = [("runner ringing",
             f"after each fly-back the runner rings at {_span(f, 1e-3)} kHz, ±{_span(a, 1e9)} nm, {decays}; "
             f"at {sum(affected)} of {len(affected)} points up to ±{max(left) * 1e9:.3g} nm of it is left "
             f"when the next fly-back starts (more than the {MEASURABLE * 1e9:g} nm measurable step), so the "
             f"{spec.label} there depends on where in its swing the runner is")]
    if len(axes) == 1:
        from passmd.protocols import ringing

        values = table[spec.column]
        turns = ringing.turns(values, resolution)
        if turns:
            near = [k for k in (turns[0] - 1, turns[0], turns[0] + 1) if 0 <= k < len(values)]
            where = ", ".join(f"{float(values.iloc[k]) / spec.scale:.4g} {spec.unit} at "
                              f"{shown(axes[0], table[axes[0].column].iloc[k])}" for k in near)
            times = f"{len(turns)} time{'s' * (len(turns) > 1)}"
            rows.append(("not monotone",
                         f"the {spec.label} turns {times} over {axes[0].name} ({where}); the runner still "
                         "rings there when the next fly-back starts (above), which makes the value depend on "
                         "its phase: the model's physics, not numerical noise (a finer grid shows more "
                         "turns, not a smoother curve)"))
    return rows


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


def ringing_text(ring: dict, what: str) -> str:
    """One line on the runner's ringing after a fly-back (:func:`passmd.protocols.ringing.at_frequency`)
    and whether it is still there, beyond the measurable step, when the next fly-back starts;
    ``what``: the answer it affects (e.g. ``"the step"``)."""
    from passmd.protocols.ringing import MEASURABLE

    if ring["ringing_frequency_Hz"] is None or not math.isfinite(ring["ringing_frequency_Hz"]):
        return "none: the runner makes no swing after the fly-back"
    decay = ring["ringing_decay_time_s"]
    decays = f"decaying to 1/e in {decay * 1e3:.3g} ms" if decay is not None and math.isfinite(decay) else \
        "decaying by less than 1/e while recorded"
    text = (f"after a fly-back the runner rings at {ring['ringing_frequency_Hz'] / 1e3:.3g} kHz, "
            f"±{ring['ringing_amplitude_m'] * 1e9:.3g} nm, {decays}; "
            f"±{ring['ringing_at_next_flyback_m'] * 1e9:.3g} nm is left when the next fly-back starts "
            f"{ring['next_flyback_after_s'] * 1e3:.3g} ms later")
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
    return [f"values depend on the runner's ringing ({f} kHz): up to ±{left * 1e9:.3g} nm of it is left\n"
            "at the next fly-back, so turns of the curve are the model's physics, not noise"]


def sweep_figure(args, axes, spec, table, title):
    """The curve or heat map of the sweep: values apart from the points with no value, not steady or
    below the resolution (:func:`passmd.plots.sweep_map.cell_marks`), named in the legend."""
    from passmd.plots.sweep_map import MapAxis, cell_marks, map_figure

    shown = [MapAxis(a.column, a.name, a.quantity.unit, a.spacing == "log") for a in axes]
    reading = f", {args.reading or 'steady'} reading" if args.quantity == "critical-amplitude" else ""
    value = MapAxis(spec.column, f"{spec.label}{reading}", spec.unit, scale=spec.scale)
    also = [MapAxis(c, "closed form (Eqs. 7–8, 11–12)" if c.startswith("analytic") else c, spec.unit,
                    scale=spec.scale) for c in spec.also]
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
                      notes=ringing_notes(table))


def sweep_title(spec, axes, drive) -> str:
    """A sweep's title: the quantity, what varies, and the base drive without the varied values."""
    from passmd.cli.output import describe

    varied = [a.name for a in axes]
    return f"{spec.label} over {' × '.join(varied)}\n{describe(drive, omit=varied)}"
