"""``passmd figure``: one paper figure's data (CSV) and image (PNG), as the book makes them."""

from __future__ import annotations

import re
import sys
import textwrap
from pathlib import Path

from passmd.cli.configuration import run_config
from passmd.cli.errors import NotAvailableError, OutputError, UsageError
from passmd.cli.options import DirectoryPath, add_sweep_options
from passmd.cli.output import JSON_HELP, emit_json
from passmd.cli.result_bounds import check_table
from passmd.cli.streams import PipeClosed, check_outputs, write_atomically
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


def _check_out(args, config) -> None:
    """--out: a directory (or one to create); NAME.csv and NAME.png neither the sweep log nor
    the file standard output goes to (blank names are refused by the parser)."""
    if Path(args.out).exists() and not Path(args.out).is_dir():
        raise OutputError(f"cannot write to --out {args.out}: it is not a directory")
    target = Path(args.out)
    check_outputs({f"{target / name} (--out {args.out})": target / name
                   for name in (f"{args.name}.csv", f"{args.name}.png")}
                  | {f"{ENVIRONMENT['sweep_log']} {config.sweep_log}": config.sweep_log})


def _write(figure_table, provenance, args, data) -> tuple[Path, Path]:
    """NAME.csv (with the provenance header) and NAME.png in --out, each written atomically."""
    target = Path(args.out)
    csv_path, png_path = target / f"{args.name}.csv", target / f"{args.name}.png"
    try:
        target.mkdir(parents=True, exist_ok=True)

        def write_csv(tmp):  # '#' lines: version, commit, profile
            with open(tmp, "w", encoding="utf-8", newline="") as fh:
                fh.write(provenance.csv_header(args.profile))
                data.to_csv(fh, index=False, lineterminator="\n")

        write_atomically(csv_path, write_csv)
        fig = figure_table.figure_plot(args.name, data)
        write_atomically(png_path, lambda tmp: fig.savefig(
            tmp, dpi=150, format="png", metadata={"Description": provenance.summary(args.profile)}))
    except BrokenPipeError as exc:  # (--out /dev/fd: a reader that went away)
        raise PipeClosed() from exc
    except OSError as exc:
        raise OutputError(f"cannot write to --out {args.out}: {exc.strerror or exc}") from exc
    pyplot = sys.modules.get("matplotlib.pyplot")
    if pyplot is not None:
        pyplot.close(fig)
    return csv_path, png_path


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
