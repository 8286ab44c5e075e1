"""``passmd fit``: the drive parameters that make the simulator reproduce a file of measurements."""

from __future__ import annotations

import contextlib
import json
import sys
import textwrap
import time
from pathlib import Path

from passmd.cli.drive import resolve_drive
from passmd.cli.errors import OutputError, UsageError
from passmd.cli.options import (
    DRIVE_QUANTITIES,
    DirectoryPath,
    add_drive_options,
    add_overwrite_option,
    add_sweep_options,
)
from passmd.cli.output import (
    JSON_HELP,
    check_results,
    describe,
    drive_record,
    emit_json,
    emit_rows,
    flyback_label,
    fmt,
    plain,
)
from passmd.cli.streams import check_new_outputs, create_outputs
from passmd.protocols.fit.free_parameters import FREE_PARAMETERS
from passmd.runtime.units import from_si, parse_quantity

__all__ = ["FREE_NAMES", "add_parser", "run_fit"]

_EPILOG = textwrap.dedent("""\
    DATA.csv: one measurement a row; column names carry their units. Conditions:
    amplitude_nm, preload_N, frequency_Hz, radius_mm (preload and radius default to the
    drive's; a critical amplitude's frequency to 100 Hz). Measured, one per row: step_nm
    (the settled step of a running drive: below 1 kHz the step once a period's end state
    repeats the last one's, moved on by the step, to 0.002 nm; above it the steady-velocity
    protocol's velocity / f),
    velocity_mm_per_s (the same × f), critical_amplitude_nm, force_N, position_nm (the
    position after three periods from rest, Fig. 9a: a measurement of a start, not of a
    running drive), each with an optional <column>_sd (given for every row or for none;
    without it each row weighs one unit of its column and the residual scale is estimated).
    Every row is checked against the drive (stroke, fly-back within half a period, preload
    and radius ranges) before anything is simulated.

    The fit (passmd.protocols.fit): a Sobol global pass of 64 points per free parameter over
    the bounds, local least-squares searches in log-parameter space, then each parameter's
    profile over its whole bounds (a comb of minima, as the step of flexible actuators has
    in k_p, is sampled at 1 %). The estimate is the lowest point found. Each parameter's
    95 % region is every value whose profile lies within the 95 % chi-square quantile (as
    many degrees of freedom as free parameters) of the minimum, the projection of the joint
    95 % region: one interval, or several pieces when the data allow several basins (then the
    one added measurement that separates them best is computed). With stated sd the
    minimum is tested against chi-square with n - p degrees of freedom; below p = 0.01 the
    model does not describe the data and no interval is called calibrated.
    While k_p or m_a moves the damping ratio stays fixed, or c_p when the drive gives c_p.

    --out DIR writes fit.json (the --json report), fit.png (data against the fitted model,
    with residuals) and fitted-drive.toml (the fitted drive, every value with its source,
    for --drive).

    --json keys (SI units): estimates{name: value, stderr, interval[low, high] (the hull),
    intervals[[low, high], ...], basins[{value, cost}], profile{value, cost}, unit, ...},
    goodness_of_fit{chi2, dof, p_value, testable, rejected}, identifiable, model_rejected,
    basins[...], next_measurement, residuals[...], correlation{parameters, matrix, limit},
    converged, verdict, cost, residual_scale, degrees_of_freedom, flyback, keep, drive{...},
    wall_time_s""")

#: Free parameters (:data:`passmd.protocols.fit.FREE_PARAMETERS`) as --free names them: the drive
#: option without its dashes, or the library name's last part with dashes; each with its library
#: name (which --free takes too, as drive show and the drive file name it) and the unit its
#: --bounds and human output use (the option's, else the SI unit, µs for a time).
_OPTION_OF = {q.field: (q.flag[2:], q.unit) for q in DRIVE_QUANTITIES}
FREE_NAMES: dict[str, tuple[str, str]] = {
    option: (lib, unit)
    for lib, free in FREE_PARAMETERS.items()
    for option, unit in [_OPTION_OF.get(lib, (lib.rpartition(".")[2].replace("_", "-"),
                                              "us" if free.unit == "s" else free.unit))]
}
#: Every name --free and --bounds take: the option names above and the library's (drive-file) names.
_ALIASES = {**{lib: name for name, (lib, _) in FREE_NAMES.items()}, **{name: name for name in FREE_NAMES}}
_OUTPUTS = ("fit.json", "fit.png", "fitted-drive.toml")


