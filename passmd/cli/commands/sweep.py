"""``passmd sweep``: one quantity over a grid of drive and waveform parameters (a curve or a map)."""

from __future__ import annotations

import argparse
import itertools
import json
import math
import re
import textwrap
from dataclasses import dataclass
from decimal import Decimal, localcontext

import numpy as np

from passmd.cli import sweep_files
from passmd.cli.configuration import run_config
from passmd.cli.drive import _bound, build_drive, explain
from passmd.cli.errors import UsageError
from passmd.cli.notes import (
    eq15_rows,
    missing_rows,
    resolution,
    sweep_figure,
    sweep_title,
    turn_rows,
    uses_eq15,
)
from passmd.cli.options import (
    AMPLITUDE,
    DRIVE_QUANTITIES,
    FREQUENCY,
    FilePath,
    Quantity,
    add_drive_options,
    add_overwrite_option,
    add_sweep_options,
)
from passmd.cli.output import JSON_HELP, describe, drive_record, emit_json, emit_rows, fmt
from passmd.cli.sweep_rows import (
    add_band,
    check_values,
    curve_rows,
    derived_columns,
    diagnose_sweep,
    extreme_rows,
    sweep_diagnosis_rows,
    warnings_of,
)
from passmd.model.defaults import PROTOCOL
from passmd.runtime.config import ENVIRONMENT
from passmd.runtime.units import QuantityError, from_si, parse_quantity
from passmd.runtime.validation import InputError

__all__ = ["AXES", "MAX_AXIS_POINTS", "MAX_POINTS", "Axis", "add_parser", "grid_values", "parse_vary",
           "run_sweep"]

#: The quantities (passmd.protocols.maps.MAP_QUANTITIES; listed here so --help does not import it).
QUANTITY_NAMES = ("velocity", "step", "back-step", "critical-amplitude", "stall-force", "gain")
#: SI unit of each display unit: a bare number in --vary is SI.
_SI = {"nm": "m", "mm": "m", "g": "kg", "kHz": "Hz", "GPa": "Pa", "V/us": "V/s", "N": "N", "N/m": "N/m",
       "kg/s": "kg/s", "V": "V", "": ""}
#: What --vary may vary: the waveform's amplitude and frequency and every drive option, by name.
AXES: dict[str, Quantity] = {"amplitude": AMPLITUDE, "frequency": FREQUENCY,
                             **{q.flag.lstrip("-"): q for q in DRIVE_QUANTITIES}}
#: Most values of one axis and most points of a map.
MAX_AXIS_POINTS = 1000
MAX_POINTS = 100_000
#: Longest curve the human output lists in full (longer ones and maps: the extremes).
MAX_SHOWN = 40
#: passmd.protocols.velocity.STEADY_DRIFT_LIMIT in percent (said here so --help does not import it;
#: tests/test_cli_sweep.py checks they agree).
STEADY_DRIFT_PERCENT = 5

