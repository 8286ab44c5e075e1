"""``passmd figure``: one paper figure's data (CSV) and image (PNG), as the book makes them."""

from __future__ import annotations

import contextlib
import re
import sys
import textwrap
from pathlib import Path

from passmd.cli.configuration import run_config
from passmd.cli.errors import NotAvailableError, OutputError, UsageError
from passmd.cli.options import DirectoryPath, add_overwrite_option, add_sweep_options
from passmd.cli.output import JSON_HELP, emit_json
from passmd.cli.result_bounds import check_table
from passmd.cli.streams import check_new_outputs, check_outputs, create_outputs
from passmd.runtime.cache import describe_default_cache_dir
from passmd.runtime.config import ENVIRONMENT, PROFILES

__all__ = ["NOT_AVAILABLE", "add_parser", "run_figure"]

NOT_AVAILABLE = "not available yet"

_EPILOG = textwrap.dedent(f"""\
    'passmd figure list' lists the panels; any other name is refused. Sweeps are
    cached in ${ENVIRONMENT['cache_dir']}, else {describe_default_cache_dir()};
    see 'passmd cache --help'.

    NAME.csv starts with '#' lines naming the passmd version, git commit and profile
    (read it with pandas.read_csv(path, comment="#")); NAME.png carries the same in
    its Description metadata.

    --json keys: name, profile, rows, columns, csv, png (paths written)""")


def add_parser(command) -> None:
    p = command("figure", "one paper figure's data (CSV) and image (PNG), as the book makes them", _EPILOG)
    p.add_argument("name", metavar="NAME",
                   help="figure panel, e.g. fig5a, or 'list' (default: none, required)")
    p.add_argument("--profile", choices=PROFILES, default="paper",
                   help="resolution: quick (CI) or paper (the paper's grids) (default: paper)")
    p.add_argument("--out", metavar="DIR", default=".", action=DirectoryPath,
                   help="directory for NAME.csv and NAME.png (default: .)")
    add_overwrite_option(p)
    add_sweep_options(p)
    p.add_argument("--json", action="store_true", help=JSON_HELP)
    p.set_defaults(handler=run_figure)


def _list(figure_table, names, args, out) -> int:
    if args.json:
        emit_json({"command": "figure", "figures": names}, out)
    else:
        for name in names:
            out.write(f"{name}  {figure_table.figure_spec(name).title}\n")
        if not names:
            out.write("no figure is available\n")
    return 0


def _check_name(args, names) -> None:
    if not re.fullmatch(r"[a-z0-9_]+", args.name):
        raise UsageError(f"figure {args.name!r} is not a figure name: a panel such as fig5a, or 'list' "
                         f"(available: {', '.join(names)})")
    if args.name not in names:
        known = ", ".join(names) if names else "none"
        raise NotAvailableError(f"figure {args.name!r} is {NOT_AVAILABLE} (available: {known})")


def _files(args) -> dict[Path, str]:
    """NAME.csv and NAME.png in --out: path -> the option as typed."""
    target = Path(args.out)
    return {target / f"{args.name}{suffix}": f"--out {args.out}" for suffix in (".csv", ".png")}


def _check_out(args, config) -> None:
    """--out: a directory (or one to create) files can be created in; NAME.csv and NAME.png neither
    there already (unless --overwrite), nor the sweep log or the file standard output goes to (blank
    names are refused by the parser)."""
    if Path(args.out).exists() and not Path(args.out).is_dir():
        raise OutputError(f"cannot write to --out {args.out}: it is not a directory")
    files = _files(args)
    check_outputs({f"{path} (--out {args.out})": path for path in files}
                  | {f"{ENVIRONMENT['sweep_log']} {config.sweep_log}": config.sweep_log})
    check_new_outputs(files, overwrite=args.overwrite, folder=args.out, parents=True)


def _write(figure_table, provenance, args, data) -> tuple[Path, Path]:
    """NAME.csv (with the provenance header) and NAME.png in --out, written together or not at all,
    never over a file unless --overwrite (:func:`passmd.cli.streams.create_outputs`); the folders the
    command created are removed again if that fails."""
    files = _files(args)
    csv_path, png_path = files
    fig = figure_table.figure_plot(args.name, data)

    def write_csv(tmp):  # '#' lines: version, commit, profile
        with open(tmp, "w", encoding="utf-8", newline="") as fh:
            fh.write(provenance.csv_header(args.profile))
            data.to_csv(fh, index=False, lineterminator="\n")

    created = _make_folders(Path(args.out))
    try:
        create_outputs({csv_path: write_csv, png_path: lambda tmp: fig.savefig(
            tmp, dpi=150, format="png", metadata={"Description": provenance.summary(args.profile)})},
            files, overwrite=args.overwrite)
    except BaseException:
        for folder in reversed(created):
            with contextlib.suppress(OSError):
                folder.rmdir()  # only while empty
        raise
    pyplot = sys.modules.get("matplotlib.pyplot")
    if pyplot is not None:
        pyplot.close(fig)
    return csv_path, png_path


def _make_folders(folder: Path) -> list[Path]:
    """Create ``folder`` and its missing parents; the ones created, outermost first."""
    missing = [p for p in (folder, *folder.parents) if not p.exists()][::-1]
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot write to --out {folder}: {exc.strerror or exc}") from exc
    return missing


def run_figure(args, out) -> int:
    from passmd.experiments import figure_table
    from passmd.runtime import provenance

    names = figure_table.figure_names()
    if args.name == "list":
        return _list(figure_table, names, args, out)
    _check_name(args, names)
    config = run_config(args)
    _check_out(args, config)
    data = figure_table.figure_data(args.name, config)
    check_table(args.name, data)  # finite before anything is written, as run and theory check theirs
    csv_path, png_path = _write(figure_table, provenance, args, data)
    record = {"command": "figure", "name": args.name, "profile": args.profile, "rows": len(data),
              "columns": list(map(str, data.columns)), "csv": str(csv_path), "png": str(png_path)}
    if args.json:
        emit_json(record, out)
    else:
        out.write(f"{args.name} ({args.profile}): {len(data)} rows -> {csv_path}, {png_path}\n")
    return 0
