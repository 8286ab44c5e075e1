"""Drive files: a drive described in TOML, read back to a :class:`~passmd.model.parameters.Drive`.

A drive file names the drive's parameters by their :class:`~passmd.model.parameters.Drive` field,
dotted for a part (``actuator.mass``); top-level keys may also sit in a ``[drive]`` table::

    hemisphere_radius = "0.5 mm"     # a string with a unit, read by passmd.runtime.units
    preload = 0.6                    # a bare number: SI (N)
    contacts = "paper-six"           # or "one"; or any arrangement as [[contact_groups]] tables:
    #   [[contact_groups]]
    #   count = 2
    #   side = 1                      # the side of the runner (1 or 2)
    #   contact_angle = "45 deg"      # preload's line to the contact's plane (90 deg: flat)
    #   radius = "0.5 mm"             # optional: the drive's hemisphere_radius
    #   load_share = 0.7              # optional: F_N / F_p (or normal_force = "0.3 N");
    #                                 # left out: F_N = F_p / (n sin α) on the side (Eq. 1)

    [actuator]
    stiffness = "5e6 N/m"
    mass = "1.5e-5 kg"
    damping_ratio = 0.05             # c_p = 2ζ√(k_p m_a); or viscosity = "..." (not both)

A bare number is always in SI units (m, kg, s, N, N/m, kg/s, Pa, V, V/s): a file has no
display unit. Every value is checked once, here, against the ranges the command line uses
(:data:`~passmd.model.parameters.PLAUSIBLE_RANGES`); a refused value is one line naming the file,
the key as typed, the value and the allowed range.

What is not given comes from the paper: Table 1 (materials, masses, μ), Section 4 (preload),
Table 2 for the actuator of the drive's radius (interpolated between its two rows), and the
viscosity derived from the damping ratio ζ (assumption ``actuator_viscosity``).
:func:`resolve` records where each value came from, for ``passmd drive show``.
:func:`drive_toml` (:mod:`passmd.model.drive_writer`) writes a file :func:`load_drive` reads back to an
equal drive.
"""

from __future__ import annotations

import math
import sys
from dataclasses import replace

from passmd.model.arrangement import FLAT, ContactGroup
from passmd.model.drive_keys import ACTUATOR_DYNAMICS, GROUP_KEYS, SI_UNITS, DriveKey, drive_value
from passmd.model.drive_keys import CONTACT_PRESETS as CONTACT_PRESETS
from passmd.model.drive_keys import DRIVE_KEYS as DRIVE_KEYS
from passmd.model.drive_keys import EXAMPLE_DRIVE_FILE as EXAMPLE_DRIVE_FILE
from passmd.model.drive_keys import JOINT_READING_FILE as JOINT_READING_FILE
from passmd.model.drive_writer import drive_toml as drive_toml
from passmd.model.parameters import PLAUSIBLE_RANGES, Drive
from passmd.model.tables import (
    ACTUATOR_DAMPING_RATIO,
    FLYBACK_RULES,
    Amplifier,
    actuator_for_radius,
    actuator_viscosity,
    table2_source,
)
from passmd.runtime.inputs import RefusedFile, decode_text, read_bounded
from passmd.runtime.units import QuantityError, parse_angle, parse_quantity
from passmd.runtime.validation import InputError, file_message

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = ["CONTACT_PRESETS", "DRIVE_KEYS", "EXAMPLE_DRIVE_FILE", "JOINT_READING_FILE", "REGION_KEY",
           "SHORTEST_FLYBACK", "SHORTEST_FLYBACK_WHY", "DriveFileError", "DriveKey", "drive_toml",
           "load_drive", "parameter_rows", "read_drive_file", "region_values", "resolve"]


class DriveFileError(InputError):
    """A drive file that cannot be read, or a key or value in it that is refused (one line)."""


_DEFAULT = Drive()


#: Shortest stated fly-back time (s): about a thousandth of Section 2's full-stroke fly-back V_pp/SR,
#: far beyond any amplifier; much shorter, the saw-tooth's corner times are no longer distinct at the
#: precision of a period's times.
SHORTEST_FLYBACK = 1e-9
SHORTEST_FLYBACK_WHY = "about a thousandth of the paper's full-stroke fly-back V_pp/SR, beyond any amplifier"