_NAMES = "NAME: " + ", ".join(AXES) + "."
_EPILOG = textwrap.dedent("""\
    QUANTITY is one of:

    - velocity, step, back-step: the steady-velocity protocol of Section 5.2's velocity chapter:
      max(20, f·5 ms) periods from rest, the slope of the period-mean position over the second
      half; step = velocity/f
    - critical-amplitude: simulated A_c, --reading steady (last step of a saw-tooth run exceeds
      0.5 nm: what continuous operation needs) or first (every contact slides in the first
      fly-back: what moves the drive once); the closed form (Eqs. 7-8, 11-12) is reported too
    - stall-force: generated force at stall against the load cell (Section 4.2)
    - gain: steady velocity of the Eq. 15 waveform (designed from this drive's saw-tooth
      response, --design-response) minus that of the saw-tooth. Eq. 15's period needs t_s + t_a,
      the fly-back and a slow ramp: above the highest frequency at which it fits (the column
      eq15_highest_frequency_Hz) a cell has no value and its note says so, as where Eq. 15 gives
      no waveform at all; so does velocity --waveform optimized

    --vary NAME=SPEC, repeated for a map (the first axis is the x axis, the last runs fastest):

    - NAME=LO..HI[:log][:N]: N values from LO to HI, linear (default) or log, N default 10
    - NAME=V1,V2,...: a list; NAME=V: a single value
    - e.g. --vary frequency=100Hz..110kHz:log:24 --vary amplitude=50nm..130nm:24, or
      --vary preload=0.1N,0.4N,1N --vary mu=0.1..0.3:5

    A bare number in --vary is in SI units (m, kg, N, Hz, Pa, N/m, kg/s, V, V/s).
    """) + textwrap.fill(_NAMES, width=92, break_on_hyphens=False) + textwrap.dedent(f"""

    Not varied: --amplitude (default the full stroke) and --frequency apply to every point.

    Points run in parallel and are cached (--cache-dir, else ${ENVIRONMENT['cache_dir']}, else the user
    cache folder; see 'passmd cache --help'): Ctrl-C keeps every finished point, and a rerun, or a
    map sharing points with an earlier one, computes only the missing points.

    --out PREFIX writes PREFIX.csv ('#' lines: passmd version, git commit, options; read
    with pandas.read_csv(path, comment="#")), PREFIX.json (the --json object) and PREFIX.png
    (a curve for one axis, a heat map with contours for two).

    --json keys: command, quantity, column, reading, waveform, design_response, axes[{{name,
    values, unit, spacing, typed}}], drive{{...}}, provenance{{...}}, sweep{{points, cached,
    computed}}, columns, rows[{{...}}] (SI units, keys carrying the unit), files. Among a row's
    columns: velocity_drift (velocity, step, back-step), the velocity of the run's fourth quarter
    minus that of its third, over the velocity: beyond {STEADY_DRIFT_PERCENT} % the point is not
    steady (hatched in the PNG, as are points with no value and points whose magnitude is below the
    measurable step); ringing_* (every quantity but the stall force): the runner's swing after a
    fly-back and what is left of it when the next starts (ringing_at_next_flyback_m);
    running_max_critical_amplitude_m (critical-amplitude over one axis: the amplitude that moves the
    runner at every point up to this one); gain_percent (gain: over the saw-tooth's velocity);
    <column>_band_low, <column>_band_high (a --drive file written by passmd fit: the least and largest
    value over the fit's estimate and the points of its 95 % region the file records; a shaded band
    in a curve's PNG).
    warnings[{{kind, points, of, range, text}}]: each warning once, with the points it covers.

    Over one axis, where a value departs from its trend (a critical amplitude jumping more than 10 %
    off its closed form's scaling, a step or velocity that turns, an Eq. 15 gain below 0), the
    largest three departures are explained by computation: each is simulated again with one
    candidate cause removed at a time (passmd.protocols.diagnosis; cached like the sweep's points)
    and each cause is given with its counterfactual value and its share of the departure; --json:
    diagnoses[{{at, quantity, values, departure, causes[{{cause, counterfactual_value, share, ...}}],
    named}}]. --no-diagnosis skips it.""")


@dataclass(frozen=True)
class Axis:
    """One --vary: the parameter's name, its values (SI), the column they fill, as typed."""

    name: str
    values: tuple[float, ...]
    spacing: str
    typed: str

    @property
    def quantity(self) -> Quantity:
        return AXES[self.name]

    @property
    def si_unit(self) -> str:
        return _SI[self.quantity.unit]

    @property
    def column(self) -> str:
        unit = self.si_unit.replace("/", "_per_")
        return f"{self.name.replace('-', '_')}_{unit}" if unit else self.name.replace("-", "_")


