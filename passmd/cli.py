"""The ``passmd`` command line.

Subcommands::

    passmd theory               closed forms of a configuration (Eqs. 1, 7–14)
    passmd critical-amplitude   simulated and analytic critical amplitude A_c
    passmd run                  one simulation of a driving waveform
    passmd force                generated force against the load cell
    passmd contact              tangential force of one MDR contact along a path
    passmd figure               one paper figure's data and image
    passmd ledger               the replication ledger: every claim's computed category
    passmd cache                the on-disk simulation cache: info, clear, prune

Quantities accept units (``0.4N``, ``1mm``, ``0.25 mm``, ``202nm``, ``100kHz``,
``310GPa``); a bare number is read in the unit ``--help`` shows. Human output uses nm,
N, mm and kHz; ``--json`` prints one JSON object in SI units whose keys carry the unit.

Exit status: 0 success, 2 usage error (unknown option, wrong unit, out-of-range value,
contradicting options), 1 failed run (the simulation diverged, a result failed its
finiteness/plausibility check, an output could not be written, an optional dependency
is missing, not enough memory), 130 interrupted (Ctrl-C), 141 standard output closed
(a pipe reader such as ``head`` went away; nothing is printed, as Unix tools do).
Errors print one line to stderr, never a traceback. Parameter ranges come from
:data:`passmd.parameters.PLAUSIBLE_RANGES`; ``--allow-extrapolation`` lifts their soft
limits. On a console that cannot encode the output's symbols (μ, ×, –, →), ASCII
stand-ins are printed.
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import importlib.util
import json
import math
import os
import re
import sys
import textwrap
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from passmd import __version__
from passmd._cli_streams import (
    Out,
    PipeClosed,
    StdoutError,
    available_memory,
    one_line_warnings,
    silence_stdout,
    use_ascii_fallback,
    write_atomically,
)
from passmd._result_bounds import ResultError, check_force_bound, check_run_bounds
from passmd._validation import check_range
from passmd.cache import CACHE_DIR_ENV, DEFAULT_CACHE_DIR, CacheWarning
from passmd.parameters import (
    ACTUATOR_DAMPING_RATIO,
    PLAUSIBLE_RANGES,
    Actuator,
    Amplifier,
    Drive,
    Material,
    actuator_for_radius,
    check_contact_plausible,
)
from passmd.units import QuantityError, from_si, parse_quantities, parse_quantity

__all__ = ["UsageError", "build_drive", "main", "make_parser"]

PROG = "passmd"
NOT_AVAILABLE = "not available yet"


_DEFAULT = Drive()

DESCRIPTION = """\
passmd: the piezo-actuated stick-slip micro-drive of Nguyen et al., Coatings 8, 62 (2018).

Quantities accept units (0.4N, 1mm, '0.25 mm', 202nm, 100kHz, 310GPa); a bare number is
read in the unit the option's help shows. Human output uses nm, N, mm and kHz; --json
prints one JSON object in SI units whose keys carry the unit (e.g. final_position_m)."""


class UsageError(ValueError):
    """A user error found after argument parsing (exit status 2)."""


class NotAvailableError(UsageError):
    """A name (figure panel) the package does not provide (exit status 2)."""


class MissingDependencyError(RuntimeError):
    """An optional dependency is not installed (exit status 1)."""


#: Optional dependencies: importable module -> the passmd extra that installs it.
OPTIONAL_EXTRAS = {"distributed": "dask", "dask": "dask"}


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (no usage dump) and exit status 2."""

    def error(self, message):  # noqa: D401 - argparse API
        self.exit(2, f"{self.prog}: error: {message}\n")

    def _print_message(self, message, file=None):  # argparse would swallow a failed write
        if message:
            (file or sys.stderr).write(message)


class _Formatter(argparse.RawDescriptionHelpFormatter):
    def __init__(self, prog):
        super().__init__(prog, max_help_position=34, width=100)


# --------------------------------------------------------------------------------------
# Quantity options
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Quantity:
    """A command-line quantity: flag, display unit, symbol, bounds and default text."""

    flag: str
    unit: str
    symbol: str
    text: str
    default: str
    lower: float | None = 0.0
    lower_open: bool = True
    upper: float | None = None
    upper_open: bool = False
    #: key of passmd.parameters.PLAUSIBLE_RANGES checked instead of lower/upper
    plausible: str | None = None

    @property
    def dest(self) -> str:
        return self.flag.lstrip("-").replace("-", "_")

    def add(self, parser) -> None:
        unit = f"[{self.unit}]" if self.unit else "[-]"
        parser.add_argument(
            self.flag,
            metavar=self.symbol,
            default=None,
            help=f"{self.text} {unit} (default: {self.default})",
        )

    def parse(self, args) -> float | None:
        """SI value of the option, ``None`` if not given; range checked in display units."""
        raw = getattr(args, self.dest)
        if raw is None:
            return None
        value = parse_quantity(raw, self.unit, name=self.flag)
        if self.plausible is not None:
            scale = 1.0 / from_si(1.0, self.unit) if self.unit else 1.0
            PLAUSIBLE_RANGES[self.plausible].check(
                self.flag, value, allow_extrapolation=bool(getattr(args, "allow_extrapolation", False)),
                shown=self.flag, scale=scale, unit=self.unit, hint="--allow-extrapolation")
            return value
        shown = float(f"{from_si(value, self.unit):.12g}")
        check_range(self.flag, shown, self.lower, self.upper, lower_open=self.lower_open,
                    upper_open=self.upper_open, unit=self.unit or "–")
        return value


def _fmt(value_si: float, unit: str) -> str:
    return f"{from_si(value_si, unit):.6g} {unit}".rstrip()


