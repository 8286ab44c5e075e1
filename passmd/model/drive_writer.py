"""Writing a drive file: :func:`~passmd.model.drive_writer.drive_toml`, a commented TOML file of a
:class:`~passmd.model.parameters.Drive` that :func:`passmd.model.drive_file.load_drive` reads back to
an equal drive (the keys and their units: :mod:`passmd.model.drive_keys`)."""

from __future__ import annotations

import math

from passmd.model.arrangement import ContactGroup, preset_groups
from passmd.model.drive_keys import ACTUATOR_DYNAMICS, DRIVE_KEYS, GROUP_KEYS, SI_UNITS, DriveKey, drive_value
from passmd.model.parameters import Drive, check_drive
from passmd.model.tables import ACTUATOR_DAMPING_RATIO
from passmd.runtime.units import from_si, parse_angle, parse_quantity

__all__ = ["drive_toml"]


def _number(value: float) -> str:
    """A float as TOML that reads back to the same double (``repr``, integers with ``.0``)."""
    text = repr(float(value))
    return text if any(c in text for c in ".en") else text + ".0"


def _string(text: str) -> str:
    """``text`` as a TOML string (tomli-w escapes quotes, backslashes, newlines and every control
    character), so that any name reads back as written."""
    import tomli_w

    return tomli_w.dumps({"k": text}).partition(" = ")[2].rstrip("\n")


def _shown(value, spec: DriveKey) -> str:
    """A value as TOML: a string in the display unit when that reads back exactly, else SI."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return _string(value)
    si_unit = "s" if spec.unit == "flyback" else spec.unit  # a stated fly-back time
    if spec.display and spec.display != si_unit:
        text = f"{float(from_si(value, spec.display)):.12g} {spec.display}"
        if parse_quantity(text, si_unit) == value:
            return f'"{text}"'
    return _number(value)  # a bare number: SI


def drive_toml(drive: Drive, sources: dict | None = None, *, title: str | None = None,
               damping_ratio: float | None = None, notes=(), region=()) -> str:
    """A commented drive file of ``drive``: :func:`~passmd.model.drive_file.load_drive` reads it back to
    an equal drive.

    Every key is written, with its symbol, meaning, unit and source (``sources`` by key,
    else the paper's source of the default). The viscosity is written as given (c_p), so that
    it reads back exactly; ``damping_ratio``: write this ζ instead, for a drive whose c_p is
    2ζ√(k_p m_a) of its own k_p and m_a (it then reads back exactly too, and ``drive show``
    derives c_p from it). ``notes``: lines the header ends with; ``region``: a fit's region as
    drive-file values at its points (:data:`passmd.model.drive_file.REGION_KEY`, written last).
    """
    check_drive(drive)
    sources = sources or {}
    lines = [f"# {title or 'passmd drive file'}",
             "# Values: a string with a unit (\"0.5 mm\", \"1.5e-5 kg\") or a bare number in SI units.",
             "# Keys left out take the paper's value (Tables 1-2; the actuator of Table 2 for the radius;",
             f"# c_p = 2ζ√(k_p m_a) with ζ = {ACTUATOR_DAMPING_RATIO:g} where the file gives neither).",
             "# Another arrangement of contacts: instead of `contacts`, one [[contact_groups]] table per",
             "# kind of contact (see the end of this file).",
             "# `passmd drive show --drive FILE` lists what a file resolves to, with sources.",
             *(f"# {line}" for line in notes)]
    section = None
    for key, spec in DRIVE_KEYS.items():
        if key in ("actuator.damping_ratio", "contact_groups") or (
                key == "contacts" and drive.contact_groups):
            continue
        head, _, name = key.rpartition(".")
        if head != section:
            lines += ["", f"[{head}]"] if head else [""]
            section = head
        value = drive_value(drive, key)
        if key == "actuator.viscosity" and damping_ratio is not None:
            key, name, value = "actuator.damping_ratio", "damping_ratio", float(damping_ratio)
            spec = DRIVE_KEYS[key]
        unit = f" [{spec.unit}]" if spec.unit in SI_UNITS and spec.unit else ""
        source = sources.get(key, spec.source)
        rigid = drive.actuator_model == "rigid" and key in ACTUATOR_DYNAMICS
        unused = "# (flexible actuators only) " if rigid else ""
        lines.append(f"{unused}{name or key} = {_shown(value, spec)}  # {spec.symbol}: {spec.text}{unit}; "
                     f"{source}")
    for group in drive.contact_groups:  # arrays of tables come last in TOML
        lines += ["", "[[contact_groups]]  # contacts of one kind: count, side, contact angle α, F_N per "
                      "contact (or its share of F_p; else Eq. 1), radius R [m]"]
        lines += [f"{name} = {_group_value(name, value)}" for name, value in _group_items(group)]
    if not drive.contact_groups:  # the preset, written out as groups (commented: a file gives one of the two)
        preset = drive_value(drive, "contacts")
        lines += ["", f"# `contacts = \"{preset}\"` written as contact groups (Eq. 1: each side carries "
                      "F_p, a",
                  "# contact at angle α carries F_N sin α of it); replace `contacts` by tables like these "
                  "for another guide:"]
        for group in preset_groups(drive.contacts):
            lines += ["# [[contact_groups]]"] + [f"# {name} = {_group_value(name, value)}"
                                                 for name, value in _group_items(group)]
    if region:
        lines += ["", "[fit_region]  # the fit's 95 % region: the fitted keys at the ends of each fitted "
                      "parameter's region",
                  "# (the others re-fitted there); passmd sweep and run with this file report the band "
                      "these points span", "points = ["]
        lines += [f"  {{{', '.join(f'{_toml_key(k)} = {_number(v)}' for k, v in point.items())}}},"
                  for point in region]
        lines.append("]")
    return "\n".join(lines) + "\n"


def _toml_key(key: str) -> str:
    """A drive key inside an inline table: quoted when dotted (``"actuator.stiffness"``)."""
    return f'"{key}"' if "." in key else key


def _group_items(group: ContactGroup) -> list[tuple[str, object]]:
    """The given fields of a group, in the order a drive file lists them
    (:data:`~passmd.model.drive_keys.GROUP_KEYS`)."""
    return [(name, getattr(group, name)) for name in GROUP_KEYS if getattr(group, name) is not None]


def _group_value(name: str, value) -> str:
    """A contact group's value as TOML: counts and sides as integers, the angle in degrees when that
    reads back exactly (else rad, SI), the rest as SI numbers."""
    if name in ("count", "side"):
        return str(value)
    if name == "contact_angle":
        text = f"{math.degrees(value):.12g} deg"
        return f'"{text}"' if parse_angle(text) == value else _number(value)
    return _number(value)