def _flatten(table: dict, name: str, prefix: str = "", section: str = "the top level",
             seen: dict | None = None) -> dict:
    """The file's keys, dotted (``[drive]`` dropped); a key given twice, e.g. ``preload`` at the top
    level and in ``[drive]``, is refused naming both places (TOML refuses only a repeat within one
    table, and the second would silently win)."""
    seen = {} if seen is None else seen  # key -> where it was given
    out = {}
    for part, value in table.items():
        if isinstance(value, dict):
            key = f"{prefix}{part}"
            inner = "" if key == "drive" and not prefix else key + "."
            out.update(_flatten(value, name, inner, f"[{key}]", seen))
            continue
        key = f"{prefix}{part}"
        if key in seen:
            raise DriveFileError(f"{name}: {key} is given twice, in {seen[key]} and in {section}: give it "
                                 "once",
                                 name=key, value=value)
        seen[key] = section
        out[key] = value
    return out


def _refuse(where: str, text: str, **kw) -> DriveFileError:
    """``"file: key = value …"``: ``where`` is ``"file: key"``, ``text`` starts with ``"= value"``."""
    return DriveFileError(f"{where} {text}", **kw)


def _value(where: str, spec: DriveKey, raw, allow_extrapolation: bool):
    """The SI value (or string/bool) of one key, checked; ``where`` is ``"file: key"``."""
    if spec.unit == "bool":
        if not isinstance(raw, bool):
            raise _refuse(where, f"= {raw!r}: must be true or false", name=spec.key, value=raw)
        return raw
    if spec.unit == "str":
        if not isinstance(raw, str):
            raise _refuse(where, f"= {raw!r}: must be a string", name=spec.key, value=raw)
        return raw
    if spec.unit == "groups":
        return _groups(where, raw, allow_extrapolation)
    if spec.unit == "flyback":
        return _flyback(where, spec, raw)
    if spec.unit == "choice":
        if isinstance(raw, str) and raw in spec.choices:
            return raw
        if spec.key == "contacts" and not isinstance(raw, bool) and raw in CONTACT_PRESETS.values():
            return {1: "one", 6: "paper-six"}[raw]
        raise _refuse(where, f"= {raw!r}: must be one of {', '.join(repr(c) for c in spec.choices)}",
                      name=spec.key, value=raw)
    if isinstance(raw, bool) or not isinstance(raw, (int, float, str)):
        raise _refuse(where, f"= {raw!r}: must be a number (SI, {spec.unit or 'plain'}) or a string with "
                             f"a unit, e.g. \"1 {spec.display or spec.unit}\"", name=spec.key, value=raw)
    try:
        value = parse_quantity(raw, spec.unit, name=where)
    except QuantityError as exc:
        raise DriveFileError(str(exc), name=spec.key, value=raw) from None
    except OverflowError:  # an integer beyond any float, e.g. 10**400
        digits = str(raw)
        raise _refuse(where, f"= {digits[:8]}… ({len(digits)} digits) is out of range: too large for a "
                             "number",
                      name=spec.key, value=raw) from None
    si = f" {spec.unit}" if spec.unit else ""
    if spec.plausible is not None:
        try:
            PLAUSIBLE_RANGES[spec.plausible].check(spec.key, value, allow_extrapolation=allow_extrapolation)
        except InputError as exc:
            limits = " and ".join(f"{op} {bound:.4g}{si}" for op, bound in exc.limits)
            hint = "; allow_extrapolation = true goes beyond it" if exc.soft else ""
            raise _refuse(where, f"= {raw!r} is out of range: must be {limits} ({exc.why}){hint}",
                          name=spec.key, value=raw, limits=exc.limits, soft=exc.soft) from None
    elif spec.key == "actuator.viscosity" and not value >= 0.0:
        raise _refuse(where, f"= {raw!r} is out of range: must be >= 0{si}", name=spec.key, value=raw)
    return value