def add_parser(command) -> None:
    p = command("sweep", "one quantity over a grid of drive and waveform parameters: CSV, JSON and a "
                "curve or heat map", _EPILOG)
    p.add_argument("quantity", metavar="QUANTITY", choices=QUANTITY_NAMES,
                   help=f"what to compute: {', '.join(QUANTITY_NAMES)} (default: none, required)")
    p.add_argument("--vary", metavar="NAME=SPEC", action="append", default=[], required=True,
                   help="a parameter and its values (see below); repeat for a map (default: none, required)")
    add_drive_options(p)
    group = p.add_argument_group("waveform and protocol")
    AMPLITUDE.add(group)
    FREQUENCY.add(group)
    group.add_argument("--waveform", choices=("sawtooth", "optimized"), default=None,
                       help="waveform of velocity, step and back-step (default: sawtooth)")
    group.add_argument("--reading", choices=("steady", "first"), default=None,
                       help="reading of critical-amplitude (default: steady)")
    group.add_argument("--design-response", choices=("paper", "driving"), default=None,
                       help="saw-tooth response the Eq. 15 waveform is designed from: paper, the 100 Hz "
                            "response of Section 5.2 (one design per drive and amplitude); driving, the "
                            "response at each point's frequency (default: paper)")
    group.add_argument("--no-diagnosis", action="store_true",
                       help="do not compute the causes of a curve's departures (default: computed)")
    add_sweep_options(p)
    out = p.add_argument_group("output")
    out.add_argument("--color-scale", choices=("auto", "linear", "log"), default="auto",
                     help="a heat map's colour scale: log needs values > 0; auto is log where every value is "
                          "and they span more than two decades (default: auto)")
    out.add_argument("--out", metavar="PREFIX", action=FilePath,
                     help="write PREFIX.csv, PREFIX.json and PREFIX.png (default: none)")
    add_overwrite_option(out)
    out.add_argument("--json", action="store_true", help=JSON_HELP)
    p.set_defaults(handler=run_sweep, profile="paper")


# --------------------------------------------------------------------------------------
# --vary
# --------------------------------------------------------------------------------------

def _refuse(text: str, problem: str) -> UsageError:
    return UsageError(f"--vary = {text!r}: {problem}")


def parse_vary(text: str) -> Axis:
    """One ``--vary NAME=SPEC`` (see the command's epilog): its values in SI, unchecked ranges."""
    name, sep, spec = text.partition("=")
    name = name.strip()
    if not sep or not spec.strip():
        raise _refuse(text, "must be NAME=LO..HI[:log][:N] or NAME=V1,V2,... (e.g. preload=0.1N..1N:5)")
    if name not in AXES:
        raise _refuse(text, f"unknown parameter {name!r}: must be one of {', '.join(AXES)}")
    unit = _SI[AXES[name].unit]

    def value(part: str) -> float:
        try:
            return parse_quantity(part.strip(), unit, name=name)
        except QuantityError as exc:
            raise _refuse(text, str(exc).replace(f"{name} = ", "", 1)) from None

    if ".." not in spec:
        return Axis(name, tuple(value(part) for part in spec.split(",")), "list", text)
    low, _, rest = spec.partition("..")
    high, *options = rest.split(":")
    spacing, count = "linear", 10
    given: dict[str, str] = {}
    for option in options:
        option = option.strip()
        what = "spacing" if option in ("log", "lin", "linear") else "N" if re.fullmatch(r"[0-9]+", option) \
            else None
        if what is not None and what in given:
            raise _refuse(text, f"{what} is given twice ({given[what]!r} and {option!r}): give it once")
        if what is not None:
            given[what] = option
        if option in ("log", "lin", "linear"):
            spacing = "log" if option == "log" else "linear"
        elif re.fullmatch(r"[0-9]+", option):
            count = int(option)
            if not 2 <= count <= MAX_AXIS_POINTS:
                raise _refuse(text, f"N = {count} is out of range: must be an integer from 2 to "
                                    f"{MAX_AXIS_POINTS}")
        else:
            raise _refuse(text, f"{option!r} is not an option of a range: must be 'log', 'lin' or a number "
                                "of values N")
    lo, hi = value(low), value(high)
    if not lo < hi:
        raise _refuse(text, f"the range {low.strip()}..{high.strip()} is empty: LO must be below HI")
    if spacing == "log" and lo <= 0:
        raise _refuse(text, f"a log range must start above 0, not at {low.strip()}")
    return Axis(name, grid_values(lo, hi, count, spacing), spacing, text)


