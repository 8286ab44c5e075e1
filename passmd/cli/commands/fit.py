"""``passmd fit``: the drive parameters that make the simulator reproduce a file of measurements."""

from __future__ import annotations

import json
import sys
import textwrap
import time
from pathlib import Path

from passmd.cli.drive import build_drive
from passmd.cli.errors import OutputError, UsageError
from passmd.cli.options import (
    DRIVE_QUANTITIES,
    DirectoryPath,
    add_drive_options,
    add_sweep_options,
    refuse_bare,
)
from passmd.cli.output import JSON_HELP, check_results, describe, drive_record, emit_json, emit_rows, plain
from passmd.runtime.units import from_si, parse_quantity

__all__ = ["FREE_NAMES", "add_parser", "run_fit"]

_EPILOG = textwrap.dedent("""\
    DATA.csv: one measurement a row; column names carry their units. Conditions:
    amplitude_nm, preload_N, frequency_Hz, radius_mm (preload and radius default to the
    drive's; a critical amplitude's frequency to 100 Hz). Measured, one per row: step_nm,
    velocity_mm_per_s, critical_amplitude_nm, force_N, position_nm, each with an optional <column>_sd
    (given for every row or for none; without it each row weighs one unit of its column
    and the residual scale is estimated).

    The fit: a Sobol global pass over the bounds, then bounded weighted least squares in
    log-parameter space (passmd.protocols.fit), every model evaluation a cached parallel
    sweep; a parameter whose response oscillates on the Jacobian's scale is scanned first. Each
    estimate comes with its standard error (Jacobian), a 95 % profile-likelihood interval and an
    identifiability verdict (flat profile, or a correlation beyond ±0.95); a fit whose profiles meet a
    lower cost than its estimate is reported as not converged, with no intervals claimed.

    --out DIR writes fit.json (the --json report), fit.png (data against the fitted model,
    with residuals) and fitted-drive.toml (the fitted drive, for --drive).

    --json keys (SI units): estimates{name: value, stderr, interval[low, high], unit, ...},
    residuals[...], correlation{parameters, matrix, limit}, identifiable, converged, verdict, cost,
    residual_scale, degrees_of_freedom, drive{...}, wall_time_s""")

#: Free parameters as --free names them: the drive option without its dashes, or a derived one;
#: each with its library name and the unit its --bounds and human output use.
FREE_NAMES: dict[str, tuple[str, str]] = {
    **{q.flag[2:]: (q.field, q.unit) for q in DRIVE_QUANTITIES
       if q.field in ("friction_coefficient", "actuator.stiffness", "actuator.mass", "actuator.viscosity",
                      "runner_mass", "amplifier.slew_rate")},
    "damping-ratio": ("actuator.damping_ratio", ""),
    "flyback-time": ("flyback_time", "us"),
    "contact-stiffness-scale": ("contact_stiffness_scale", ""),
}
_OUTPUTS = ("fit.json", "fit.png", "fitted-drive.toml")


def add_parser(command) -> None:
    p = command("fit", "fit unknown drive parameters to measurements, with uncertainties", _EPILOG)
    p.add_argument("data", metavar="DATA.csv", help="the measurements (see below)")
    group = p.add_argument_group("fit")
    group.add_argument("--free", required=True, metavar="NAME[,NAME...]",
                       help="parameters to fit (default: none; required): " + ", ".join(FREE_NAMES))
    group.add_argument("--bounds", action="append", default=[], metavar="NAME=LOW..HIGH",
                       help="range of a free parameter, with a unit (a bare number is SI, refused where the "
                            "parameter is shown in another unit) (default: the plausible range)")
    group.add_argument("--reading", choices=("steady", "first"), default="steady",
                       help="how the simulator reads a critical amplitude (default: steady)")
    group.add_argument("--loss", choices=("linear", "soft_l1", "huber", "cauchy", "arctan"), default="linear",
                       help="robust loss of the estimate; intervals use least squares (default: linear)")
    group.add_argument("--starts", type=int, default=16, metavar="N",
                       help="points of the global pass, a power of two, 0 for none (default: 16)")
    add_drive_options(p)
    add_sweep_options(p)
    out = p.add_argument_group("output")
    out.add_argument("--json", action="store_true", help=JSON_HELP)
    out.add_argument("--out", metavar="DIR", action=DirectoryPath,
                     help="write " + ", ".join(_OUTPUTS) + " to DIR (created if missing; never replaces "
                          "a file) (default: none)")
    p.set_defaults(handler=run_fit)


def _free(args) -> list[str]:
    names = [n.strip() for n in args.free.split(",")]
    for name in names:
        if name not in FREE_NAMES:
            raise UsageError(f"--free = {name!r} is not allowed: must be one of " + ", ".join(FREE_NAMES))
    if len(set(names)) != len(names):
        raise UsageError(f"--free = {args.free!r} names a parameter twice")
    return names


