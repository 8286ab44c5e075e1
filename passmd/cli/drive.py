"""The drive a command line describes, and refused inputs said again in the options' terms.

:func:`build_drive`: the defaults, replaced by what the user gave. :func:`explain`: the one
place a refused input (:class:`passmd._validation.InputError`, raised by the records and
functions the options reach) is said again with the option that set it, as typed.
"""

from __future__ import annotations

import math
from dataclasses import replace
from decimal import ROUND_CEILING, ROUND_FLOOR, Decimal

from passmd._validation import InputError
from passmd.cli.errors import UsageError
from passmd.cli.options import ACTUATOR_DYNAMICS, DEFAULT_DRIVE, DRIVE_QUANTITIES, OPTION_FOR, QUANTITIES
from passmd.parameters import Drive, actuator_for_radius, actuator_viscosity
from passmd.units import dimension_name, from_si

__all__ = ["build_drive", "explain"]


def _given(args) -> dict[str, float]:
    """SI values of the drive options the user gave, by flag (each checked in display units)."""
    values = {q.flag: q.parse(args) for q in DRIVE_QUANTITIES if hasattr(args, q.dest)}
    return {flag: value for flag, value in values.items() if value is not None}


def _check_combinations(given, args, load_cell: bool) -> None:
    if getattr(args, "actuator", None) == "rigid":
        dynamics = [flag for flag in ACTUATOR_DYNAMICS if flag in given]
        if dynamics:
            raise UsageError(f"{dynamics[0]} contradicts --actuator rigid: ideally rigid actuators have no "
                             "stiffness, mass or viscosity (use --actuator flexible, or drop the option)")
    if "--load-cell-stiffness" in given and not load_cell:
        raise UsageError("--load-cell-stiffness has no effect here: the runner is free (no load cell); "
                         "use it with `passmd force` or `passmd run --load-cell`")


def build_drive(args, **fixed) -> Drive:
    """The :class:`~passmd.parameters.Drive` the parsed options describe (SI inside).

    :data:`~passmd.cli.options.DEFAULT_DRIVE` with each given option replacing its field;
    ``fixed`` (e.g. ``load_cell=True``) replaces fields last. Actuator: Table 2 for the
    radius, each given option replacing its field; the viscosity, unless given, is
    2ζ√(k_p m_a) of the final k_p and m_a (:func:`~passmd.parameters.actuator_viscosity`).
    The dataclasses validate the result.
    """
    given = _given(args)
    _check_combinations(given, args, bool(fixed.get("load_cell", False)))
    fields = {q.field: given[q.flag] for q in DRIVE_QUANTITIES if q.flag in given}

    def part(name: str) -> dict[str, float]:
        return {key.split(".", 1)[1]: value for key, value in fields.items() if key.startswith(name + ".")}

    changes = {key: value for key, value in fields.items() if "." not in key}
    base = actuator_for_radius(changes.get("hemisphere_radius", DEFAULT_DRIVE.hemisphere_radius))
    actuator = {"stiffness": base.stiffness, "mass": base.mass, **part("actuator")}
    actuator.setdefault("viscosity", actuator_viscosity(actuator["stiffness"], actuator["mass"]))
    changes["actuator"] = replace(base, **actuator)
    changes["amplifier"] = replace(DEFAULT_DRIVE.amplifier, **part("amplifier"))
    for name in ("hemisphere_material", "runner_material"):
        material = getattr(DEFAULT_DRIVE, name)
        if part(name):
            changes[name] = replace(material, **part(name), name=f"{material.name} (modified)")
    changes["allow_extrapolation"] = bool(getattr(args, "allow_extrapolation", False))
    if hasattr(args, "contacts"):
        changes.update(contacts=args.contacts, actuator_model=args.actuator)
    return replace(DEFAULT_DRIVE, **{**changes, **fixed})


# --------------------------------------------------------------------------------------
# Refused inputs in the options' terms
# --------------------------------------------------------------------------------------

#: How to move an option to meet a limit on it.
_VERBS = {">": "raise {} above", ">=": "raise {} to at least", "<": "lower {} below",
          "<=": "lower {} to at most"}


def explain(exc: ValueError, args) -> str:
    """The one-line message of a refused input, naming the option the user typed.

    An :class:`~passmd._validation.InputError` (or a usage error raised from one) whose input
    an option of this command sets (:data:`~passmd.cli.options.OPTION_FOR`) is said again
    with that option as typed, the limit in the option's unit and why; a quantity computed
    from an option says what it is, its value and how to change the option. Any other error
    keeps its message.
    """
    cause = exc if isinstance(exc, InputError) else exc.__cause__
    text = _rephrase(cause, args) if isinstance(cause, InputError) else None
    return text or str(exc)