def grid_values(lo: float, hi: float, count: int, spacing: str) -> tuple[float, ...]:
    """``count`` values from ``lo`` to ``hi`` (SI) as a reader writes them: a linear grid in decimal
    (0.1..1:10 gives 0.4, not 0.39999999999999997), a log grid to 12 significant digits; the ends
    exactly as typed. The points are computed at these values, so the CSV holds what ran."""
    if spacing == "log":
        values = [float(f"{v:.12g}") for v in np.geomspace(lo, hi, count)]
    else:
        with localcontext() as ctx:
            ctx.prec = 28
            start, stop = Decimal(repr(lo)), Decimal(repr(hi))
            values = [float(start + (stop - start) * k / (count - 1)) for k in range(count)]
    values[0], values[-1] = lo, hi
    return tuple(values)


def _shown(axis: Axis, value: float) -> str:
    unit = axis.quantity.unit
    return f"{from_si(value, unit):.6g} {unit}".rstrip() if unit else f"{value:.6g}"


def _check_axis_values(axis: Axis, args) -> None:
    """Each value of a drive or frequency axis within the option's range, said in --vary's terms."""
    if axis.name == "amplitude":
        for v in axis.values:
            if not v > 0:
                raise _refuse(axis.typed, f"{_shown(axis, v)} is out of range: must be > 0 nm")
        return
    for v in axis.values:
        probe = argparse.Namespace(**{**vars(args), axis.quantity.dest: f"{v!r} {axis.si_unit}".strip()})
        try:
            axis.quantity.parse(probe)
        except (UsageError, ValueError) as exc:
            reason = str(exc).split(" is ", 1)[-1]
            raise _refuse(axis.typed, f"{_shown(axis, v)} is {reason}") from None


def _check_axes(args, quantity: str) -> list[Axis]:
    axes = [parse_vary(text) for text in args.vary]
    names = [a.name for a in axes]
    for axis in axes:
        if names.count(axis.name) > 1:
            raise UsageError(f"--vary {axis.name} is given {names.count(axis.name)} times: vary each "
                             "parameter once")
        if getattr(args, axis.quantity.dest, None) is not None:
            raise UsageError(f"--vary = {axis.typed!r} contradicts {axis.quantity.flag} "
                             f"{getattr(args, axis.quantity.dest)}: give one of them")
        if axis.name == "amplitude" and quantity == "critical-amplitude":
            raise UsageError(f"--vary = {axis.typed!r}: critical-amplitude searches over the amplitude "
                             "itself; vary a parameter of the drive or the frequency")
        _check_axis_values(axis, args)
    total = math.prod(len(a.values) for a in axes)
    if total > MAX_POINTS:
        raise UsageError(f"--vary: {' × '.join(str(len(a.values)) for a in axes)} = {total} points is out of "
                         f"range: must be at most {MAX_POINTS}")
    return axes


def _check_options(args) -> None:
    if args.reading is not None and args.quantity != "critical-amplitude":
        raise UsageError(f"--reading {args.reading} has no effect on {args.quantity}: it chooses the reading "
                         "of critical-amplitude")
    if args.waveform is not None and args.quantity not in ("velocity", "step", "back-step"):
        raise UsageError(f"--waveform {args.waveform} has no effect on {args.quantity}: it chooses the "
                         "waveform of velocity, step and back-step")
    if args.design_response is not None and not uses_eq15(args):
        raise UsageError(f"--design-response {args.design_response} has no effect on {args.quantity}"
                         f"{' --waveform sawtooth' if args.waveform else ''}: it chooses the response the "
                         "Eq. 15 waveform is designed from (gain, or --waveform optimized)")
    if args.amplitude is not None and args.quantity == "critical-amplitude":
        raise UsageError("--amplitude has no effect on critical-amplitude: it searches over the amplitude")
    if args.out is not None:
        sweep_files.check_prefix(args.out, overwrite=args.overwrite)


# --------------------------------------------------------------------------------------
# The grid
# --------------------------------------------------------------------------------------

