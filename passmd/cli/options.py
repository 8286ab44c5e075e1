"""The commands' options: quantities with units, and the option groups the commands share.

A :class:`Quantity` is one option that takes a number with a unit (``0.4N``, ``1mm``,
``202nm``). A bare number is SI, as in a drive file: an option whose help shows another unit
(mm, nm, kHz, g, GPa, V/us) refuses it and asks for the unit
(:func:`passmd.runtime.units.parse_quantity`).
Its default text is computed from the defaults it stands for (:data:`DEFAULT_DRIVE`,
:data:`passmd.model.defaults.PROTOCOL`), never retyped.
"""

from __future__ import annotations

import argparse
import re
from dataclasses import dataclass

from passmd.cli.output import JSON_HELP, fmt
from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import PLAUSIBLE_RANGES, Drive
from passmd.model.tables import ACTUATOR_DAMPING_RATIO
from passmd.runtime.cache import describe_default_cache_dir
from passmd.runtime.config import ENVIRONMENT, MAX_WORKERS, WORKERS_PER_CORE
from passmd.runtime.units import parse_quantity, si_factor, to_display
from passmd.runtime.validation import InputError, check_range

__all__ = ["ACTUATOR_DYNAMICS", "AMPLITUDE", "CACHE_DIR_HELP", "DEFAULT_DRIVE", "DRIVE_QUANTITIES",
           "FREQUENCY", "MATERIAL_FLAGS", "NORMAL_FORCE", "OPTION_FOR", "QUANTITIES", "THRESHOLD",
           "TOLERANCE", "DirectoryPath", "FilePath", "Quantity", "add_drive_options",
           "add_output_options", "add_overwrite_option", "add_simulation_options", "add_sweep_options"]

#: The drive every option replaces a part of (Tables 1–2 at R = 1 mm, F_p = 0.4 N, μ = 0.2).
DEFAULT_DRIVE = Drive()

@dataclass(frozen=True)
class Quantity:
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
    #: key of passmd.model.parameters.PLAUSIBLE_RANGES checked instead of lower/upper
    plausible: str | None = None
    #: the Drive field the option sets, dotted for a part (``"actuator.mass"``); None: not a drive field
    field: str | None = None

    @property
    def dest(self) -> str:
        return self.flag.lstrip("-").replace("-", "_")

    def add(self, parser) -> None:
        unit = f"[{self.unit}]" if si_factor(self.unit) == 1.0 else f"[{self.unit}; unit required]"
        unit = unit if self.unit else "[-]"
        parser.add_argument(self.flag, metavar=self.symbol, default=None,
                            help=f"{self.text} {unit} (default: {self.default})")

    def parse(self, args) -> float | None:
        """SI value of the option, ``None`` if not given; range checked in display units."""
        raw = getattr(args, self.dest)
        if raw is None:
            return None
        value = parse_quantity(raw, self.unit, name=self.flag)
        try:
            if self.plausible is not None:
                scale = si_factor(self.unit)
                PLAUSIBLE_RANGES[self.plausible].check(
                    self.flag, value, allow_extrapolation=bool(getattr(args, "allow_extrapolation", False)),
                    flag=self.flag, scale=scale, unit=self.unit, hint="--allow-extrapolation")
                return value
            shown = to_display(value, self.unit)  # the parsed value itself, in the unit shown
            check_range(self.flag, shown, self.lower, self.upper, lower_open=self.lower_open,
                        upper_open=self.upper_open, unit=self.unit or "–")
        except InputError as exc:
            raise _as_typed(exc, self.flag, str(raw), value) from None
        return value

    def parse_or(self, args, default: float) -> float:
        """SI value of the option, ``default`` if not given."""
        value = self.parse(args)
        return default if value is None else value


