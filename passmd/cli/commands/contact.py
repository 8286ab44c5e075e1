"""``passmd contact``: tangential force of one MDR contact along a displacement path (Eqs. 4–7)."""

from __future__ import annotations

import textwrap

import numpy as np

from passmd.cli.drive import build_drive
from passmd.cli.errors import UsageError
from passmd.cli.options import DEFAULT_DRIVE, NORMAL_FORCE, add_drive_options
from passmd.cli.output import JSON_HELP, check_results, emit_json, fmt
from passmd.model.parameters import check_contact_plausible
from passmd.runtime.units import from_si, parse_quantities

__all__ = ["add_parser", "check_springs", "run_contact"]

_EPILOG = textwrap.dedent("""\
    The path is a comma-separated list of displacements u = x_a − x_r (hemisphere
    minus runner), visited in turn from a virgin contact at u = 0; the force T acts
    on the runner. Example: --path 0nm,30nm,-10nm,45nm

    --json keys (SI units): displacement_m, force_N, model, springs, normal_force_N,
    hemisphere_radius_m, friction_coefficient, E_star_Pa, G_star_Pa, sliding_force_N,
    presliding_m, contact_radius_m""")


def add_parser(command) -> None:
    p = command("contact", "tangential force of one MDR contact along a displacement path (Eqs. 4–7)",
                _EPILOG)
    group = p.add_argument_group("contact")
    NORMAL_FORCE.add(group)
    group.add_argument("--path", metavar="U1,U2,...",
                       help="displacements to visit [nm; unit required] (default: none, required)")
    group.add_argument("--springs", type=int, default=None, metavar="N",
                       help="discrete MDR model with N springs (default: exact, N → ∞)")
    add_drive_options(p, contact_only=True)
    p.add_argument("--json", action="store_true", help=JSON_HELP)
    p.set_defaults(handler=run_contact)


def check_springs(springs):
    """``--springs``: None (the exact contact) or an integer >= 2."""
    if springs is None:
        return None
    if springs < 2:
        raise UsageError(
            f"--springs = {springs} is out of range: must be an integer >= 2 (omit it for the exact contact)"
        )
    return springs


def run_contact(args, out) -> int:
    from passmd.model.mdr_contact import MDRContact
    from passmd.model.theory import contact_moduli

    if args.path is None:
        raise UsageError("--path is required, e.g. --path 0nm,30nm,-10nm,45nm")
    path = parse_quantities(args.path, "nm", name="--path")
    normal = NORMAL_FORCE.parse_or(args, DEFAULT_DRIVE.preload)
    springs = check_springs(args.springs)
    drive = build_drive(args)
    E_star, G_star = contact_moduli(drive)
    check_contact_plausible(normal, drive.hemisphere_radius, E_star, names="--normal-force, --radius",
                            allow_extrapolation=args.allow_extrapolation, hint="--allow-extrapolation")
    contact = MDRContact(normal, drive.hemisphere_radius, E_star, G_star, drive.friction_coefficient,
                         springs=springs)
    forces = contact.path(np.array(path))
    record = {
        "command": "contact",
        "model": contact.model,
        "springs": springs,
        "normal_force_N": contact.normal_force,
        "hemisphere_radius_m": drive.hemisphere_radius,
        "friction_coefficient": drive.friction_coefficient,
        "E_star_Pa": E_star,
        "G_star_Pa": G_star,
        "sliding_force_N": contact.sliding_force,
        "presliding_m": contact.presliding,
        "contact_radius_m": contact.contact_radius,
        "displacement_m": path,
        "force_N": forces,
    }
    check_results(record)
    if args.json:
        emit_json(record, out)
        return 0
    model = "exact (N → ∞)" if springs is None else f"discrete, {springs} springs"
    out.write(
        f"passmd contact — {model}, F_N = {fmt(contact.normal_force, 'N')}, "
        f"R = {fmt(drive.hemisphere_radius, 'mm')}, μ = {drive.friction_coefficient:g}\n"
        f"  μF_N = {contact.sliding_force:.6g} N, u_max = {fmt(contact.presliding, 'nm')} (Eq. 7)\n"
        f"  {'u = x_a − x_r [nm]':>20}  {'T [N]':>12}\n"
    )
    for u, f in zip(path, forces, strict=True):
        out.write(f"  {from_si(u, 'nm'):>20.6g}  {f:>12.6g}\n")
    return 0