_ACT = _DEFAULT.actuator
_AT_R = f"at {_fmt(_DEFAULT.hemisphere_radius, 'mm')}"
_DRIVE_QUANTITIES = (
    _Quantity("--preload", "N", "F_p", "preload", _fmt(_DEFAULT.preload, "N"), plausible="preload"),
    _Quantity("--radius", "mm", "R", "hemisphere radius", _fmt(_DEFAULT.hemisphere_radius, "mm"),
              plausible="hemisphere_radius"),
    _Quantity("--mu", "", "mu", "friction coefficient", f"{_DEFAULT.friction_coefficient:g}",
              plausible="friction_coefficient"),
    _Quantity("--runner-mass", "g", "m_r", "runner mass", _fmt(_DEFAULT.runner_mass, "g"),
              plausible="runner_mass"),
    _Quantity("--load-cell-stiffness", "N/m", "k", "load cell stiffness",
              _fmt(_DEFAULT.load_cell_stiffness, "N/m"), plausible="load_cell_stiffness"),
    _Quantity("--hemisphere-modulus", "GPa", "E_1", "Young's modulus of the hemispheres",
              _fmt(_DEFAULT.hemisphere_material.youngs_modulus, "GPa") + " (ruby)",
              plausible="material.youngs_modulus"),
    _Quantity("--hemisphere-poisson", "", "nu_1", "Poisson's ratio of the hemispheres",
              f"{_DEFAULT.hemisphere_material.poissons_ratio:g}", -1.0, True, 0.5, True),
    _Quantity("--runner-modulus", "GPa", "E_2", "Young's modulus of the runner",
              _fmt(_DEFAULT.runner_material.youngs_modulus, "GPa") + " (steel)",
              plausible="material.youngs_modulus"),
    _Quantity("--runner-poisson", "", "nu_2", "Poisson's ratio of the runner",
              f"{_DEFAULT.runner_material.poissons_ratio:g}", -1.0, True, 0.5, True),
    _Quantity("--actuator-stiffness", "N/m", "k_p", "actuator stiffness",
              f"Table 2 for --radius, {_fmt(_ACT.stiffness, 'N/m')} {_AT_R}", plausible="actuator.stiffness"),
    _Quantity("--actuator-mass", "g", "m_a", "actuator mass",
              f"Table 2 for --radius, {_fmt(_ACT.mass, 'g')} {_AT_R}", plausible="actuator.mass"),
    _Quantity("--actuator-viscosity", "kg/s", "c_p", "actuator viscosity",
              f"2ζ√(k_p m_a) with ζ = {ACTUATOR_DAMPING_RATIO:g}, {_fmt(_ACT.viscosity, 'kg/s')} {_AT_R}",
              0.0, False),
    _Quantity("--full-stroke-amplitude", "nm", "A_max", "actuation amplitude at the full voltage",
              f"Table 2 for --radius, {_fmt(_ACT.full_stroke_amplitude, 'nm')} {_AT_R}",
              plausible="actuator.full_stroke_amplitude"),
    _Quantity("--amplifier-voltage", "V", "V_pp", "amplifier peak-to-peak voltage",
              _fmt(_DEFAULT.amplifier.peak_to_peak_voltage, "V"), plausible="amplifier.peak_to_peak_voltage"),
    _Quantity("--slew-rate", "V/us", "SR", "amplifier slew rate",
              _fmt(_DEFAULT.amplifier.slew_rate, "V/us"), plausible="amplifier.slew_rate"),
)
#: Options of the actuators' dynamics, which rigid actuators do not have.
_ACTUATOR_DYNAMICS = ("--actuator-stiffness", "--actuator-mass", "--actuator-viscosity")
_Q = {q.flag: q for q in _DRIVE_QUANTITIES}

_MATERIAL_FLAGS = ("--hemisphere-modulus", "--hemisphere-poisson", "--runner-modulus", "--runner-poisson")


def _add_drive_options(parser, *, contact_only: bool = False) -> None:
    group = parser.add_argument_group("drive (Tables 1–2; a bare number is in the unit shown)")
    if not contact_only:
        group.add_argument("--contacts", type=int, choices=(1, 6), default=_DEFAULT.contacts,
                           help=f"one-contact or six-contact model (default: {_DEFAULT.contacts})")
        group.add_argument("--actuator", choices=("rigid", "flexible"), default=_DEFAULT.actuator_model,
                           help="ideally rigid or mass–spring–damper actuators "
                                f"(default: {_DEFAULT.actuator_model})")
    for q in _DRIVE_QUANTITIES:
        if contact_only and q.flag not in ("--radius", "--mu", *_MATERIAL_FLAGS):
            continue
        q.add(group)
    group.add_argument("--allow-extrapolation", action="store_true",
                       help="accept parameters outside the plausible ranges around Tables 1–2 (soft limits; "
                            "hard limits, where the model breaks, stay) (default: off)")


def _material(base: Material, modulus, poisson) -> Material:
    if modulus is None and poisson is None:
        return base
    return Material(
        base.youngs_modulus if modulus is None else modulus,
        base.poissons_ratio if poisson is None else poisson,
        f"{base.name} (modified)",
    )


def build_drive(args, **fixed) -> Drive:
    """The :class:`~passmd.parameters.Drive` the parsed options describe (SI inside).

    Actuator: Table 2 for the radius, each given override replacing its field; the
    viscosity, unless given, is 2ζ√(k_p m_a) of the final k_p and m_a.
    """
    v = {flag: q.parse(args) for flag, q in _Q.items() if hasattr(args, q.dest)}
    if getattr(args, "actuator", None) == "rigid":
        given = [flag for flag in _ACTUATOR_DYNAMICS if v.get(flag) is not None]
        if given:
            raise UsageError(f"{given[0]} contradicts --actuator rigid: ideally rigid actuators have no "
                             "stiffness, mass or viscosity (use --actuator flexible, or drop the option)")
    if v.get("--load-cell-stiffness") is not None and not fixed.get("load_cell", False):
        raise UsageError("--load-cell-stiffness has no effect here: the runner is free (no load cell); "
                         "use it with `passmd force` or `passmd run --load-cell`")
    radius = v.get("--radius") or _DEFAULT.hemisphere_radius
    base = actuator_for_radius(radius)
    k_p = v.get("--actuator-stiffness") or base.stiffness
    m_a = v.get("--actuator-mass") or base.mass
    c_p = v.get("--actuator-viscosity")
    actuator = Actuator(
        stiffness=k_p,
        mass=m_a,
        viscosity=2.0 * ACTUATOR_DAMPING_RATIO * math.sqrt(k_p * m_a) if c_p is None else c_p,
        full_stroke_amplitude=v.get("--full-stroke-amplitude") or base.full_stroke_amplitude,
    )
    amplifier = Amplifier(
        peak_to_peak_voltage=v.get("--amplifier-voltage") or _DEFAULT.amplifier.peak_to_peak_voltage,
        slew_rate=v.get("--slew-rate") or _DEFAULT.amplifier.slew_rate,
    )
    fields = {
        "hemisphere_radius": radius,
        "preload": v.get("--preload") or _DEFAULT.preload,
        "friction_coefficient": v.get("--mu") or _DEFAULT.friction_coefficient,
        "runner_mass": v.get("--runner-mass") or _DEFAULT.runner_mass,
        "load_cell_stiffness": v.get("--load-cell-stiffness") or _DEFAULT.load_cell_stiffness,
        "hemisphere_material": _material(_DEFAULT.hemisphere_material, v.get("--hemisphere-modulus"),
                                         v.get("--hemisphere-poisson")),
        "runner_material": _material(_DEFAULT.runner_material, v.get("--runner-modulus"),
                                     v.get("--runner-poisson")),
        "actuator": actuator,
        "amplifier": amplifier,
        "allow_extrapolation": bool(getattr(args, "allow_extrapolation", False)),
    }
    if hasattr(args, "contacts"):
        fields["contacts"] = args.contacts
        fields["actuator_model"] = args.actuator
    fields.update(fixed)
    return Drive(**fields)


def drive_record(drive: Drive) -> dict:
    """The drive's parameters in SI, keys carrying the unit (the ``drive`` object of ``--json``)."""
    act, amp = drive.actuator, drive.amplifier
    return {
        "contacts": drive.contacts,
        "actuator_model": drive.actuator_model,
        "preload_N": drive.preload,
        "hemisphere_radius_m": drive.hemisphere_radius,
        "friction_coefficient": drive.friction_coefficient,
        "runner_mass_kg": drive.runner_mass,
        "load_cell_stiffness_N_per_m": drive.load_cell_stiffness,
        "load_cell": drive.load_cell,
        "hemisphere_youngs_modulus_Pa": drive.hemisphere_material.youngs_modulus,
        "hemisphere_poissons_ratio": drive.hemisphere_material.poissons_ratio,
        "runner_youngs_modulus_Pa": drive.runner_material.youngs_modulus,
        "runner_poissons_ratio": drive.runner_material.poissons_ratio,
        "actuator_stiffness_N_per_m": act.stiffness,
        "actuator_mass_kg": act.mass,
        "actuator_viscosity_kg_per_s": act.viscosity,
        "full_stroke_amplitude_m": act.full_stroke_amplitude,
        "amplifier_voltage_V": amp.peak_to_peak_voltage,
        "slew_rate_V_per_s": amp.slew_rate,
    }