def _as_typed(exc: InputError, flag: str, typed: str, value: float) -> InputError:
    """``exc`` naming the value as the user typed it (``1mHz``, not its display ``1e-06 kHz``; ``1e-400``,
    not the 0 it reads as), the parsed value beside it where the two differ."""
    head = f"{flag} = "
    text = str(exc)
    if not text.startswith(head) or " is out of range" not in text:
        return exc
    shown = text[len(head):text.index(" is out of range")]
    number = re.match(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*$", typed)
    if value == 0.0 and number and float(number.group(1).replace("e", "E").split("E")[0] or 0) != 0.0:
        note = " (below the smallest number a double holds: it reads as 0)"
    elif number and number.group(2) and " " in shown and shown.partition(" ")[2] != number.group(2):
        # typed in another unit than the one shown (1mHz against kHz)
        note = f" (= {shown})"
    else:
        return exc  # shown in the unit typed already
    return InputError(f"{head}{typed}{note}{text[text.index(' is out of range'):]}", name=exc.name,
                      value=exc.value, unit=exc.unit, limits=exc.limits, why=exc.why, soft=exc.soft)


_ACT = DEFAULT_DRIVE.actuator
_AT_R = f"at {fmt(DEFAULT_DRIVE.hemisphere_radius, 'mm')}"
_HEMISPHERE, _RUNNER = DEFAULT_DRIVE.hemisphere_material, DEFAULT_DRIVE.runner_material
_AMPLIFIER = DEFAULT_DRIVE.amplifier
DRIVE_QUANTITIES = (
    Quantity("--preload", "N", "F_p", "preload", fmt(DEFAULT_DRIVE.preload, "N"), plausible="preload",
             field="preload"),
    Quantity("--radius", "mm", "R", "hemisphere radius", fmt(DEFAULT_DRIVE.hemisphere_radius, "mm"),
             plausible="hemisphere_radius", field="hemisphere_radius"),
    Quantity("--mu", "", "mu", "friction coefficient", f"{DEFAULT_DRIVE.friction_coefficient:g}",
             plausible="friction_coefficient", field="friction_coefficient"),
    Quantity("--runner-mass", "g", "m_r", "runner mass", fmt(DEFAULT_DRIVE.runner_mass, "g"),
             plausible="runner_mass", field="runner_mass"),
    Quantity("--load-cell-stiffness", "N/m", "k", "load cell stiffness",
             fmt(DEFAULT_DRIVE.load_cell_stiffness, "N/m"), plausible="load_cell_stiffness",
             field="load_cell_stiffness"),
    Quantity("--hemisphere-modulus", "GPa", "E_1", "Young's modulus of the hemispheres",
             fmt(_HEMISPHERE.youngs_modulus, "GPa") + f" ({_HEMISPHERE.name})",
             plausible="material.youngs_modulus", field="hemisphere_material.youngs_modulus"),
    Quantity("--hemisphere-poisson", "", "nu_1", "Poisson's ratio of the hemispheres",
             f"{_HEMISPHERE.poissons_ratio:g}", -1.0, True, 0.5, True,
             field="hemisphere_material.poissons_ratio"),
    Quantity("--runner-modulus", "GPa", "E_2", "Young's modulus of the runner",
             fmt(_RUNNER.youngs_modulus, "GPa") + f" ({_RUNNER.name})",
             plausible="material.youngs_modulus", field="runner_material.youngs_modulus"),
    Quantity("--runner-poisson", "", "nu_2", "Poisson's ratio of the runner",
             f"{_RUNNER.poissons_ratio:g}", -1.0, True, 0.5, True, field="runner_material.poissons_ratio"),
    Quantity("--actuator-stiffness", "N/m", "k_p", "actuator stiffness",
             f"Table 2 for --radius, {fmt(_ACT.stiffness, 'N/m')} {_AT_R}", plausible="actuator.stiffness",
             field="actuator.stiffness"),
    Quantity("--actuator-mass", "g", "m_a", "actuator mass",
             f"Table 2 for --radius, {fmt(_ACT.mass, 'g')} {_AT_R}", plausible="actuator.mass",
             field="actuator.mass"),
    Quantity("--actuator-viscosity", "kg/s", "c_p", "actuator viscosity",
             f"2ζ√(k_p m_a) with ζ = {ACTUATOR_DAMPING_RATIO:g}, {fmt(_ACT.viscosity, 'kg/s')} {_AT_R}",
             0.0, False, field="actuator.viscosity"),
    Quantity("--damping-ratio", "", "zeta", "damping ratio of the bare actuator, c_p = 2ζ√(k_p m_a) (or give "
             "--actuator-viscosity)", f"{ACTUATOR_DAMPING_RATIO:g}", plausible="actuator.damping_ratio",
             field="actuator.damping_ratio"),
    Quantity("--full-stroke-amplitude", "nm", "A_max", "actuation amplitude at the full voltage",
             f"Table 2 for --radius, {fmt(_ACT.full_stroke_amplitude, 'nm')} {_AT_R}",
             plausible="actuator.full_stroke_amplitude", field="actuator.full_stroke_amplitude"),
    Quantity("--amplifier-voltage", "V", "V_pp", "amplifier peak-to-peak voltage",
             fmt(_AMPLIFIER.peak_to_peak_voltage, "V"), plausible="amplifier.peak_to_peak_voltage",
             field="amplifier.peak_to_peak_voltage"),
    Quantity("--slew-rate", "V/us", "SR", "amplifier slew rate", fmt(_AMPLIFIER.slew_rate, "V/us"),
             plausible="amplifier.slew_rate", field="amplifier.slew_rate"),
)
#: Options of the actuators' dynamics, which rigid actuators do not have.
ACTUATOR_DYNAMICS = ("--actuator-stiffness", "--actuator-mass", "--actuator-viscosity", "--damping-ratio")
MATERIAL_FLAGS = ("--hemisphere-modulus", "--hemisphere-poisson", "--runner-modulus", "--runner-poisson")

AMPLITUDE = Quantity("--amplitude", "nm", "A", "actuation amplitude",
                     "the full stroke, --full-stroke-amplitude", 0.0, False)
FREQUENCY = Quantity("--frequency", "kHz", "f", "driving frequency", fmt(PROTOCOL.drive_frequency, "kHz"),
                     plausible="frequency")
NORMAL_FORCE = Quantity("--normal-force", "N", "F_N", "normal force on the contact",
                        fmt(DEFAULT_DRIVE.preload, "N"), plausible="preload")
THRESHOLD = Quantity("--threshold", "nm", "S", "steady protocol: a step counts when the last step "
                     "exceeds this", fmt(PROTOCOL.step_threshold, "nm"))
TOLERANCE = Quantity("--tolerance", "nm", "W", "stop when the bracket is narrower than this",
                     fmt(PROTOCOL.search_tolerance, "nm"))

#: Every option that takes a number with a unit, by flag.
QUANTITIES = {q.flag: q for q in (*DRIVE_QUANTITIES, AMPLITUDE, FREQUENCY, NORMAL_FORCE, THRESHOLD,
                                   TOLERANCE)}

#: The option that sets each input the package's checks name (``passmd.runtime.validation.InputError.name``):
#: the drive's fields (dotted for a part, as :class:`Quantity.field`), then the parameters of the
#: waveforms, contacts and protocols the commands pass their options to.
OPTION_FOR: dict[str, str] = {
    **{q.field: q.flag for q in DRIVE_QUANTITIES},
    "amplifier.flyback": "--flyback",
    "amplitude": AMPLITUDE.flag,
    "frequency": FREQUENCY.flag,
    "normal_force": NORMAL_FORCE.flag,
    "threshold": THRESHOLD.flag,
    "tolerance": TOLERANCE.flag,
    "periods": "--periods",
    "initial_periods": "--periods",
    "max_periods": "--max-periods",
    "springs": "--springs",
    "max_points": "--max-points",
}


class FilePath(argparse.Action):
    """A path option (``action=FilePath``): an empty or blank name is refused while parsing,
    before anything runs, naming the option as typed (``--csv = '' is not a file name``)."""

    kind = "file"

    def __call__(self, parser, namespace, values, option_string=None):
        if not values.strip():
            parser.error(f"{option_string or self.dest} = {values!r} is not a {self.kind} name")
        setattr(namespace, self.dest, values)


class DirectoryPath(FilePath):
    """A directory option: as :class:`FilePath` (``--out = '' is not a directory name``)."""

    kind = "directory"


CACHE_DIR_HELP = f"cache directory (default: ${ENVIRONMENT['cache_dir']}, else " \
                 f"{describe_default_cache_dir()})"


def add_drive_options(parser, *, contact_only: bool = False) -> None:
    """The drive's options (Tables 1–2, or a drive file); ``contact_only``: those of one contact.

    ``--drive FILE`` reads a drive file (:mod:`passmd.model.drive_file`); each option given replaces
    the file's value.
    """
    group = parser.add_argument_group("drive (Tables 1–2, or --drive FILE; a bare number is SI: options "
                                      "shown in another unit need the unit written)")
    group.add_argument("--drive", metavar="FILE", action=FilePath,
                       help="drive file (TOML, `passmd drive template` writes one); the options below "
                            "replace its values (default: the paper's drive)")
    if not contact_only:
        group.add_argument("--contacts", type=int, choices=(1, 6), default=None,
                           help="one-contact or the paper's six-contact model; any other arrangement: "
                                "[[contact_groups]] in a --drive file (default: the file's, else "
                                f"{DEFAULT_DRIVE.contacts})")
        group.add_argument("--actuator", choices=("rigid", "flexible"), default=None,
                           help="ideally rigid or mass–spring–damper actuators "
                                f"(default: {DEFAULT_DRIVE.actuator_model})")
    for q in DRIVE_QUANTITIES:
        if contact_only and q.flag not in ("--radius", "--mu", *MATERIAL_FLAGS):
            continue
        q.add(group)
    if not contact_only:
        group.add_argument("--flyback", metavar="RULE", default=None,
                           help="fly-back of the saw-tooth: slew (slew-rate limited, A/A_max · V_pp/SR), "
                                "fixed (the full-stroke V_pp/SR at every amplitude) or a stated time with "
                                "its unit, e.g. 1.5us (default: the drive file's, else "
                                f"{DEFAULT_DRIVE.amplifier.flyback})")
    group.add_argument("--allow-extrapolation", action="store_true",
                       help="accept parameters outside the plausible ranges around Tables 1–2 (soft limits; "
                            "hard limits, where the model breaks, stay) (default: off)")


def add_simulation_options(parser, default_periods: int) -> None:
    """Waveform, amplitude, frequency, periods and contact model of a run (the fly-back is the drive's)."""
    group = parser.add_argument_group("waveform and simulation")
    group.add_argument("--waveform", choices=("sawtooth", "optimized"), default="sawtooth",
                       help="driving waveform: the standard saw-tooth or the optimized waveform of Eq. 15, "
                            "designed from the drive's own saw-tooth response (default: sawtooth)")
    AMPLITUDE.add(group)
    FREQUENCY.add(group)
    group.add_argument("--periods", type=int, default=default_periods, metavar="N",
                       help=f"number of driving periods (default: {default_periods})")
    group.add_argument("--springs", type=int, default=None, metavar="N",
                       help="discrete MDR contacts with N springs (default: exact contact, N → ∞)")


OVERWRITE_HELP = ("replace output files that are already there, atomically (default: off: an output file "
                  "already there is refused before any work, and a new one is never put over a file)")


def add_overwrite_option(group) -> None:
    """--overwrite, on every command that writes files (:mod:`passmd.runtime.outputs`)."""
    group.add_argument("--overwrite", action="store_true", help=OVERWRITE_HELP)


def add_output_options(parser) -> None:
    """--json, and the time series' --csv, --plot, --overwrite and --max-points."""
    group = parser.add_argument_group("output")
    group.add_argument("--json", action="store_true", help=JSON_HELP)
    group.add_argument("--csv", metavar="FILE", action=FilePath,
                       help="write the time series to FILE (CSV, SI units) (default: none)")
    group.add_argument("--plot", metavar="FILE", action=FilePath,
                       help="plot piezo and runner position to FILE (PNG) (default: none)")
    add_overwrite_option(group)
    group.add_argument("--max-points", type=int, default=20000, metavar="N",
                       help="samples of the recorded time series (default: 20000)")


def add_sweep_options(parser) -> None:
    """Options of the commands that run figure sweeps (``figure``, ``ledger``); see passmd.runtime.sweep."""
    group = parser.add_argument_group("sweep execution")
    group.add_argument("--executor", choices=("process", "serial", "dask"), default=None,
                       help="process pool, in this process, or Dask (default: process, or dask with "
                            "--scheduler)")
    group.add_argument("--scheduler", metavar="ADDRESS", default=None,
                       help="Dask scheduler, e.g. tcp://10.0.0.5:8786 (default: none)")
    group.add_argument("--workers", type=int, default=None, metavar="N",
                       help=f"worker processes for process/local Dask, 1 to {MAX_WORKERS}; at most "
                            f"{WORKERS_PER_CORE} per usable core and one per point run (default: one per "
                            "usable core)")
    group.add_argument("--cache-dir", metavar="DIR", action=DirectoryPath, help=CACHE_DIR_HELP)
