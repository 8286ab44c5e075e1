"""``passmd drive``: a drive file of the paper's drive, and what a drive resolves to."""

from __future__ import annotations

import textwrap

from passmd.cli.drive import resolve_drive
from passmd.cli.options import add_drive_options
from passmd.cli.output import JSON_HELP, describe, drive_record, emit_json, emit_rows, fmt

__all__ = ["add_parser", "run_show", "run_template"]

_EPILOG = textwrap.dedent("""\
    template: prints a commented drive file (TOML) of the paper's drive, every parameter
    with its unit and source: passmd drive template > mydrive.toml
    show: every parameter of the drive (--drive FILE and the options) with its unit and
    where it came from: given in the file, an option, or the paper (Table 1, Table 2 for
    the radius, interpolated between its rows; the viscosity derived from ζ).
    A drive file's bare numbers are SI; a string may carry a unit ("0.5 mm").

    show --json keys: parameters [{key, value, unit (SI), symbol, meaning, source}], drive{...}""")


def add_parser(command) -> None:
    p = command("drive", "write a drive file, or show what a drive resolves to", _EPILOG)
    sub = p.add_subparsers(dest="action", metavar="ACTION", required=True)
    template = sub.add_parser("template", help="print a drive file of the paper's drive (TOML)",
                              description="print a commented drive file of the paper's drive (TOML)")
    template.set_defaults(handler=run_template)
    show = sub.add_parser("show", help="every parameter of a drive, its unit and where it came from",
                          description="every parameter of a drive, its unit and where it came from")
    add_drive_options(show)
    show.add_argument("--json", action="store_true", help=JSON_HELP)
    show.set_defaults(handler=run_show)


def run_template(args, out) -> int:
    from passmd.model.drive_file import drive_toml, resolve

    drive, sources = resolve({})
    sources = {key: text[len("default ("):-1] if text.startswith("default (") else text
               for key, text in sources.items()}
    out.write(drive_toml(drive, sources, title="passmd drive file: the paper's drive (R = 1 mm, F_p = 0.4 N, "
                                                "μ = 0.2, six contacts, flexible actuators)"))
    return 0


def _shown(row: dict) -> str:
    value, unit = row["value"], row["display_unit"]
    if isinstance(value, list):  # contact groups
        return "; ".join(", ".join(f"{k} = {v:g}" for k, v in group.items()) for group in value) or "–"
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
        emit_json({"command": "drive show", "parameters": [
            {k: row[k] for k in ("key", "value", "unit", "symbol", "meaning", "source")} for row in rows],
            "drive": drive_record(drive)}, out)
        return 0
    shown = [(f"{row['key']} ({row['symbol']})", f"{_shown(row)}   [{row['source']}]") for row in rows]
    emit_rows(f"passmd drive show — {describe(drive)}", shown, out)
    return 0