def add_parser(command) -> None:
    p = command("fit", "fit unknown drive parameters to measurements, with uncertainties", _EPILOG)
    p.add_argument("data", metavar="DATA.csv", help="the measurements (see below)")
    group = p.add_argument_group("fit")
    group.add_argument("--free", required=True, metavar="NAME[,NAME...]",
                       help="parameters to fit, by option or drive-file name (default: none; required): "
                            + ", ".join(f"{name} ({lib})" for name, (lib, _) in FREE_NAMES.items()))
    group.add_argument("--bounds", action="append", default=[], metavar="NAME=LOW..HIGH",
                       help="range of a free parameter, with a unit (a bare number is SI, refused where the "
                            "parameter is shown in another unit) (default: the plausible range)")
    group.add_argument("--reading", choices=("steady", "first"), default="steady",
                       help="how the simulator reads a critical amplitude (default: steady)")
    group.add_argument("--loss", choices=("linear", "soft_l1", "huber", "cauchy", "arctan"), default="linear",
                       help="robust loss of the estimate; intervals use least squares (default: linear)")
    add_drive_options(p)
    add_sweep_options(p)
    out = p.add_argument_group("output")
    out.add_argument("--json", action="store_true", help=JSON_HELP)
    out.add_argument("--out", metavar="DIR", action=DirectoryPath,
                     help="write " + ", ".join(_OUTPUTS) + " to DIR (created if missing; never replaces "
                          "a file unless --overwrite) (default: none)")
    add_overwrite_option(out)
    p.set_defaults(handler=run_fit)


def _free(args) -> list[str]:
    """The --free names as option names (a drive-file name is read as its option)."""
    names = []
    for text in args.free.split(","):
        name = text.strip()
        if name not in _ALIASES:
            raise UsageError(f"--free = {name!r} is not allowed: must be one of "
                             + ", ".join(f"{n} ({lib})" for n, (lib, _) in FREE_NAMES.items()))
        names.append(_ALIASES[name])
    if len(set(names)) != len(names):
        raise UsageError(f"--free = {args.free!r} names a parameter twice")
    return names


def _bounds(args, names, drive) -> dict[str, tuple[float, float]]:
    """--bounds as typed: each free parameter once, 0 < LOW < HIGH, within its plausible range unless
    --allow-extrapolation (or the drive file's allow_extrapolation) lifts it."""
    from passmd.protocols.fit.free_parameters import plausible_bounds

    out, typed = {}, {}
    for text in args.bounds:
        name, sep, span = text.partition("=")
        low, dots, high = span.partition("..")
        name = _ALIASES.get(name.strip(), name.strip())
        if not sep or not dots:
            raise UsageError(f"--bounds = {text!r} is not NAME=LOW..HIGH")
        if name not in names:
            raise UsageError(f"--bounds = {text!r} names {name!r}, which is not in --free "
                             f"({', '.join(names)})")
        if name in typed:
            raise UsageError(f"--bounds = {text!r} bounds {name} again (--bounds {typed[name]!r}): give each "
                             "parameter's bounds once")
        typed[name] = text
        unit = FREE_NAMES[name][1]
        lo, hi = (parse_quantity(v.strip(), unit, name=f"--bounds {name}") for v in (low, high))
        if not 0 < lo < hi:
            raise UsageError(f"--bounds = {text!r} is out of range: must be 0 < LOW < HIGH")
        lib = FREE_NAMES[name][0]
        low_ok, high_ok = plausible_bounds(drive, lib)
        if not (args.allow_extrapolation or drive.allow_extrapolation) and (lo < low_ok or hi > high_ok):
            shown = f" {unit}" if unit else ""
            raise UsageError(f"--bounds = {text!r} is out of range: must be within "
                             f"{from_si(low_ok, unit):.4g}..{from_si(high_ok, unit):.4g}{shown}, the "
                             f"plausible range of {name} (a search far outside it simulates drives the model "
                             "was not checked for, and may never end); --allow-extrapolation goes beyond it")
        out[lib] = (lo, hi)
    return out


def _progress(config):
    if config.progress is False:
        return None
    start = time.perf_counter()
    return lambda line: sys.stderr.write(f"passmd fit: {line} [{time.perf_counter() - start:.0f} s]\n")


def _check_out(args) -> Path | None:
    """--out before any work: a directory (or one to create in an existing one) that files can be
    created in, none of the outputs there yet unless --overwrite (exit 2 naming the file)."""
    if args.out is None:
        return None
    target = Path(args.out)
    if target.exists() and not target.is_dir():
        raise UsageError(f"--out = {args.out!r} is not a directory")
    check_new_outputs(_named(target), overwrite=args.overwrite, folder=target)
    return target


def _named(target: Path) -> dict[Path, str]:
    """fit.json, fit.png and fitted-drive.toml in --out: path -> the option as typed."""
    return {target / name: f"--out {target}" for name in _OUTPUTS}