def _bounds(args, names) -> dict[str, tuple[float, float]]:
    out = {}
    for text in args.bounds:
        name, sep, span = text.partition("=")
        low, dots, high = span.partition("..")
        name = name.strip()
        if not sep or not dots:
            raise UsageError(f"--bounds = {text!r} is not NAME=LOW..HIGH")
        if name not in names:
            raise UsageError(f"--bounds = {text!r} names {name!r}, which is not in --free "
                             f"({', '.join(names)})")
        unit = FREE_NAMES[name][1]
        for v in (low, high):
            refuse_bare(f"--bounds {name}", v, unit)
        lo, hi = (parse_quantity(v.strip(), unit, name=f"--bounds {name}") for v in (low, high))
        if not 0 < lo < hi:
            raise UsageError(f"--bounds = {text!r} is out of range: must be 0 < LOW < HIGH")
        out[FREE_NAMES[name][0]] = (lo, hi)
    return out


def _progress(config):
    if config.progress is False:
        return None
    start = time.perf_counter()
    return lambda line: sys.stderr.write(f"passmd fit: {line} [{time.perf_counter() - start:.0f} s]\n")


def _check_out(args) -> Path | None:
    if args.out is None:
        return None
    target = Path(args.out)
    if target.exists() and not target.is_dir():
        raise UsageError(f"--out = {args.out!r} is not a directory")
    if not target.exists() and not target.parent.is_dir():
        raise OutputError(f"cannot write --out {args.out}: directory {str(target.parent)!r} does not exist")
    for name in _OUTPUTS:
        if (target / name).exists():
            raise UsageError(f"--out {args.out}: {name} is already there; choose another directory "
                             "(a fit keeps every file it did not create)")
    return target


def _write(target: Path, result, record: dict, text: str) -> None:
    from passmd.cli.streams import write_atomically
    from passmd.plots.fit import fit_figure

    fig = fit_figure(result)  # before any file is written: a failing figure leaves none
    try:
        target.mkdir(exist_ok=True)
        write_atomically(target / "fit.json",
                         lambda tmp: Path(tmp).write_text(json.dumps(plain(record), indent=2) + "\n"))
        write_atomically(target / "fit.png", lambda tmp: fig.savefig(tmp, dpi=150, format="png"))
        write_atomically(target / "fitted-drive.toml", lambda tmp: Path(tmp).write_text(text))
    except OSError as exc:
        raise OutputError(f"cannot write --out {target}: {exc.strerror or exc}") from exc


def run_fit(args, out) -> int:
    from passmd.cli.configuration import execution_config
    from passmd.protocols import fit as fitting

    names = _free(args)
    bounds = _bounds(args, names)
    drive = build_drive(args)
    target = _check_out(args)
    if args.starts < 0 or (args.starts & (args.starts - 1)):
        raise UsageError(f"--starts = {args.starts} is out of range: must be 0 or a power of two")
    try:
        data = fitting.read_measurements(args.data)
    except FileNotFoundError:
        raise UsageError(f"DATA.csv = {args.data!r}: no such file") from None
    except fitting.MeasurementError as exc:
        raise UsageError(str(exc)) from None
    except IsADirectoryError:
        raise UsageError(f"DATA.csv = {args.data!r} is a directory") from None
    config = execution_config(args)
    library = {FREE_NAMES[n][0]: n for n in names}
    try:
        result = fitting.fit(drive, data, list(library), bounds=bounds, reading=args.reading, loss=args.loss,
                             starts=args.starts, config=config, progress=_progress(config))
    except fitting.InputError as exc:
        if exc.name in ("free", "bounds", "data"):
            raise UsageError(str(exc).replace("free = ", "--free: ")) from None
        raise
    text = fitting.fitted_drive_file(result.drive, Path(args.data).name, list(library))
    record = {"command": "fit", **result.report(), "drive": drive_record(result.drive)}
    check_results(record)
    if target is not None:
        _write(target, result, record, text)
    if args.json:
        emit_json(record, out)
        return 0
    rows = []
    for lib, name in library.items():
        est = result.estimates[lib]
        unit = FREE_NAMES[name][1]
        low, high = (from_si(v, unit) for v in est["interval"])
        rows.append((name, f"{from_si(est['value'], unit):.5g} ± {from_si(est['stderr'], unit):.2g} {unit}  "
                           f"(95 % profile interval {low:.5g}–{high:.5g})".replace("  (", " (")))
    rows.append(("fit", f"{len(data)} measurements, cost {result.cost:.4g}, {result.dof} degrees of freedom, "
                        f"{result.simulations} simulations, {result.wall_time_s:.1f} s"))
    rows.append(("verdict", result.verdict))
    if target is not None:
        rows.append(("written", ", ".join(str(target / n) for n in _OUTPUTS)))
    emit_rows(f"passmd fit — {describe(result.drive)}", rows, out)
    return 0