def _rephrase(exc: InputError, args) -> str | None:
    """``exc`` in the options' terms, or None when no option of this command set its input."""
    lifted = "--allow-extrapolation goes beyond it" if exc.soft else ""
    why = f" ({exc.why})" if exc.why else ""
    if exc.sources:  # several options together (e.g. the Hertz contact of --preload and --radius)
        flags = list(dict.fromkeys(flag for flag in (_flag(name, args) for name in exc.sources) if flag))
        if not flags:
            return None
        given = [f"{flag} {_typed(flag, args)}" for flag in flags if getattr(args, _dest(flag)) is not None]
        return f"{', '.join(given or flags)}: {exc.detail}" + (f"; {lifted}" if lifted else "")
    if exc.quantity and exc.source:  # a quantity computed from one option
        flag = _flag(exc.source, args)
        if flag is None or not exc.limits:
            return None
        unit = _display_unit(exc.unit, flag)
        value = float(exc.value)
        shown = f"{from_si(value, unit) if unit else value:.4g}{_suffix(unit or exc.unit)}"
        text = (f"{exc.quantity} derived from {flag} {_typed(flag, args, exc.source_value)} is {shown}, "
                f"out of range: must be {_limits(exc.limits, unit, exc.unit)}{why}")
        remedies = [f"{_VERBS[op].format(flag)} {_bound(op, bound, _quantity_unit(flag), '')}"
                    for op, bound in exc.source_limits[:1]] + ([lifted] if lifted else [])
        return text + (f"; {', or '.join(remedies)}" if remedies else "")
    flag = _flag(exc.name, args)
    if flag is None or not exc.limits:
        return None
    return (f"{flag} = {_typed(flag, args, exc.value)} is out of range: must be "
            f"{_limits(exc.limits, _quantity_unit(flag), exc.unit)}{why}" + (f"; {lifted}" if lifted else ""))


def _flag(name: str | None, args) -> str | None:
    """The option of this command that sets the input ``name``, or None."""
    flag = OPTION_FOR.get(name or "")
    return flag if flag is not None and hasattr(args, _dest(flag)) else None


def _dest(flag: str) -> str:
    return flag.lstrip("-").replace("-", "_")


def _quantity_unit(flag: str) -> str:
    q = QUANTITIES.get(flag)
    return q.unit if q is not None else ""


def _typed(flag: str, args, value_si=None) -> str:
    """The option's value as the user typed it (a bare number with the unit it is read in).

    An option left out shows ``value_si`` (its default) in the option's unit.
    """
    raw = getattr(args, _dest(flag))
    unit = _quantity_unit(flag)
    if raw is None:
        if value_si is None:
            return "(default)"
        return f"{from_si(float(value_si), unit) if unit else float(value_si):.10g}{_suffix(unit)} (default)"
    text = str(raw).strip()
    try:
        float(text)
    except ValueError:
        return text
    return f"{text} {unit}" if unit else text


def _display_unit(si_unit: str, flag: str) -> str:
    """The option's display unit if the quantity has the option's dimension, else ``""`` (SI)."""
    unit = _quantity_unit(flag)
    if not unit or si_unit in ("", "–"):
        return ""
    return unit if dimension_name(unit) == dimension_name(si_unit) else ""


def _suffix(unit: str) -> str:
    return f" {unit}" if unit and unit != "–" else ""


def _limits(limits, unit: str, si_unit: str) -> str:
    """``"> -1 and < 0.5"``: the limits in ``unit`` (else in SI, ``si_unit``)."""
    return " and ".join(f"{op} {_bound(op, bound, unit, si_unit)}" for op, bound in limits)


def _bound(op: str, bound: float, unit: str, si_unit: str) -> str:
    """One limit's bound in ``unit`` (else SI), 4 digits rounded on its safe side, with the unit."""
    value = float(from_si(float(bound), unit)) if unit else float(bound)
    return f"{_safe(op, value)}{_suffix(unit or si_unit)}"


def _safe(op: str, bound: float, digits: int = 4) -> str:
    """``bound`` to ``digits`` significant digits, rounded so that the stated limit stays true.

    A lower limit (``>``, ``>=``) is rounded up, an upper one down: any value the rounded
    limit allows, the exact one allows too.
    """
    if bound == 0.0 or not math.isfinite(bound):
        return f"{bound:g}"
    exact = Decimal(bound)
    step = Decimal(1).scaleb(exact.adjusted() - digits + 1)
    rounded = exact.quantize(step, rounding=ROUND_CEILING if op.startswith(">") else ROUND_FLOOR)
    return f"{float(rounded):.{digits}g}"