def _flyback(label: str, spec: DriveKey, raw) -> str | float:
    """A fly-back rule: ``"slew"``, ``"fixed"``, or a time (a string with a unit, or a bare number in s)."""
    if isinstance(raw, str) and raw.strip() in FLYBACK_RULES:
        return raw.strip()
    refused = _refuse(label, f"= {raw!r}: must be \"slew\", \"fixed\" or a time, e.g. \"1.5 us\"",
                      name=spec.key, value=raw)
    if isinstance(raw, bool) or not isinstance(raw, (int, float, str)):
        raise refused
    try:
        value = parse_quantity(raw, "s", name=label)
    except QuantityError:
        raise refused from None
    if not (math.isfinite(value) and value >= SHORTEST_FLYBACK):
        raise _refuse(label, f"= {raw!r} is out of range: must be >= {SHORTEST_FLYBACK:g} s "
                             f"({SHORTEST_FLYBACK_WHY})", name=spec.key, value=raw,
                      limits=((">=", SHORTEST_FLYBACK),))
    return value


def _groups(where: str, raw, allow_extrapolation: bool) -> tuple:
    """``[[contact_groups]]`` tables to :class:`~passmd.model.arrangement.ContactGroup` s, each key
    checked."""
    if not isinstance(raw, list) or not raw or not all(isinstance(t, dict) for t in raw):
        raise _refuse(where, "must be one or more [[contact_groups]] tables (count, side, contact_angle, "
                             "load_share or normal_force, radius)", name="contact_groups", value=raw)
    groups = []
    for i, table in enumerate(raw):
        label = f"{where}[{i}]"
        unknown = [k for k in table if k not in GROUP_KEYS]
        if unknown:
            raise _refuse(f"{label}.{unknown[0]}", f"is not a key of a contact group: the known keys are "
                          f"{', '.join(GROUP_KEYS)}", name="contact_groups", value=table)
        values = {}
        for key, allowed, rule in (("count", None, "must be an integer >= 1"), ("side", (1, 2), "must be 1 "
                                   "or 2 (the side of the runner the group presses on)")):
            value = table.get(key)
            if key in table or key == "count":
                if isinstance(value, bool) or not isinstance(value, int) or value < 1 or (
                        allowed and value not in allowed):
                    raise _refuse(f"{label}.{key}", f"= {value!r}: {rule}", name="contact_groups",
                                  value=value)
                values[key] = value
        if "contact_angle" in table:
            values["contact_angle"] = _angle(f"{label}.contact_angle", table["contact_angle"])
        for key in ("load_share", "normal_force", "radius"):
            if key in table:
                spec = DriveKey(f"contact_groups.{key}", GROUP_KEYS[key], "", "", key, "",
                                {"normal_force": "preload", "radius": "hemisphere_radius"}.get(key))
                values[key] = _value(f"{label}.{key}", spec, table[key], allow_extrapolation)
                if key == "load_share" and not values[key] > 0:
                    raise _refuse(f"{label}.{key}", f"= {table[key]!r} is out of range: must be > 0",
                                  name="contact_groups", value=table[key])
        if "load_share" in values and "normal_force" in values:
            raise _refuse(label, "gives both load_share and normal_force: give at most one (neither: the "
                                 "normal force follows from the preload and the contact angles, Eq. 1)",
                          name="contact_groups", value=table)
        groups.append(ContactGroup(**values))
    return tuple(groups)


def _angle(where: str, raw) -> float:
    """A contact angle in rad, 0 < α <= 90°; ``where`` is ``"file: contact_groups[i].contact_angle"``."""
    try:
        value = parse_angle(raw, name=where)
    except QuantityError as exc:
        raise DriveFileError(str(exc), name="contact_groups", value=raw) from None
    if not 0.0 < value <= FLAT:
        bare = " (a bare number is in rad: write \"45 deg\")" if not isinstance(raw, str) else ""
        raise _refuse(where, f"= {raw!r} is out of range: must be > 0 and <= 90 deg (the angle between the "
                             f"preload's line and the contact's tangent plane; 90 deg: a flat guide){bare}",
                      name="contact_groups", value=raw)
    return value


#: The table a fitted drive file records its fit's region in (:func:`drive_toml`'s ``region``): the
#: values of the fitted keys at each extreme point of the 95 % region; not a drive parameter.
REGION_KEY = "fit_region.points"
_NUMERIC = {key for key, spec in DRIVE_KEYS.items() if spec.unit in SI_UNITS}