# --------------------------------------------------------------------------------------
# Output
# --------------------------------------------------------------------------------------


def _plain(obj, where: str = "result"):
    """JSON-ready: numpy scalars/arrays to Python; a non-finite float is a :class:`ResultError`."""
    if isinstance(obj, dict):
        return {str(k): _plain(v, str(k)) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, np.ndarray)):
        return [_plain(x, where) for x in (obj.tolist() if isinstance(obj, np.ndarray) else obj)]
    if isinstance(obj, (np.bool_, bool)):
        return bool(obj)
    if isinstance(obj, (np.integer, int)):
        return int(obj)
    if isinstance(obj, (np.floating, float)):
        if not math.isfinite(float(obj)):
            raise ResultError(f"result {where} = {float(obj)!r} is not finite: the configuration is outside "
                              "what the model can compute")
        return float(obj)
    return obj


def _check_results(record: dict) -> dict:
    """Every number of a command's record finite (same check with and without ``--json``)."""
    _plain(record)
    return record


def _emit_json(payload: dict, out) -> None:
    out.write(json.dumps(_plain(payload), indent=2, allow_nan=False) + "\n")


def _emit_rows(title: str, rows: list[tuple[str, str]], out) -> None:
    out.write(title + "\n")
    width = max((len(label) for label, _ in rows), default=0)
    for label, value in rows:
        out.write(f"  {label:<{width}}  {value}\n")


def _nm(values, shown: int = 8) -> str:
    """Lengths in nm; long lists show their first and last values (--json has all)."""
    text = [f"{x:.4g}" for x in from_si(np.atleast_1d(np.asarray(values, dtype=float)), "nm")]
    if len(text) > shown:
        half = shown // 2
        return f"{', '.join(text[:half])}, …, {', '.join(text[-half:])} nm ({len(text)} values)"
    return ", ".join(text) + " nm"


def _sides(values, unit: str, digits: int = 5) -> str:
    arr = np.atleast_1d(np.asarray(values, dtype=float))
    text = [f"{x:.{digits}g}" for x in from_si(arr, unit)]
    if len(text) == 2:
        return f"{text[0]} {unit} (side 1, ×2) | {text[1]} {unit} (side 2, ×4)"
    return f"{text[0]} {unit}"


def _describe(drive: Drive) -> str:
    return (
        f"R = {_fmt(drive.hemisphere_radius, 'mm')}, F_p = {_fmt(drive.preload, 'N')}, "
        f"μ = {drive.friction_coefficient:g}, {drive.contacts} contact{'s' * (drive.contacts > 1)}, "
        f"{drive.actuator_model} actuators"
    )


# --------------------------------------------------------------------------------------
# Subcommands
# --------------------------------------------------------------------------------------


def _cmd_theory(args, out) -> int:
    from passmd.theory import drive_theory, runner_frequency

    drive = build_drive(args)
    result = drive_theory(drive)
    result["runner_frequency_Hz"] = runner_frequency(drive)
    result["actuator_natural_frequency_Hz"] = drive.actuator.natural_frequency
    _check_results(result)
    if args.json:
        _emit_json({"command": "theory", "drive": drive_record(drive), **result}, out)
        return 0
    rows = [
        ("E* (Eq. 4)", _fmt(result["E_star_Pa"], "GPa")),
        ("G* (Eq. 4)", _fmt(result["G_star_Pa"], "GPa")),
        ("normal force per contact F_N (Eq. 1)", _sides(result["normal_force_N"], "N")),
        ("Hertz contact radius a", _sides(result["contact_radius_m"], "mm")),
        ("indentation d", _sides(result["indentation_m"], "nm")),
        ("tangential stiffness 2aG*", _sides(result["tangential_stiffness_N_per_m"], "N/m")),
        ("presliding u_x,max (Eq. 7/10)", _sides(result["presliding_m"], "nm")),
        ("actuator deformation u_x,a (Eq. 9/14)", _sides(result["actuator_deformation_m"], "nm")),
        ("A_c, rigid actuators (Eq. 7/11)", _fmt(result["critical_amplitude_rigid_m"], "nm")),
        ("A_c, flexible actuators (Eq. 8/12)", _fmt(result["critical_amplitude_flexible_m"], "nm")),
        ("runner-on-contacts frequency", _fmt(result["runner_frequency_Hz"], "kHz")),
        ("bare actuator frequency", _fmt(result["actuator_natural_frequency_Hz"], "kHz")),
    ]
    _emit_rows(f"passmd theory — {_describe(drive)}", rows, out)
    return 0


def _cmd_contact(args, out) -> int:
    from passmd.contact import MDRContact
    from passmd.theory import contact_moduli

    if args.path is None:
        raise UsageError("--path is required, e.g. --path 0nm,30nm,-10nm,45nm")
    path = parse_quantities(args.path, "nm", name="--path")
    normal = _NORMAL_FORCE.parse(args) or _DEFAULT.preload
    springs = _check_springs(args.springs)
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
    _check_results(record)
    if args.json:
        _emit_json(record, out)
        return 0
    model = "exact (N → ∞)" if springs is None else f"discrete, {springs} springs"
    out.write(
        f"passmd contact — {model}, F_N = {_fmt(contact.normal_force, 'N')}, "
        f"R = {_fmt(drive.hemisphere_radius, 'mm')}, μ = {drive.friction_coefficient:g}\n"
        f"  μF_N = {contact.sliding_force:.6g} N, u_max = {_fmt(contact.presliding, 'nm')} (Eq. 7)\n"
        f"  {'u = x_a − x_r [nm]':>20}  {'T [N]':>12}\n"
    )
    for u, f in zip(path, forces, strict=True):
        out.write(f"  {from_si(u, 'nm'):>20.6g}  {f:>12.6g}\n")
    return 0


def _check_springs(springs):
    if springs is None:
        return None
    if springs < 2:
        raise UsageError(
            f"--springs = {springs} is out of range: must be an integer >= 2 (omit it for the exact contact)"
        )
    return springs


def _waveform_args(args, drive):
    """(amplitude, frequency) in SI after the display-unit checks."""
    a_max = drive.actuator.full_stroke_amplitude
    amplitude = _AMPLITUDE.parse(args)
    amplitude = a_max if amplitude is None else amplitude
    if amplitude > a_max * (1 + 1e-12):
        raise UsageError(
            f"--amplitude = {from_si(amplitude, 'nm'):.10g} nm is out of range: must be <= "
            f"{from_si(a_max, 'nm'):.10g} nm, the actuator's full stroke (--full-stroke-amplitude)"
        )
    frequency = _FREQUENCY.parse(args) or _DEFAULT_FREQUENCY
    if args.periods < 1:
        raise UsageError(f"--periods = {args.periods} is out of range: must be an integer >= 1")
    return min(amplitude, a_max), frequency


