"""The drive a command line describes, and refused inputs said again in the options' terms.

:func:`build_drive`: the defaults, replaced by a drive file's values (``--drive``), then by
the options the user gave. :func:`explain`: the one
place a refused input (:class:`passmd.runtime.validation.InputError`, raised by the records and
functions the options reach) is said again with the option that set it, as typed.
"""

from __future__ import annotations

from passmd.cli.errors import UsageError
from passmd.cli.options import ACTUATOR_DYNAMICS, DRIVE_QUANTITIES, OPTION_FOR, QUANTITIES
from passmd.cli.output import flyback_label, fmt
from passmd.model.drive_file import (
    REGION_KEY,
    SHORTEST_FLYBACK,
    SHORTEST_FLYBACK_WHY,
    DriveFileError,
    read_drive_file,
    region_values,
    resolve,
)
from passmd.model.parameters import Drive
from passmd.model.tables import FLYBACK_RULES
from passmd.runtime.units import QuantityError, dimension_name, from_si, parse_quantity
from passmd.runtime.validation import LIMIT_VERBS, InputError, file_message, safe_bound

__all__ = ["build_drive", "drive_rows", "explain", "region_drives", "resolve_drive"]


def _given(args) -> dict[str, float]:
    """SI values of the drive options the user gave, by flag (each checked in display units)."""
    values = {q.flag: q.parse(args) for q in DRIVE_QUANTITIES if hasattr(args, q.dest)}
    return {flag: value for flag, value in values.items() if value is not None}


def _check_combinations(given, args, load_cell: bool, rigid: bool) -> None:
    if rigid:
        dynamics = [flag for flag in ACTUATOR_DYNAMICS if flag in given]
        if dynamics:
            raise UsageError(f"{dynamics[0]} contradicts --actuator rigid: ideally rigid actuators have no "
                             "stiffness, mass or viscosity (use --actuator flexible, or drop the option)")
    if "--actuator-viscosity" in given and "--damping-ratio" in given:
        raise UsageError("--actuator-viscosity contradicts --damping-ratio: give one (c_p = 2ζ√(k_p m_a))")
    if "--load-cell-stiffness" in given and not load_cell:
        raise UsageError("--load-cell-stiffness has no effect here: the runner is free (no load cell); "
                         "use it with `passmd force` or `passmd run --load-cell`")


def resolve_drive(args, **fixed) -> tuple[Drive, dict[str, str]]:
    """The drive the options (and ``--drive FILE``) describe, and where each parameter came from.

    The drive file's values (:func:`passmd.model.drive_file.read_drive_file`), then each option
    given replacing its key, then ``fixed`` (e.g. ``load_cell=True``) replacing fields last;
    what is left comes from the paper as :func:`passmd.model.drive_file.resolve` says (Table 2
    actuator of the radius, viscosity 2ζ√(k_p m_a) of the final k_p and m_a). Returns the
    drive and, by drive-file key, ``"file NAME"``, ``"option --flag"`` or the default's source.
    """
    return _resolve(args, _file_values(args), **fixed)


def _file_values(args) -> dict:
    """The values of the --drive file (none without one); its allow_extrapolation lifts the options'
    soft limits too."""
    path = getattr(args, "drive", None)
    if path is None:
        return {}
    values = read_drive_file(path, allow_extrapolation=bool(getattr(args, "allow_extrapolation", False)))
    if values.get("allow_extrapolation") is True:
        args.allow_extrapolation = True
    return values


def region_drives(args, **fixed) -> list[Drive]:
    """The drives at the points of the fit's 95 % region a fitted --drive file records
    (:func:`passmd.model.drive_file.region_values`), each with the options applied as
    :func:`resolve_drive` applies them; none for a file without a region."""
    return [_resolve(args, values, **fixed)[0] for values in region_values(_file_values(args))]


def _resolve(args, values: dict, **fixed) -> tuple[Drive, dict[str, str]]:
    """:func:`resolve_drive` from the drive file's ``values``."""
    values = {k: v for k, v in values.items() if k != REGION_KEY}
    path = getattr(args, "drive", None)
    origins = dict.fromkeys(values, f"given in {path}")
    given = _given(args)
    rigid = (getattr(args, "actuator", None) or values.get("actuator_model")) == "rigid"
    _check_combinations(given, args, bool(fixed.get("load_cell", values.get("load_cell", False))), rigid)
    for q in DRIVE_QUANTITIES:
        if q.flag in given:
            values[q.field] = given[q.flag]
            origins[q.field] = f"option {q.flag}"
            if q.field == "actuator.viscosity":
                values.pop("actuator.damping_ratio", None)
            if q.field == "actuator.damping_ratio":
                values.pop("actuator.viscosity", None)
    if getattr(args, "contacts", None) is not None:
        values["contacts"] = {1: "one", 6: "paper-six"}[args.contacts]
        origins["contacts"] = "option --contacts"
        values.pop("contact_groups", None)  # the option's preset replaces the file's groups
    if getattr(args, "actuator", None) is not None:
        values["actuator_model"], origins["actuator_model"] = args.actuator, "option --actuator"
    if getattr(args, "flyback", None) is not None:
        values["amplifier.flyback"], origins["amplifier.flyback"] = _flyback(args.flyback), "option --flyback"
    if getattr(args, "allow_extrapolation", False):
        values["allow_extrapolation"] = True
        origins.setdefault("allow_extrapolation", "option --allow-extrapolation")
    try:
        return resolve(values, origins, **fixed)
    except InputError as exc:
        inputs = {exc.name, exc.source, *(exc.sources or ())} - {None}
        if path is not None and any(origins.get(key) == f"given in {path}" for key in inputs):
            # a value of the file (or one derived from it, e.g. ζ from c_p): name the file
            raise DriveFileError(f"{path}: {file_message(exc)}", name=exc.name, value=exc.value) from None
        raise