def _points(args, axes: list[Axis], with_amplitude: bool, build=build_drive) -> list[dict]:
    """Every point of the grid: its drive (options, each drive axis' value replacing its option;
    ``build`` makes it from them), frequency and amplitude, and the axes' values as columns."""
    drives: dict[tuple, object] = {}
    drive_axes = [a for a in axes if a.name not in ("amplitude", "frequency")]
    fixed_amplitude = AMPLITUDE.parse(args) if with_amplitude else None
    fixed_frequency = FREQUENCY.parse_or(args, PROTOCOL.drive_frequency)
    points = []
    for combo in itertools.product(*(a.values for a in axes)):
        at = dict(zip((a.name for a in axes), combo, strict=True))
        key = tuple(at[a.name] for a in drive_axes)
        if key not in drives:
            probe = argparse.Namespace(**vars(args))
            for a in drive_axes:
                setattr(probe, a.quantity.dest, f"{at[a.name]!r} {a.si_unit}".strip())
            try:  # the stall force pushes against the load cell: its stiffness is an option there
                fixed = {"load_cell": True} if args.quantity == "stall-force" else {}
                drives[key] = build(probe, **fixed)
            except (UsageError, ValueError) as exc:
                where = ", ".join(f"{a.name} = {_shown(a, at[a.name])}" for a in drive_axes)
                raise UsageError(f"--vary at {where}: {explain(exc, probe)}") from None
        drive = drives[key]
        point = {"drive": drive, "frequency": at.get("frequency", fixed_frequency)}
        columns = {a.column: at[a.name] for a in axes}
        if with_amplitude:
            a_max = drive.actuator.full_stroke_amplitude
            amplitude = at.get("amplitude", fixed_amplitude if fixed_amplitude is not None else a_max)
            if amplitude > a_max * (1 + 1e-12):
                source = (f"--vary = {next(a.typed for a in axes if a.name == 'amplitude')!r}"
                          if "amplitude" in at else f"--amplitude = {args.amplitude!r}")
                raise UsageError(f"{source}: {fmt(amplitude, 'nm')} is out of range: must be <= "
                                 f"{fmt(a_max, 'nm')}, the actuator's full stroke (--full-stroke-amplitude)")
            point["amplitude"] = min(amplitude, a_max)
            columns.setdefault("amplitude_m", point["amplitude"])
        columns.setdefault("frequency_Hz", point["frequency"])
        _check_waveform(args, axes, at, drive, point.get("amplitude", drive.actuator.full_stroke_amplitude),
                        point["frequency"])
        points.append({**point, **columns})
    return points


def _check_waveform(args, axes, at, drive, amplitude, frequency) -> None:
    """The saw-tooth of a point can be built (e.g. its fly-back fits in half a period), before
    anything runs; a refused frequency axis is named as typed."""
    from passmd.model import waveforms

    try:
        waveforms.sawtooth(amplitude, frequency, drive, periods=1)
    except InputError as exc:
        if exc.name == "frequency" and "frequency" in at and exc.limits:
            axis = next(a for a in axes if a.name == "frequency")
            limits = " and ".join(f"{op} {fmt(bound, 'kHz')}" for op, bound in exc.limits)
            why = f" ({exc.why})" if exc.why else ""
            raise _refuse(axis.typed, f"{_shown(axis, frequency)} is out of range: must be "
                                      f"{limits}{why}") from None
        if exc.source == "amplitude" and "amplitude" in at and exc.source_limits:  # e.g. the fly-back time
            axis = next(a for a in axes if a.name == "amplitude")
            limits = " and ".join(f"{op} {_bound(op, bound, 'nm', 'm')}" for op, bound in exc.source_limits)
            raise _refuse(axis.typed, f"{_shown(axis, amplitude)} is out of range: must be {limits} "
                                      f"({exc.quantity} derived from it is out of range)") from None
        raise UsageError(explain(exc, args)) from None


# --------------------------------------------------------------------------------------
# Outputs
# --------------------------------------------------------------------------------------

def _finite_or_none(value):
    if isinstance(value, (float, np.floating)) and not math.isfinite(float(value)):
        return None
    return value