#: Bytes per recorded sample (time, piezo/runner positions and velocities, per-group
#: contact columns, with the DataFrame/plot copies) and per period (waveform breakpoints,
#: per-period measures) used to estimate a run's memory before allocating it.
_BYTES_PER_SAMPLE = 4 * 8 * (4 + 3 * 6)
_BYTES_PER_PERIOD = 8 * 64


def _check_memory(args, periods_flag: str = "--periods") -> None:
    """Refuse a run whose records would not fit in memory (estimated before allocating)."""
    if args.max_points < 2:
        raise UsageError(f"--max-points = {args.max_points} is out of range: must be an integer >= 2")
    periods = max(args.periods, getattr(args, "max_periods", 0) or 0)
    need = args.max_points * _BYTES_PER_SAMPLE + periods * _BYTES_PER_PERIOD
    available = available_memory()
    if available is not None and need > available // 2:
        raise UsageError(
            f"--max-points = {args.max_points} with {periods_flag} = {periods} needs about "
            f"{need / 2**30:.3g} GiB, more than half the {available / 2**30:.3g} GiB available: "
            "lower --max-points or the number of periods"
        )


#: Image formats --plot can write (matplotlib's Agg/PDF/SVG/PS backends).
_PLOT_FORMATS = ("png", "pdf", "svg", "ps", "eps", "jpg", "jpeg", "tif", "tiff", "webp")


def _check_output_paths(args) -> None:
    """--csv/--plot: a file name in an existing directory, a known image format (before running)."""
    for flag, name in (("--csv", args.csv), ("--plot", args.plot)):
        if name is None:
            continue
        if not name.strip():
            raise UsageError(f"{flag} = {name!r} is not a file name")
        target = Path(name)
        if target.is_dir():
            raise UsageError(f"{flag} = {name!r} is a directory: give a file name")
        parent = target.parent if str(target.parent) else Path(".")
        if not parent.is_dir():
            raise OutputError(f"cannot write {flag} {name}: directory {str(parent)!r} does not exist")
    if args.plot is not None:
        suffix = Path(args.plot).suffix.lower().lstrip(".")
        if suffix not in _PLOT_FORMATS:
            raise UsageError(f"--plot = {args.plot!r} has {'no' if not suffix else 'an unknown'} image "
                             f"extension: must end in one of {', '.join('.' + f for f in _PLOT_FORMATS)}")


def _simulate(args, drive):
    from passmd import dynamics, optimized_waveform, waveforms
    from passmd.protocols import eq15

    amplitude, frequency = _waveform_args(args, drive)
    springs = _check_springs(args.springs)
    if args.waveform == "optimized":
        # Eq. 15, designed from this drive's own simulated saw-tooth response (first period a
        # saw-tooth, as in the paper); a ValueError (e.g. Δ_a ≥ A) is a usage error
        design = eq15.optimized_design(amplitude, drive, flyback=args.flyback)
        wave = optimized_waveform.optimized(amplitude, frequency, drive, periods=args.periods,
                                            flyback=args.flyback, design=design)
    else:
        wave = waveforms.sawtooth(amplitude, frequency, drive, periods=args.periods, flyback=args.flyback)
    result = dynamics.simulate(
        drive, wave, contact_model="exact" if springs is None else "discrete",
        springs=springs or 200, max_points=args.max_points,
    )
    return result


def _write_outputs(args, result) -> None:
    if args.csv:
        try:
            frame = result.to_frame()
            write_atomically(args.csv, lambda tmp: frame.to_csv(tmp, index=False))
        except OSError as exc:
            raise OutputError(f"cannot write --csv {args.csv}: {exc.strerror or exc}") from exc
    if args.plot:
        from matplotlib.figure import Figure

        fig = Figure(figsize=(7, 4), layout="constrained")
        ax = fig.add_subplot()
        t_ms = result.time * 1e3
        ax.plot(t_ms, from_si(result.piezo_position, "nm"), label="piezo x_p", lw=0.8)
        ax.plot(t_ms, from_si(result.runner_position, "nm"), label="runner x_r", lw=0.8)
        ax.set_xlabel("time [ms]")
        ax.set_ylabel("position [nm]")
        ax.legend()
        ax.set_title(_describe(result.drive), fontsize=9)
        try:
            fmt = Path(args.plot).suffix.lstrip(".").lower()
            write_atomically(args.plot, lambda tmp: fig.savefig(tmp, dpi=150, format=fmt))
        except OSError as exc:
            raise OutputError(f"cannot write --plot {args.plot}: {exc.strerror or exc}") from exc


class OutputError(RuntimeError):
    """An output file could not be written (exit status 1)."""


def _run_summary(result) -> dict:
    summary = result.summary()
    summary["wall_time_s"] = float(result.wall_time)
    return summary


def _cmd_run(args, out) -> int:
    drive = build_drive(args, load_cell=bool(args.load_cell))
    _waveform_args(args, drive)  # every option checked before anything runs
    _check_springs(args.springs)
    _check_memory(args)
    _check_output_paths(args)
    result = _simulate(args, drive)
    summary = _check_results(_run_summary(result))
    check_run_bounds(summary, drive, float(summary["amplitude_m"]))
    _write_outputs(args, result)
    if args.json:
        _emit_json({"command": "run", "waveform": args.waveform, "flyback": args.flyback,
                    "drive": drive_record(drive), **summary}, out)
        return 0
    rows = [
        ("waveform", f"{args.waveform}, A = {_fmt(summary['amplitude_m'], 'nm')}, "
                     f"f = {_fmt(summary['frequency_Hz'], 'kHz')}, {summary['periods']} periods"),
        ("final position", _fmt(summary["final_position_m"], "nm")),
        ("step per period", _nm(summary["step_sizes_m"]) if summary["step_sizes_m"] else "– (one period)"),
        ("back-step per period", _nm(summary["back_steps_m"])),
    ]
    if "mean_velocity_m_per_s" in summary:
        rows.append(("mean velocity", f"{summary['mean_velocity_m_per_s'] * 1e3:.6g} mm/s"))
    if "generated_force_N" in summary:
        rows.append(("generated force", _fmt(summary["generated_force_N"], "N")))
    rows.append(("integrator", f"{summary['integrator_steps']} steps, {summary['wall_time_s']:.3g} s"))
    _emit_rows(f"passmd run — {_describe(drive)}", rows, out)
    return 0