def _flyback(raw: str) -> str | float:
    """``--flyback``: ``slew``, ``fixed`` or a time with its unit (a bare number is refused: shown in us)."""
    text = raw.strip()
    if text in FLYBACK_RULES:
        return text
    try:
        value = parse_quantity(text, "us", name="--flyback")
    except QuantityError as exc:
        if any(c.isdigit() for c in text):
            raise UsageError(str(exc)) from None
        raise UsageError(f"--flyback = {raw!r} is not allowed: must be slew, fixed or a time with its unit, "
                         "e.g. 1.5us") from None
    if not value >= SHORTEST_FLYBACK:
        raise UsageError(f"--flyback = {raw!r} is out of range: must be >= {SHORTEST_FLYBACK * 1e6:g} us "
                         f"({SHORTEST_FLYBACK_WHY})")
    return value


def build_drive(args, **fixed) -> Drive:
    """The :class:`~passmd.model.parameters.Drive` the parsed options describe (SI inside).

    As :func:`resolve_drive`, without the sources; the dataclasses validate the result.
    """
    return resolve_drive(args, **fixed)[0]


def drive_rows(drive: Drive) -> list[tuple[str, str]]:
    """Two compact rows of the drive a command used: contacts and runner, and the actuators."""
    act, amp = drive.actuator, drive.amplifier
    e1, e2 = drive.hemisphere_material, drive.runner_material
    rows = [("drive", f"R = {fmt(drive.hemisphere_radius, 'mm')}, F_p = {fmt(drive.preload, 'N')}, "
                      f"μ = {drive.friction_coefficient:g}, m_r = {fmt(drive.runner_mass, 'g')}, "
                      f"E_1 = {fmt(e1.youngs_modulus, 'GPa')}, E_2 = {fmt(e2.youngs_modulus, 'GPa')}, "
                      f"ν = {e1.poissons_ratio:g}/{e2.poissons_ratio:g}")]
    stroke = (f"A_max = {fmt(act.full_stroke_amplitude, 'nm')}, SR = {amp.slew_rate / 1e6:.4g} V/µs, "
              f"{flyback_label(amp.flyback)} fly-back")
    if drive.actuator_model == "flexible":
        rows.append(("actuators", f"k_p = {act.stiffness:.4g} N/m, m_a = {act.mass:.4g} kg, "
                                  f"c_p = {act.viscosity:.4g} kg/s (ζ = {act.damping_ratio:.3g}), {stroke}"))
    else:
        rows.append(("actuators", f"rigid, {stroke}"))
    return rows


# --------------------------------------------------------------------------------------
# Refused inputs in the options' terms
# --------------------------------------------------------------------------------------

#: How to move an option to meet a limit on it.


def explain(exc: ValueError, args) -> str:
    """The one-line message of a refused input, naming the option the user typed.

    An :class:`~passmd.runtime.validation.InputError` (or a usage error raised from one) whose input
    an option of this command sets (:data:`~passmd.cli.options.OPTION_FOR`) is said again
    with that option as typed, the limit in the option's unit and why; a quantity computed
    from an option says what it is, its value and how to change the option. Any other error
    keeps its message.
    """
    cause = exc if isinstance(exc, InputError) else exc.__cause__
    if isinstance(cause, DriveFileError):  # already names the drive file and its key as typed
        return str(cause)
    text = _rephrase(cause, args) if isinstance(cause, InputError) else None
    text = text or str(exc)
    if isinstance(cause, InputError) and cause.name == "frequency" and "fly-back" in (cause.why or ""):
        text += f"; the fly-back is {_flyback_source(args)}"
    return text


def _flyback_source(args) -> str:
    """Where the fly-back of a run comes from, as the user gave it."""
    if getattr(args, "flyback", None) is not None:
        return f"--flyback {args.flyback}"
    path = getattr(args, "drive", None)
    if path is not None:
        try:
            given = read_drive_file(path, allow_extrapolation=True).get("amplifier.flyback")
        except (DriveFileError, ValueError):
            given = None
        if given is not None:
            return f"amplifier.flyback in {path}"
    return "the slew-rate rule (A/A_max)·V_pp/SR (--slew-rate, --amplifier-voltage; or --flyback)"


def _rephrase(exc: InputError, args) -> str | None:
    """``exc`` in the options' terms, or None when no option of this command set its input."""
    lifted = "--allow-extrapolation goes beyond it" if exc.soft else ""
    why = f" ({exc.why})" if exc.why else ""
    if exc.sources:  # several options together (e.g. the Hertz contact of --preload and --radius)
        flags = list(dict.fromkeys(flag for flag in (_flag(name, args) for name in exc.sources) if flag))
        if not flags:
            return None
        given = [f"{flag} {_typed(flag, args)}" for flag in flags if getattr(args, _dest(flag)) is not None]
        if not given and getattr(args, "drive", None) is not None:  # the file's contacts, not an option
            return (f"{args.drive}: {exc.detail} (the contacts this drive file describes: its preload, "
                    "hemisphere_radius, materials and contact_groups)") + (f"; {lifted}" if lifted else "")
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
        remedies = [f"{LIMIT_VERBS[op].format(flag)} {_bound(op, bound, _quantity_unit(flag), '')}"
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
    return f"{text} {unit}" if unit else text  # only options shown in SI take a bare number


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
    return f"{safe_bound(op, value)}{_suffix(unit or si_unit)}"