def _region(where: str, raw, allow_extrapolation: bool) -> tuple[dict, ...]:
    """``[fit_region] points``: a list of tables of numeric drive keys, each value checked as the key's."""
    if not isinstance(raw, list) or not raw or not all(isinstance(t, dict) and t for t in raw):
        raise _refuse(where, "must be a list of tables of drive keys and their values, e.g. "
                             "[{friction_coefficient = 0.21}]", name=REGION_KEY, value=raw)
    points = []
    for i, table in enumerate(raw):
        unknown = [k for k in table if k not in _NUMERIC]
        if unknown:
            raise _refuse(f"{where}[{i}].{unknown[0]}", "is not a numeric drive key", name=REGION_KEY,
                          value=table)
        points.append({k: _value(f"{where}[{i}].{k}", DRIVE_KEYS[k], v, allow_extrapolation)
                       for k, v in table.items()})
    return tuple(points)


def region_values(values: dict) -> list[dict]:
    """The drive-file values at each point of a fitted drive file's region (``values`` as
    :func:`read_drive_file` returns them): the file's values with the point's keys replaced; none
    when the file records no region."""
    base = {k: v for k, v in values.items() if k != REGION_KEY}
    out = []
    for point in values.get(REGION_KEY, ()):
        at = {**base, **point}
        if "actuator.viscosity" in point:
            at.pop("actuator.damping_ratio", None)
        out.append(at)
    return out


def read_drive_file(path, *, allow_extrapolation: bool | None = None) -> dict:
    """The values a drive file gives, by key (SI floats, strings, booleans), each checked.

    ``allow_extrapolation`` (the command line's option) lifts the soft limits as the file's own
    ``allow_extrapolation = true`` does. The file is read as UTF-8 (a byte-order mark is
    dropped) from a regular file of at most ``LIMITS["drive file"]`` bytes
    (:func:`passmd.runtime.inputs.read_bounded`). Raises :class:`DriveFileError` (a
    ``ValueError``): the file unreadable, not a regular file, too large or not TOML, a key
    unknown (the known ones listed), or a value refused.
    """
    name = str(path)
    try:
        text = decode_text(read_bounded(path, "drive file"), name, "drive file")
        table = tomllib.loads(text)
    except OSError as exc:
        raise DriveFileError(f"cannot read the drive file {name}: {exc.strerror or exc}", name="drive",
                             value=name) from None
    except RefusedFile as exc:
        raise DriveFileError(str(exc), name="drive", value=name) from None
    except tomllib.TOMLDecodeError as exc:
        raise DriveFileError(f"{name}: not a TOML file: {exc}", name="drive", value=name) from None
    except RecursionError:
        raise DriveFileError(f"{name}: not a drive file: its arrays or tables are nested too deeply for the "
                             "TOML reader (a drive file's values are numbers, strings and flat tables)",
                             name="drive", value=name) from None
    raw = _flatten(table, name)
    region = raw.pop(REGION_KEY, None)
    unknown = [key for key in raw if key not in DRIVE_KEYS]
    if unknown:
        raise DriveFileError(f"{name}: unknown key {unknown[0]!r}: the known keys are "
                             f"{', '.join(DRIVE_KEYS)}", name=unknown[0], value=raw[unknown[0]])
    lift = raw.get("allow_extrapolation") is True or bool(allow_extrapolation)
    values = {key: _value(f"{name}: {key}", DRIVE_KEYS[key], value, lift) for key, value in raw.items()}
    if region is not None:
        values[REGION_KEY] = _region(f"{name}: {REGION_KEY}", region, lift)
    if "contacts" in values and "contact_groups" in values:
        raise DriveFileError(f"{name}: contacts and contact_groups both given: give one (a preset, or the "
                             "groups)", name="contacts", value=values["contacts"])
    dynamics = [key for key in ACTUATOR_DYNAMICS if key in values]
    if values.get("actuator_model") == "rigid" and dynamics:
        raise DriveFileError(f"{name}: {dynamics[0]} contradicts actuator_model = \"rigid\": ideally rigid "
                             "actuators have no stiffness, mass or damping; remove it, or set actuator_model "
                             "= \"flexible\"", name=dynamics[0], value=values[dynamics[0]])
    if "actuator.viscosity" in values and "actuator.damping_ratio" in values:
        raise DriveFileError(f"{name}: actuator.viscosity and actuator.damping_ratio both given: give one "
                             "(c_p = 2ζ√(k_p m_a))", name="actuator.viscosity",
                             value=values["actuator.viscosity"])
    return values


