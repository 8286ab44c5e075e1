"""The drive a command line describes: the defaults, replaced by what the user gave."""

from __future__ import annotations

from dataclasses import replace

from passmd.cli.errors import UsageError
from passmd.cli.options import ACTUATOR_DYNAMICS, DEFAULT_DRIVE, DRIVE_QUANTITIES
from passmd.parameters import Drive, actuator_for_radius, actuator_viscosity

__all__ = ["build_drive"]


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