def _cmd_force(args, out) -> int:
    from passmd.experiments import force_generation as fg

    drive = build_drive(args, load_cell=True)
    if args.waveform != "sawtooth":
        raise UsageError(
            "--waveform optimized is not supported by force: the stall protocol of the force-generation "
            "chapter (Section 4.2) drives with the saw-tooth; use `passmd run --waveform optimized "
            "--load-cell` for one run against the load cell"
        )
    if args.springs is not None:
        raise UsageError("--springs is not supported by force: the stall runs use the exact contact")
    amplitude, frequency = _waveform_args(args, drive)
    if args.max_periods < args.periods:
        raise UsageError(f"--max-periods = {args.max_periods} is out of range: must be >= --periods "
                         f"({args.periods})")
    _check_memory(args, "--max-periods")
    _check_output_paths(args)
    # the force-generation chapter's stall protocol: runs from rest, lengthened until stalled
    try:
        found = fg.generated_force(drive, amplitude, frequency, flyback=args.flyback,
                                   initial_periods=args.periods, max_periods=args.max_periods)
    except ValueError as exc:  # name the command's options, not the library's parameters
        text = re.sub(r"\binitial_periods\b", "--periods", str(exc))
        raise UsageError(re.sub(r"\bmax_periods\b", "--max-periods", text)) from exc
    _check_results(found)
    check_force_bound(found, drive)
    if args.csv or args.plot:  # the reported run again, for its time series
        from passmd import dynamics, waveforms

        wave = waveforms.sawtooth(amplitude, frequency, drive, periods=found["periods"], flyback=args.flyback)
        _write_outputs(args, dynamics.simulate(drive, wave, max_points=args.max_points))
    record = {"command": "force", "waveform": "sawtooth", "flyback": args.flyback,
              "amplitude_m": amplitude, "frequency_Hz": frequency, "drive": drive_record(drive), **found}
    if args.json:
        _emit_json(record, out)
        return 0
    state = "stalled" if found["converged"] else f"NOT stalled after {found['periods_simulated']} periods"
    rows = [
        ("waveform", f"sawtooth, A = {_fmt(amplitude, 'nm')}, f = {_fmt(frequency, 'kHz')}"),
        ("generated force k·x̄_r", f"{_fmt(found['generated_force_N'], 'N')}  ({state})"),
        ("run reported", f"{found['periods']} periods from rest; still to come ≈ "
                         f"{_fmt(found['remaining_force_N'], 'N')}"),
        ("last step", _fmt(found["last_step_m"], "nm")),
        ("integration", f"{found['periods_simulated']} periods, {found['wall_time_s']:.3g} s"),
    ]
    _emit_rows(f"passmd force — {_describe(drive)}, load cell k = "
               f"{_fmt(drive.load_cell_stiffness, 'N/m')}", rows, out)
    return 0


def _cmd_critical_amplitude(args, out) -> int:
    from passmd.theory import drive_theory

    drive = build_drive(args)
    theory = drive_theory(drive)
    record = {
        "command": "critical-amplitude",
        "drive": drive_record(drive),
        "analytic_critical_amplitude_m": theory["analytic_critical_amplitude_m"],
        "critical_amplitude_rigid_m": theory["critical_amplitude_rigid_m"],
        "critical_amplitude_flexible_m": theory["critical_amplitude_flexible_m"],
    }
    from passmd.experiments import critical_amplitude as ca

    # every option is checked, whether or not --analytic-only skips the search
    if args.periods < 2:
        raise UsageError(f"--periods = {args.periods} is out of range: a step needs >= 2 periods")
    if args.threshold is not None and args.protocol == "first":
        raise UsageError("--threshold contradicts --protocol first: the first-fly-back protocol has no "
                         "step threshold (use --protocol steady, or drop --threshold)")
    threshold = _THRESHOLD.parse(args) or ca.STEP_THRESHOLD
    tolerance = _TOLERANCE.parse(args) or _DEFAULT_TOLERANCE
    frequency = _FREQUENCY.parse(args) or ca.DRIVE_FREQUENCY
    if not args.analytic_only:
        # the book's search (critical-amplitude chapters): one protocol for users and book
        found = ca.critical_amplitude(
            drive, protocol=args.protocol, frequency=frequency, flyback=args.flyback,
            periods=args.periods, threshold=threshold, tolerance=tolerance,
        )
        value = found["critical_amplitude_m"]
        record.update({
            "critical_amplitude_m": None if math.isnan(value) else value,
            "bracket_m": [found["bracket_low_m"],
                          None if math.isnan(found["bracket_high_m"]) else found["bracket_high_m"]],
            "protocol": args.protocol,
            "threshold_m": threshold if args.protocol == "steady" else None,
            "tolerance_m": tolerance,
            "frequency_Hz": frequency,
            "periods": args.periods if args.protocol == "steady" else 1,
            "flyback": args.flyback,
            "simulations": found["runs"],
            "wall_time_s": found["wall_time_s"],
        })
    _check_results(record)
    if args.json:
        _emit_json(record, out)
        return 0
    rows = []
    if not args.analytic_only:
        found = record["critical_amplitude_m"]
        lo, hi = record["bracket_m"]
        a_max = drive.actuator.full_stroke_amplitude
        if record["protocol"] == "steady":
            criterion = (f"last of {record['periods']} steps > {_fmt(record['threshold_m'], 'nm')}")
        else:
            criterion = "full sliding of every contact in the first fly-back"
        rows.append(("simulated A_c", f"{_fmt(found, 'nm')}  (bracket {from_si(lo, 'nm'):.4g}–"
                                      f"{from_si(hi, 'nm'):.4g} nm)" if found is not None else
                     f"none up to the full stroke {_fmt(a_max, 'nm')} ({criterion})"))
        rows.append(("search", f"{record['protocol']}: {criterion}, "
                               f"f = {_fmt(record['frequency_Hz'], 'kHz')}, {record['flyback']} fly-back, "
                               f"{record['simulations']} simulations"))
    eq = "Eq. 7/11" if drive.actuator_model == "rigid" else "Eq. 8/12"
    rows.append((f"analytic A_c ({eq})", _fmt(record["analytic_critical_amplitude_m"], "nm")))
    _emit_rows(f"passmd critical-amplitude — {_describe(drive)}", rows, out)
    return 0


@contextlib.contextmanager
def _sweep_environment(args):
    """Route the figure's sweeps (run deep inside passmd.experiments) through the environment."""
    from passmd import sweep

    settings = {
        sweep.EXECUTOR_ENV: args.executor,
        sweep.SCHEDULER_ENV: args.scheduler,
        sweep.WORKERS_ENV: None if args.workers is None else str(args.workers),
        CACHE_DIR_ENV: args.cache_dir,
    }
    saved = {key: os.environ.get(key) for key in settings}
    try:
        for key, value in settings.items():
            if value is not None:
                os.environ[key] = value
        yield
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


def _require_executor(executor, scheduler) -> None:
    """Dask needs the optional ``distributed`` package: say which extra installs it."""
    if (executor == "dask" or (executor in (None, "") and scheduler)) \
            and importlib.util.find_spec("distributed") is None:
        raise MissingDependencyError("the Dask executor needs the 'distributed' package, which is not "
                                     "installed: pip install 'passmd[dask]'")


def _check_sweep_options(args) -> None:
    """The sweep options of ``figure`` and ``ledger``: workers, cache directory, executor."""
    if args.workers is not None and args.workers < 1:
        raise UsageError(f"--workers = {args.workers} is out of range: must be an integer >= 1")
    if args.cache_dir is not None and not args.cache_dir.strip():
        raise UsageError(f"--cache-dir = {args.cache_dir!r} is not a directory name")
    _require_executor(args.executor or os.environ.get("PASSMD_EXECUTOR"), args.scheduler
                      or os.environ.get("PASSMD_SCHEDULER"))