def resolve(values: dict, origins: dict | None = None, **fixed) -> tuple[Drive, dict]:
    """The drive ``values`` describe, and where each of its parameters came from.

    ``values``: SI values by drive-file key (:data:`~passmd.model.drive_keys.DRIVE_KEYS`); ``origins``:
    how each was given (``"file"``, ``"option"``; default ``"given"``). ``fixed`` replaces Drive fields last
    (``load_cell=True`` for a stall run). What is not given: the paper's default (its source),
    the Table 2 actuator of the radius (interpolated between its rows), the viscosity
    2ζ√(k_p m_a) of the final k_p and m_a. Returns ``(drive, sources)``, ``sources`` by key.
    """
    origins = origins or {}
    sources = {key: origins.get(key, "given") for key in values}
    for key, spec in DRIVE_KEYS.items():
        sources.setdefault(key, f"default ({spec.source})")

    def get(key):
        return values.get(key, drive_value(_DEFAULT, key))

    radius = get("hemisphere_radius")
    base = actuator_for_radius(radius)
    table2 = table2_source(radius)
    act = {name: values.get(f"actuator.{name}", getattr(base, name))
           for name in ("stiffness", "mass", "full_stroke_amplitude")}
    sources.update({f"actuator.{name}": table2 for name in act if f"actuator.{name}" not in values})
    zeta = values.get("actuator.damping_ratio", ACTUATOR_DAMPING_RATIO)
    if "actuator.viscosity" in values:
        viscosity = values["actuator.viscosity"]
        sources["actuator.damping_ratio"] = "derived from c_p"
    else:
        viscosity = float(actuator_viscosity(act["stiffness"], act["mass"], zeta))
        sources["actuator.viscosity"] = f"derived from ζ = {zeta:g}: 2ζ√(k_p m_a)"
    changes = {"actuator": replace(base, viscosity=viscosity, **act)}
    for which in ("hemisphere_material", "runner_material"):
        material = getattr(_DEFAULT, which)
        part = {key.split(".", 1)[1]: value for key, value in values.items() if key.startswith(which + ".")}
        if part:
            part.setdefault("name", f"{material.name} (modified)")
            changes[which] = replace(material, **part)
    amplifier = {key.split(".", 1)[1]: value for key, value in values.items() if key.startswith("amplifier.")}
    changes["amplifier"] = replace(Amplifier(), **amplifier)
    for key in ("hemisphere_radius", "preload", "friction_coefficient", "runner_mass", "load_cell_stiffness",
                "load_cell", "allow_extrapolation", "actuator_model", "guide_rail"):
        if key in values:
            changes[key] = values[key]
    if "contacts" in values:
        contacts = values["contacts"]
        changes["contacts"] = CONTACT_PRESETS[contacts] if isinstance(contacts, str) else contacts
        changes["contact_groups"] = ()
        sources["contact_groups"] = "not used (contacts)"
    elif "contact_groups" in values:
        changes["contact_groups"] = values["contact_groups"]
        sources["contacts"] = "derived: the groups' total count"
    changes.update(fixed)
    for key, value in fixed.items():
        if key in DRIVE_KEYS:
            sources[key] = f"set by the command ({value!r})"
    return replace(_DEFAULT, **changes), sources


def load_drive(path, **fixed) -> Drive:
    """The :class:`~passmd.model.parameters.Drive` a drive file describes (module docstring).

    What the file does not give comes from the paper (Tables 1–2, ζ for the viscosity), as
    on the command line. ``fixed`` replaces Drive fields last. Raises ``ValueError`` naming
    the file and the key for a refused value or an unknown key.
    """
    values = read_drive_file(path)
    try:
        return resolve(values, **fixed)[0]
    except DriveFileError:
        raise
    except InputError as exc:
        raise DriveFileError(f"{path}: {file_message(exc)}", name=exc.name, value=exc.value) from None


def parameter_rows(drive: Drive, sources: dict | None = None) -> list[dict]:
    """Every drive-file key of ``drive``: value (SI), unit, symbol, meaning and source."""
    sources = sources or {}
    return [{"key": key, "value": drive_value(drive, key), "unit": spec.unit if spec.unit in SI_UNITS else "",
             "display_unit": spec.display, "symbol": spec.symbol, "meaning": spec.text,
             "source": sources.get(key, spec.source)} for key, spec in DRIVE_KEYS.items()]
