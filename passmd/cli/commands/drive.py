"""``passmd drive``: a drive file of the paper's drive, and what a drive resolves to."""

from __future__ import annotations

import math
import textwrap

from passmd.cli.drive import resolve_drive
from passmd.cli.options import add_drive_options
from passmd.cli.output import JSON_HELP, describe, drive_record, emit_json, emit_rows, fmt

__all__ = ["add_parser", "run_show", "run_template"]

_EPILOG = textwrap.dedent("""\
    template: prints a commented drive file (TOML) of the paper's drive, every parameter
    with its unit and source: passmd drive template > mydrive.toml. With --example, the
    worked example of the book's chapter "Design your own drive" (a drive that is not the
    paper's, its guide written as [[contact_groups]]):
    passmd drive template --example > example_drive.toml
    With --joint-reading, the paper's drive under the replication ledger's joint reading of
    the paper profile (its protocol options in the header; passmd ledger --write-drive FILE
    writes the one of a ledger run): passmd drive template --joint-reading > joint.toml
    show: every parameter of the drive (--drive FILE and the options) with its unit and
    where it came from: given in the file, an option, or the paper (Table 1, Table 2 for
    the radius, interpolated between its rows; the viscosity derived from ζ).
    A drive file's bare numbers are SI; a string may carry a unit ("0.5 mm").

    show also lists each contact group: its side of the runner, contact angle α, radius and
    normal force per contact (given, or F_p/(n sin α) from the side's balance, Eq. 1).

    show --json keys: parameters [{key, value, unit (SI), symbol, meaning, source}],
    contact_arrangement [{side, count, contact_angle_rad, radius_m, normal_force_N, force_from,
    preload_share_N}], drive{...}""")


def add_parser(command) -> None:
    p = command("drive", "write a drive file, or show what a drive resolves to", _EPILOG)
    sub = p.add_subparsers(dest="action", metavar="ACTION", required=True)
    template = sub.add_parser("template", help="print a drive file of the paper's drive (TOML)",
                              description="print a commented drive file of the paper's drive (TOML)")
    shipped = template.add_mutually_exclusive_group()
    shipped.add_argument("--example", action="store_true",
                         help="print the book's example drive (chapter 'Design your own drive') instead of "
                              "the paper's drive (default: off)")
    shipped.add_argument("--joint-reading", action="store_true",
                         help="print the paper's drive under the replication ledger's joint reading "
                              "(paper profile) instead (default: off)")
    template.set_defaults(handler=run_template)
    show = sub.add_parser("show", help="every parameter of a drive, its unit and where it came from",
                          description="every parameter of a drive, its unit and where it came from")
    add_drive_options(show)
    show.add_argument("--json", action="store_true", help=JSON_HELP)
    show.set_defaults(handler=run_show)


def run_template(args, out) -> int:
    from passmd.model.drive_file import EXAMPLE_DRIVE_FILE, JOINT_READING_FILE, drive_toml, resolve
    from passmd.runtime.inputs import read_text

    if args.example or args.joint_reading:  # the shipped file itself, with its comments
        out.write(read_text(EXAMPLE_DRIVE_FILE if args.example else JOINT_READING_FILE, "drive file"))
        return 0
    drive, sources = resolve({})
    sources = {key: text[len("default ("):-1] if text.startswith("default (") else text
               for key, text in sources.items()}
    out.write(drive_toml(drive, sources, title="passmd drive file: the paper's drive (R = 1 mm, F_p = 0.4 N, "
                                                "μ = 0.2, six contacts, flexible actuators)"))
    return 0


def _shown(row: dict) -> str:
    value, unit = row["value"], row["display_unit"]
    if isinstance(value, list):  # contact groups: listed resolved below the table
        return f"{len(value)} group{'s' * (len(value) != 1)} (see the contact groups below)" if value else "–"
    if isinstance(value, bool) or isinstance(value, str):
        return str(value).lower() if isinstance(value, bool) else value
    if unit and unit not in ("kg", "N/m", "kg/s"):
        return fmt(value, unit)
    return f"{value:.6g} {row['unit']}".rstrip()


def run_show(args, out) -> int:
    from passmd.model.drive_file import parameter_rows

    drive, sources = resolve_drive(args)
    rows = parameter_rows(drive, sources)
    if args.json:
        from passmd.model.theory import contact_arrangement

        emit_json({"command": "drive show", "parameters": [
            {k: row[k] for k in ("key", "value", "unit", "symbol", "meaning", "source")} for row in rows],
            "contact_arrangement": contact_arrangement(drive), "drive": drive_record(drive)}, out)
        return 0
    shown = [(f"{row['key']} ({row['symbol']})", f"{_shown(row)}   [{row['source']}]") for row in rows]
    emit_rows(f"passmd drive show — {describe(drive)}", shown + arrangement_rows(drive), out)
    return 0


def arrangement_rows(drive) -> list[tuple[str, str]]:
    """One row per contact group: side, count, contact angle, radius and normal force per contact
    (given, or from the side's balance, Eq. 1), then what each side carries against F_p."""
    from passmd.model.theory import contact_arrangement

    rows, loads = [], {}
    for i, g in enumerate(contact_arrangement(drive)):
        how = {"Eq. 1": "F_p / (n sin α) on its side, Eq. 1", "load_share": "given as a share of F_p",
               "normal_force": "given"}[g["force_from"]]
        rows.append((f"contact group {i + 1} (side {g['side']})",
                     f"{g['count']} contact{'s' * (g['count'] != 1)} at "
                     f"α = {math.degrees(g['contact_angle_rad']):.4g}°, "
                     f"R = {fmt(g['radius_m'], 'mm')}: F_N = {g['normal_force_N']:.4g} N each ({how})"))
        loads[g["side"]] = loads.get(g["side"], 0.0) + g["preload_share_N"]
    balance = ", ".join(f"side {side} {load:.4g} N" for side, load in sorted(loads.items()))
    rows.append(("preload balance",
                 f"Σ n F_N sin α: {balance}; each side carries F_p = {drive.preload:.4g} N"))
    from passmd.model.arrangement import preset_groups, side_lateral

    left = side_lateral(drive.preload, drive.contact_groups or preset_groups(drive.contacts))
    sideways = ", ".join(f"side {side} {force:.4g} N" for side, force in left.items())
    taken = "taken by the guide's rail (guide_rail = true)" if drive.guide_rail and any(
        f > 0 for f in left.values()) else "cancelled on the groove's flanks"
    rows.append(("sideways balance", f"Σ ± n F_N cos α left over: {sideways}; {taken}"))
    return rows