def _write(target: Path, result, record: dict, text: str, overwrite: bool) -> None:
    """fit.json, fit.png and fitted-drive.toml written together or not at all, never over a file
    unless ``overwrite`` (:func:`passmd.cli.streams.create_outputs`); a folder the fit created is
    removed on failure."""
    from passmd.plots.fit import fit_figure

    fig = fit_figure(result.residual_table())  # before any file is written: a failing figure leaves none
    option = f"--out {target}"
    try:
        target.mkdir()
        created = True
    except FileExistsError:
        created = False
    except OSError as exc:
        raise OutputError(f"cannot create the directory {target} ({option}): {exc.strerror or exc}") from None
    try:
        create_outputs({
            target / "fit.json": lambda tmp: Path(tmp).write_text(json.dumps(plain(record), indent=2) + "\n"),
            target / "fit.png": lambda tmp: fig.savefig(tmp, dpi=150, format="png"),
            target / "fitted-drive.toml": lambda tmp: Path(tmp).write_text(text, encoding="utf-8"),
        }, _named(target), overwrite=overwrite)
    except BaseException:
        if created:
            with contextlib.suppress(OSError):
                target.rmdir()  # only while empty: another run's files keep it
        raise


def run_fit(args, out) -> int:
    from passmd.cli.configuration import run_config
    from passmd.protocols import fit

    names = _free(args)
    drive, sources = resolve_drive(args)
    bounds = _bounds(args, names, drive)
    target = _check_out(args)
    config = run_config(args)  # the sweep log too, before any work
    try:
        data = fit.read_measurements(args.data)
    except FileNotFoundError:
        raise UsageError(f"DATA.csv = {args.data!r}: no such file") from None
    except fit.MeasurementError as exc:
        raise UsageError(str(exc)) from None
    except IsADirectoryError:
        raise UsageError(f"DATA.csv = {args.data!r} is a directory") from None
    except OSError as exc:  # unreadable: bad input, as an unreadable drive file
        raise UsageError(f"DATA.csv = {args.data!r} cannot be read: {exc.strerror or exc}") from None
    library = {FREE_NAMES[n][0]: n for n in names}
    # c_p stays fixed while k_p or m_a moves only when the user gave c_p (drive show: "given"/"option")
    given_cp = sources.get("actuator.viscosity", "").startswith(("given", "option"))
    try:
        result = fit.fit(drive, data, list(library), bounds=bounds, reading=args.reading, loss=args.loss,
                             keep="viscosity" if given_cp else "damping_ratio", config=config,
                             progress=_progress(config))
    except fit.MeasurementError as exc:  # a row the drive cannot run: refused before any simulation
        raise UsageError(str(exc)) from None
    except fit.InputError as exc:
        if exc.name in ("free", "bounds", "data"):
            raise UsageError(str(exc).replace("free = ", "--free: ")) from None
        raise
    text = fit.fitted_drive_file(result, Path(args.data).name, sources)
    record = {"command": "fit", **result.report(), "drive": drive_record(result.drive)}
    check_results(record)
    if target is not None:
        _write(target, result, record, text, args.overwrite)
    if args.json:
        emit_json(record, out)
        return 0
    emit_rows(f"passmd fit — {describe(result.drive)}", _rows(result, library, data, target), out)
    return 0


def _flyback(result, library: dict[str, str]) -> str:
    """The fly-back rule, and the full-stroke time V_pp/SR when the fit set it (its slew rate free)."""
    rule = flyback_label(result.drive.amplifier.flyback)
    if {"flyback_time", "amplifier.slew_rate"} & set(library):
        time = fmt(result.drive.amplifier.full_stroke_time, "us")
        return f"{rule} with the fitted full-stroke time V_pp/SR = {time}"
    return rule


def _rows(result, library: dict[str, str], data, target) -> list[tuple[str, str]]:
    """The human report: each estimate with its 95 % region, the goodness of fit, the verdict."""
    rows = []
    for lib, name in library.items():
        est = result.estimates[lib]
        unit = FREE_NAMES[name][1]
        shown = f" {unit}" if unit else ""
        region = ", ".join(f"{from_si(a, unit):.5g}–{from_si(b, unit):.5g}" for a, b in est["intervals"])
        pieces = len(est["intervals"])
        rows.append((name, f"{from_si(est['value'], unit):.5g}{shown} (local standard error "
                           f"{from_si(est['stderr'], unit):.2g}); 95 % region {region}{shown}"
                           + (f" ({pieces} pieces, {len(est['basins'])} basins)" if pieces > 1 else "")))
    gof = result.goodness_of_fit
    test = (f"χ² = {gof['chi2']:.4g} on {gof['dof']} degrees of freedom, p = {gof['p_value']:.3g}"
            + (" (the model does not describe the data)" if gof["rejected"] else "")
            if gof["testable"] else "no sd given: residual scale estimated, no test possible")
    rows.append(("goodness of fit", test))
    rows.append(("fit", f"{len(data)} measurements, {result.dof} degrees of freedom, fly-back "
                        f"{_flyback(result, library)}, {result.simulations} simulations, "
                        f"{result.wall_time_s:.1f} s"))
    rows.append(("verdict", result.verdict))
    rows += [("note", note) for note in result.notes]
    if target is not None:
        rows.append(("written", ", ".join(str(target / n) for n in _OUTPUTS)))
    return rows