def _cmd_cache(args, out) -> int:
    from passmd.cache import Cache

    store = Cache(args.cache_dir or None)
    if store.directory.exists() and not store.directory.is_dir():
        raise OutputError(f"the cache {store.directory} is not a directory")
    if args.action == "info":
        record = store.info()
    elif args.action == "clear":
        record = {"directory": str(store.directory), "removed": store.clear()}
    else:
        record = {"directory": str(store.directory), "removed": store.prune()}
    if args.json:
        _emit_json({"command": "cache", "action": args.action, **record}, out)
        return 0
    if args.action != "info":
        out.write(f"{args.action}: removed {record['removed']} file(s) from {record['directory']}\n")
        return 0
    rows = [("directory", record["directory"]),
            ("entries", f"{record['entries']} ({record['current_code']} of the current code, "
                        f"{record['other_code']} of other code versions: 'passmd cache prune' removes them)"),
            ("size", f"{record['bytes'] / 2**20:.3g} MiB"),
            ("unreadable / leftovers", f"{record['unreadable']} / {record['leftovers']}")]
    rows += [(f"  {name}", str(n)) for name, n in sorted(record["functions"].items())]
    _emit_rows("passmd cache", rows, out)
    return 0


def _cmd_ledger(args, out) -> int:
    """Every claim of the paper with its computed category, values and evidence (Section 4-6)."""
    from passmd import ledger, ledger_views
    from passmd.claims import STATUSES
    from passmd.config import RunConfig

    _check_sweep_options(args)
    with _sweep_environment(args):
        evaluated = ledger.evaluate(config=RunConfig(profile=args.profile))
    if args.write_baseline:
        header = (f"ledger categories, {args.profile} profile; produced by\n"
                  f"passmd ledger --profile {args.profile} --write-baseline {args.write_baseline}")
        try:
            ledger.write_baseline(evaluated, args.write_baseline, header=header)
        except OSError as exc:
            raise OutputError(f"cannot write --write-baseline {args.write_baseline}: "
                              f"{exc.strerror or exc}") from exc
    counts = {s: int((evaluated["status"] == s).sum()) for s in STATUSES}
    if args.json:
        _emit_json({"command": "ledger", "profile": args.profile, "summary": ledger_views.summary(evaluated),
                    "counts": counts, "claims": ledger.records(evaluated)}, out)
        return 0
    out.write(f"passmd ledger — profile {args.profile}: {ledger_views.summary(evaluated)}\n")
    for row in evaluated.itertuples():
        basis = " (closed form)" if row.basis == "closed form" else ""
        out.write(f"\n{row.claim}: {row.status}{basis}\n  {row.verdict}\n")
        for item in (e for e in row.evidence.split(" | ") if e):
            out.write(f"  - {item}\n")
    return 0


def _cmd_figure(args, out) -> int:
    from passmd import experiments, provenance

    names = experiments.figure_names()
    if args.name == "list":
        if args.json:
            _emit_json({"command": "figure", "figures": names}, out)
        else:
            for name in names:
                out.write(f"{name}  {experiments.figure_spec(name).title}\n")
            if not names:
                out.write("no figure is available\n")
        return 0
    if not re.fullmatch(r"[a-z0-9_]+", args.name):
        raise UsageError(f"figure {args.name!r} is not a figure name: a panel such as fig5a, or 'list' "
                         f"(available: {', '.join(names)})")
    if args.name not in names:
        known = ", ".join(names) if names else "none"
        raise NotAvailableError(f"figure {args.name!r} is {NOT_AVAILABLE} (available: {known})")
    _check_sweep_options(args)
    if not args.out.strip():
        raise UsageError(f"--out = {args.out!r} is not a directory name "
                         "(use --out . for the working directory)")
    if Path(args.out).exists() and not Path(args.out).is_dir():
        raise OutputError(f"cannot write to --out {args.out}: it is not a directory")
    with _sweep_environment(args):
        data = experiments.figure_data(args.name, args.profile)
    target = Path(args.out)
    csv_path, png_path = target / f"{args.name}.csv", target / f"{args.name}.png"
    try:
        target.mkdir(parents=True, exist_ok=True)
        def _write_csv(tmp):  # '#' lines: version, commit, profile
            with open(tmp, "w", encoding="utf-8", newline="") as fh:
                fh.write(provenance.csv_header(args.profile))
                data.to_csv(fh, index=False, lineterminator="\n")

        write_atomically(csv_path, _write_csv)
        fig = experiments.figure_plot(args.name, data)
        write_atomically(png_path, lambda tmp: fig.savefig(
            tmp, dpi=150, format="png", metadata={"Description": provenance.summary(args.profile)}))
    except OSError as exc:
        raise OutputError(f"cannot write to --out {args.out}: {exc.strerror or exc}") from exc
    pyplot = sys.modules.get("matplotlib.pyplot")
    if pyplot is not None:
        pyplot.close(fig)
    record = {"command": "figure", "name": args.name, "profile": args.profile, "rows": len(data),
              "columns": list(map(str, data.columns)), "csv": str(csv_path), "png": str(png_path)}
    if args.json:
        _emit_json(record, out)
    else:
        out.write(f"{args.name} ({args.profile}): {len(data)} rows -> {csv_path}, {png_path}\n")
    return 0


# --------------------------------------------------------------------------------------
# Parser
# --------------------------------------------------------------------------------------

_DEFAULT_FREQUENCY = 100.0
_AMPLITUDE = _Quantity("--amplitude", "nm", "A", "actuation amplitude",
                       "the full stroke, --full-stroke-amplitude", 0.0, False)
_FREQUENCY = _Quantity("--frequency", "kHz", "f", "driving frequency", _fmt(_DEFAULT_FREQUENCY, "kHz"),
                       plausible="frequency")
_NORMAL_FORCE = _Quantity("--normal-force", "N", "F_N", "normal force on the contact",
                          _fmt(_DEFAULT.preload, "N"), plausible="preload")
# defaults of the book's critical-amplitude search (passmd.experiments.critical_amplitude)
_DEFAULT_STEADY_PERIODS = 10
_DEFAULT_TOLERANCE = 0.1e-9
_THRESHOLD = _Quantity("--threshold", "nm", "S", "steady protocol: a step counts when the last step "
                       "exceeds this", "0.5 nm")
_TOLERANCE = _Quantity("--tolerance", "nm", "W", "stop when the bracket is narrower than this", "0.1 nm")

_JSON_HELP = "print one JSON object (SI units) instead (default: off)"
_RUN_KEYS = """\
--json keys (SI units): final_position_m, settled_positions_m, step_sizes_m,
back_steps_m, mean_velocity_m_per_s (>= 2 periods), periods, frequency_Hz, amplitude_m,
integrator_steps and the integrator's step sizes (keys ending in _time_step_s), wall_time_s, waveform,
flyback, drive{...}"""


def _add_simulation_options(parser, default_periods: int) -> None:
    group = parser.add_argument_group("waveform and simulation")
    group.add_argument("--waveform", choices=("sawtooth", "optimized"), default="sawtooth",
                       help="driving waveform: the standard saw-tooth or the optimized waveform of Eq. 15, "
                            "designed from the drive's own saw-tooth response (default: sawtooth)")
    _AMPLITUDE.add(group)
    _FREQUENCY.add(group)
    group.add_argument("--periods", type=int, default=default_periods, metavar="N",
                       help=f"number of driving periods (default: {default_periods})")
    group.add_argument("--flyback", choices=("slew", "fixed"), default="slew",
                       help="fly-back duration: slew-rate limited (A/A_max · V_pp/SR) or the fixed "
                            "full-stroke time (default: slew)")
    group.add_argument("--springs", type=int, default=None, metavar="N",
                       help="discrete MDR contacts with N springs (default: exact contact, N → ∞)")