def _arguments(args) -> str:
    """The command's options as parsed (the record of what was asked), one JSON line."""
    skip = ("handler", "resumes_collector", "json", "profile")
    given = {k: v for k, v in sorted(vars(args).items())
             if k not in skip and v is not None and v is not False}
    return json.dumps(given, separators=(",", ":"), ensure_ascii=False)


def _record(args, axes, table, spec, drive) -> dict:
    from passmd import __version__
    from passmd.runtime.provenance import commit_or_version

    rows = [{k: _finite_or_none(v) for k, v in row.items()} for row in table.to_dict(orient="records")]
    missing = sum(row[spec.column] is None for row in rows)
    return {
        "command": "sweep",
        "quantity": args.quantity,
        "column": spec.column,
        "reading": (args.reading or "steady") if args.quantity == "critical-amplitude" else None,
        "waveform": (args.waveform or "sawtooth") if spec.function.__name__ == "steady_point" else None,
        "design_response": (args.design_response or "paper") if uses_eq15(args) else None,
        "axes": [{"name": a.name, "column": a.column, "values": list(a.values), "unit": a.si_unit,
                  "spacing": a.spacing, "typed": a.typed} for a in axes],
        "drive": drive_record(drive),
        "provenance": {"passmd_version": __version__, "git_commit": commit_or_version(),
                       "arguments": _arguments(args)},
        "sweep": {k: table.attrs["sweep"][k] for k in ("points", "cached", "computed")},
        "missing_values": missing,
        "columns": list(map(str, table.columns)),
        "rows": rows,
    }


def run_sweep(args, out) -> int:
    from passmd.protocols.maps import MAP_QUANTITIES, compute_map

    spec = MAP_QUANTITIES[args.quantity]
    _check_options(args)
    axes = _check_axes(args, args.quantity)
    config = run_config(args)
    points = _points(args, axes, spec.amplitude)
    base = points[0]["drive"]
    table = compute_map(args.quantity, points, reading=args.reading or "steady",
                        waveform=args.waveform or "sawtooth", design_response=args.design_response or "paper",
                        config=config)
    check_values(args, spec.column, table)
    add_band(args, spec, table, lambda build: _points(args, axes, spec.amplitude, build), config)
    derived_columns(args, axes, table)
    title = sweep_title(spec, axes, base)
    warned = warnings_of(axes, spec, table, _shown)
    diagnoses = diagnose_sweep(args, axes, spec, table, points, config)
    record = {**_record(args, axes, table, spec, base), "warnings": warned, "diagnoses": diagnoses}
    if args.out is not None:
        figure = sweep_figure(args, axes, spec, table, title) if len(axes) <= 2 else None
        record["files"] = sweep_files.write(args, record, table, figure)
    if args.json:
        emit_json(record, out)
        return 0
    counts = record["sweep"]
    rows = [("axes", " × ".join(f"{a.name} {_shown(a, a.values[0])} … {_shown(a, a.values[-1])} "
                                f"({len(a.values)}, {a.spacing})" for a in axes)),
            ("points", f"{counts['points']} ({counts['cached']} from the cache, "
                       f"{counts['computed']} computed)")]
    rows += curve_rows(axes, spec, table, _shown) if len(axes) == 1 and len(table) <= MAX_SHOWN else \
        extreme_rows(axes, spec, table, _shown)
    rows += eq15_rows(args, table)
    rows += [(w["kind"], f"at {w['points']} of {w['of']} points ({w['range']}): {w['text']}") for w in warned]
    if len(axes) == 1:
        resolved = resolution(spec, table["frequency_Hz"])
        rows += turn_rows(axes[0], spec, table, resolved, _shown, bool(diagnoses))
        rows += sweep_diagnosis_rows(diagnoses, axes[0], spec, table, _shown)
    if record["missing_values"]:
        rows += missing_rows(args, table, record["missing_values"])
    if "files" in record:
        rows.append(("written", ", ".join(record["files"].values())))
    emit_rows(f"passmd sweep {args.quantity} — {describe(base, omit=[a.name for a in axes])}", rows, out)
    return 0