def _add_output_options(parser) -> None:
    group = parser.add_argument_group("output")
    group.add_argument("--json", action="store_true", help=_JSON_HELP)
    group.add_argument("--csv", metavar="FILE",
                       help="write the time series to FILE (CSV, SI units) (default: none)")
    group.add_argument("--plot", metavar="FILE",
                       help="plot piezo and runner position to FILE (PNG) (default: none)")
    group.add_argument("--max-points", type=int, default=20000, metavar="N",
                       help="samples of the recorded time series (default: 20000)")


def _add_sweep_options(parser) -> None:
    """Options of the commands that run figure sweeps (``figure``, ``ledger``); see passmd.sweep."""
    group = parser.add_argument_group("sweep execution")
    group.add_argument("--executor", choices=("process", "serial", "dask"), default=None,
                       help="process pool, in this process, or Dask (default: process, or dask with "
                            "--scheduler)")
    group.add_argument("--scheduler", metavar="ADDRESS", default=None,
                       help="Dask scheduler, e.g. tcp://10.0.0.5:8786 (default: none)")
    group.add_argument("--workers", type=int, default=None, metavar="N",
                       help="worker processes for process/local Dask (default: all cores)")
    group.add_argument("--cache-dir", metavar="DIR",
                       help=f"cache directory (default: ${CACHE_DIR_ENV} or ./{DEFAULT_CACHE_DIR})")


def make_parser() -> argparse.ArgumentParser:
    """The ``passmd`` argument parser (all subcommands)."""
    parser = _Parser(
        prog=PROG,
        formatter_class=_Formatter,
        description=DESCRIPTION,
        epilog="Exit status: 0 ok, 2 usage error, 1 failed run. 'passmd COMMAND --help' for options.",
    )
    parser.add_argument("--version", action="version", version=f"passmd {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    def command(name, help_text, epilog):
        return sub.add_parser(name, help=help_text, description=help_text, epilog=epilog,
                              formatter_class=_Formatter)

    p = command("theory", "closed forms of a drive configuration (Eqs. 1, 4, 7–14)", textwrap.dedent("""\
        --json keys (SI units): E_star_Pa, G_star_Pa, normal_force_N, contact_radius_m,
        indentation_m, tangential_stiffness_N_per_m, presliding_m, actuator_deformation_m
        (per side: [side 1, side 2] for six contacts), critical_amplitude_rigid_m,
        critical_amplitude_flexible_m, analytic_critical_amplitude_m (for --actuator),
        runner_frequency_Hz, actuator_natural_frequency_Hz, drive{...}"""))
    _add_drive_options(p)
    p.add_argument("--json", action="store_true", help=_JSON_HELP)
    p.set_defaults(handler=_cmd_theory)

    p = command("critical-amplitude", "simulated and analytic critical amplitude A_c", textwrap.dedent("""\
        The simulated A_c comes from the critical-amplitude chapters' search
        (passmd.experiments.critical_amplitude): bisection on [0, A_max] with one of two
        protocols, reporting its final bracket. steady: the last step of a run of
        --periods saw-tooth periods from rest exceeds --threshold; first: every contact
        slides fully in the first fly-back from virgin contacts.

        --json keys (SI units): critical_amplitude_m (null if none up to A_max),
        bracket_m, analytic_critical_amplitude_m, critical_amplitude_rigid_m,
        critical_amplitude_flexible_m, protocol, threshold_m, tolerance_m, frequency_Hz,
        periods, flyback, simulations, wall_time_s, drive{...}"""))
    _add_drive_options(p)
    group = p.add_argument_group("search")
    group.add_argument("--protocol", choices=("steady", "first"), default="steady",
                       help="steady-state A_c or first-fly-back onset (default: steady)")
    _FREQUENCY.add(group)
    group.add_argument("--periods", type=int, default=_DEFAULT_STEADY_PERIODS, metavar="N",
                       help=f"periods of a steady-state run (default: {_DEFAULT_STEADY_PERIODS})")
    _THRESHOLD.add(group)
    _TOLERANCE.add(group)
    group.add_argument("--flyback", choices=("slew", "fixed"), default="slew",
                       help="fly-back duration rule (default: slew)")
    group.add_argument("--analytic-only", action="store_true", help="skip the simulation (default: off)")
    p.add_argument("--json", action="store_true", help=_JSON_HELP)
    p.set_defaults(handler=_cmd_critical_amplitude)

    p = command("run", "one simulation of a driving waveform from rest", _RUN_KEYS +
                ", generated_force_N (with --load-cell)")
    _add_drive_options(p)
    _add_simulation_options(p, default_periods=3)
    p.add_argument("--load-cell", action="store_true",
                   help="the runner pushes against the load cell (default: off, free runner)")
    _add_output_options(p)
    p.set_defaults(handler=_cmd_run)

    p = command("force", "generated force against the load cell at stall (Section 4.2)", textwrap.dedent("""\
        Runs the saw-tooth from rest with the load cell at its free length and lengthens
        the run (--periods, doubling up to --max-periods) until the force-generation
        chapter's stall criterion holds; reports whether it did.

        --json keys (SI units): generated_force_N (k times the mean runner position over the
        last period), converged, periods, periods_simulated, remaining_force_N,
        force_spread_N, mean_friction_N, piezo_mean_force_N, last_step_m,
        net_displacement_m, wall_time_s, cpu_time_s, amplitude_m, frequency_Hz, drive{...}"""))
    _add_drive_options(p)
    _add_simulation_options(p, default_periods=64)
    p.add_argument("--max-periods", type=int, default=4096, metavar="N",
                   help="longest run before a point is reported as not stalled (default: 4096)")
    _add_output_options(p)
    p.set_defaults(handler=_cmd_force)

    p = command("contact", "tangential force of one MDR contact along a displacement path (Eqs. 4–7)",
                textwrap.dedent("""\
        The path is a comma-separated list of displacements u = x_a − x_r (hemisphere
        minus runner), visited in turn from a virgin contact at u = 0; the force T acts
        on the runner. Example: --path 0nm,30nm,-10nm,45nm

        --json keys (SI units): displacement_m, force_N, model, springs, normal_force_N,
        hemisphere_radius_m, friction_coefficient, E_star_Pa, G_star_Pa, sliding_force_N,
        presliding_m, contact_radius_m"""))
    group = p.add_argument_group("contact")
    _NORMAL_FORCE.add(group)
    group.add_argument("--path", metavar="U1,U2,...",
                       help="displacements to visit [nm] (default: none, required)")
    group.add_argument("--springs", type=int, default=None, metavar="N",
                       help="discrete MDR model with N springs (default: exact, N → ∞)")
    _add_drive_options(p, contact_only=True)
    p.add_argument("--json", action="store_true", help=_JSON_HELP)
    p.set_defaults(handler=_cmd_contact)

    p = command("figure", "one paper figure's data (CSV) and image (PNG), as the book makes them",
                textwrap.dedent(f"""\
        'passmd figure list' lists the panels; any other name is refused. Sweeps are
        cached in ./{DEFAULT_CACHE_DIR}/ (or ${CACHE_DIR_ENV}); see 'passmd cache --help'.

        NAME.csv starts with '#' lines naming the passmd version, git commit and profile
        (read it with pandas.read_csv(path, comment="#")); NAME.png carries the same in
        its Description metadata.

        --json keys: name, profile, rows, columns, csv, png (paths written)"""))
    p.add_argument("name", metavar="NAME",
                   help="figure panel, e.g. fig5a, or 'list' (default: none, required)")
    p.add_argument("--profile", choices=("quick", "paper"), default="paper",
                   help="resolution: quick (CI) or paper (the paper's grids) (default: paper)")
    p.add_argument("--out", metavar="DIR", default=".",
                   help="directory for NAME.csv and NAME.png (default: .)")
    _add_sweep_options(p)
    p.add_argument("--json", action="store_true", help=_JSON_HELP)
    p.set_defaults(handler=_cmd_figure)

    p = command("cache", "the on-disk simulation cache: summary, empty it, or prune old entries",
                textwrap.dedent(f"""\
        info: entries (of the current code and of older code versions), size, entries per
        function. clear: remove every entry. prune: remove entries of other code versions
        (their code fingerprint differs, so they can never be served), unreadable entries
        and leftovers. Entries are checksummed data (JSON header + raw array bytes), never
        code; see passmd.cache for the format. Directory: ${CACHE_DIR_ENV} or ./{DEFAULT_CACHE_DIR}.

        --json keys: action, directory, and entries, bytes, current_code, other_code,
        unreadable, leftovers, functions (info) or removed (clear, prune)"""))
    p.add_argument("action", choices=("info", "clear", "prune"), help="what to do (default: none, required)")
    p.add_argument("--cache-dir", metavar="DIR",
                   help=f"cache directory (default: ${CACHE_DIR_ENV} or ./{DEFAULT_CACHE_DIR})")
    p.add_argument("--json", action="store_true", help=_JSON_HELP)
    p.set_defaults(handler=_cmd_cache)

    p = command("ledger", "the replication ledger: every claim's computed category and evidence",
                textwrap.dedent(f"""\
        Computes (or reads from the cache the book uses, ./{DEFAULT_CACHE_DIR}/ or ${CACHE_DIR_ENV})
        every figure's results at --profile and evaluates every claim of
        passmd/data/reference/claims.csv over the declared readings of passmd.readings.

        --json keys: profile, summary, counts{{category: n}}, claims[{{claim, category, basis,
        verdict, evidence[], reason, depends_on[], readings{{reading: state}}, fraction_holds,
        best_reading, tolerance, check, paper_<SI unit>, ours_<SI unit>, ours_text,
        abs_deviation_<SI unit>, rel_deviation (fraction)}}]"""))
    p.add_argument("--profile", choices=("quick", "paper"), default="quick",
                   help="resolution: quick (CI) or paper (the paper's grids) (default: quick)")
    p.add_argument("--write-baseline", metavar="CSV", default=None,
                   help="also write the categories as a baseline CSV (default: none)")
    _add_sweep_options(p)
    p.add_argument("--json", action="store_true", help=_JSON_HELP)
    p.set_defaults(handler=_cmd_ledger)
    return parser


def main(argv=None, out=None) -> int:
    """Run the command line; return the exit status (0 ok, 2 usage error, 1 failed run).

    130 on Ctrl-C, 141 when standard output was closed by its reader (nothing printed).
    """
    to_stdout = out is None
    for stream in (sys.stdout, sys.stderr):
        use_ascii_fallback(stream)
    out = Out(sys.stdout if out is None else out)
    parser = make_parser()
    try:
        args = parser.parse_args(argv)
    except BrokenPipeError:  # --help piped into head
        silence_stdout()
        return 141
    except OSError as err:  # --help > /dev/full
        silence_stdout()
        sys.stderr.write(f"{PROG}: error: cannot write the output: {err.strerror or err}\n")
        return 1
    except SystemExit as exc:  # --help, --version: what argparse printed must reach the file
        if exc.code == 0 and to_stdout:
            try:
                sys.stdout.flush()
            except BrokenPipeError:
                silence_stdout()
                return 141
            except OSError as err:
                silence_stdout()
                sys.stderr.write(f"{PROG}: error: cannot write the output: {err.strerror or err}\n")
                return 1
        raise
    prog = f"{PROG} {args.command}"
    with warnings.catch_warnings():
        # cache problems: one line each; numerical warnings: the results are checked instead
        warnings.showwarning = one_line_warnings(prog)
        warnings.simplefilter("always", CacheWarning)
        warnings.simplefilter("ignore", RuntimeWarning)
        with np.errstate(all="ignore"):
            return _dispatch(args, out, prog, to_stdout)


def _dispatch(args, out: Out, prog: str, to_stdout: bool) -> int:
    try:
        status = args.handler(args, out)
        out.flush()
        return status
    except PipeClosed:
        if to_stdout:
            silence_stdout()
        return 141
    except StdoutError as exc:
        if to_stdout:
            silence_stdout()
        sys.stderr.write(f"{prog}: error: cannot write the output: {exc.strerror or exc}\n")
        return 1
    except (UsageError, QuantityError) as exc:
        sys.stderr.write(f"{prog}: error: {exc}\n")
        return 2
    except OutputError as exc:
        sys.stderr.write(f"{prog}: error: {exc}\n")
        return 1
    except KeyboardInterrupt:
        kept = " (finished points are kept in the cache)" if args.command == "figure" else ""
        sys.stderr.write(f"{prog}: interrupted{kept}\n")
        # exit at once: the interpreter's exit-time collection of numba's object graph takes ≈ 1 s
        gc.freeze()
        return 130
    except ValueError as exc:  # the package's input checks (passmd._validation)
        sys.stderr.write(f"{prog}: error: {exc}\n")
        return 2
    except (ResultError, MissingDependencyError) as exc:
        sys.stderr.write(f"{prog}: error: {exc}\n")
        return 1
    except RuntimeError as exc:  # passmd.dynamics.SimulationError and other failed runs
        sys.stderr.write(f"{prog}: error: run failed: {exc}\n")
        return 1
    except ModuleNotFoundError as exc:
        extra = OPTIONAL_EXTRAS.get((exc.name or "").split(".")[0])
        hint = f"pip install 'passmd[{extra}]'" if extra else "reinstall passmd with its dependencies"
        sys.stderr.write(f"{prog}: error: the package {exc.name!r} is not installed: {hint}\n")
        return 1
    except MemoryError:
        sys.stderr.write(f"{prog}: error: not enough memory for this run (lower --max-points or the "
                         "number of periods)\n")
        return 1
    except OSError as exc:  # e.g. the cache or an output directory vanished under the run
        where = f" ({exc.filename})" if getattr(exc, "filename", None) else ""
        sys.stderr.write(f"{prog}: error: {exc.strerror or exc}{where}\n")
        return 1
    except Exception as exc:  # a bug: one line, the traceback on request
        if os.environ.get("PASSMD_DEBUG"):
            raise
        sys.stderr.write(f"{prog}: error: internal error: {type(exc).__name__}: {exc} "
                         "(set PASSMD_DEBUG=1 for the traceback)\n")
        return 1


if __name__ == "__main__":
    sys.exit(main())
