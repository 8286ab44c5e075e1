"""The keys a drive file may hold (:data:`~passmd.model.drive_keys.DRIVE_KEYS`): each with its SI
unit, display unit, symbol, meaning and the source of its default; and the drive files the package
ships (the book's worked example, the ledger's joint reading). Read by
:mod:`passmd.model.drive_file`, written by :mod:`passmd.model.drive_writer`."""

from __future__ import annotations

import os
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from passmd.model.parameters import PLAUSIBLE_RANGES, Drive
from passmd.model.tables import ACTUATOR_DAMPING_RATIO

__all__ = ["ACTUATOR_DYNAMICS", "CONTACT_PRESETS", "DRIVE_KEYS", "EXAMPLE_DRIVE_FILE", "GROUP_KEYS",
           "JOINT_READING_FILE", "SI_UNITS", "DriveKey", "drive_value"]


@dataclass(frozen=True)
class DriveKey:
    """One key of a drive file: its SI unit, display unit, symbol, meaning and default's source."""

    key: str
    unit: str  # SI unit of a bare number ("" for plain numbers, "str"/"bool"/"choice" for others)
    display: str  # unit the template and ``drive show`` write the value in
    symbol: str
    text: str
    source: str  # where the default comes from
    plausible: str | None = None  # key of PLAUSIBLE_RANGES; None: the key's own (a material's for both)
    choices: tuple = ()

    def __post_init__(self):
        own = self.key.replace("hemisphere_material.", "material.").replace("runner_material.", "material.")
        object.__setattr__(self, "plausible", self.plausible or (own if own in PLAUSIBLE_RANGES else None))


_DEFAULT = Drive()
#: The worked example of the book's chapter "Design your own drive" (package data: an installed wheel
#: has it; ``passmd drive template --example`` prints it).
EXAMPLE_DRIVE_FILE = Path(os.fspath(resources.files("passmd") / "data" / "drives"
                                    / "example_drive.toml"))
#: The paper's drive under the replication ledger's joint reading, paper profile (package data;
#: ``passmd drive template --joint-reading`` prints it, :mod:`passmd.ledger.joint_drive` writes it).
JOINT_READING_FILE = EXAMPLE_DRIVE_FILE.with_name("joint_reading.toml")
#: The paper's two contact arrangements, by name (Section 4.1).
CONTACT_PRESETS = {"one": 1, "paper-six": 6}

#: Every key a drive file may hold, by its dotted name (the Drive field path).
DRIVE_KEYS: dict[str, DriveKey] = {k.key: k for k in (
    DriveKey("contacts", "choice", "", "n", "contact arrangement: \"one\" (one contact) or \"paper-six\" "
             "(two contacts on one side, four on the other)", "Section 4.1", choices=tuple(CONTACT_PRESETS)),
    DriveKey("contact_groups", "groups", "", "n_g, side, α, F_N, R", "any other arrangement: "
             "[[contact_groups]] tables of count, side (1 or 2), contact_angle (default 90 deg, flat), "
             "radius (default: the drive's) and, optionally, load_share (F_N / F_p) or normal_force; each "
             "side's Σ n F_N sin α must balance the preload (Eq. 1)", "instead of contacts"),
    DriveKey("actuator_model", "choice", "", "–", "\"flexible\" (mass–spring–damper) or \"rigid\" actuators",
             "Section 3.1", choices=("flexible", "rigid")),
    DriveKey("hemisphere_radius", "m", "mm", "R", "radius of the hemispheres", "Table 1"),
    DriveKey("preload", "N", "N", "F_p", "preload", "Section 4"),
    DriveKey("friction_coefficient", "", "", "μ", "friction coefficient", "Table 1; Section 4.2"),
    DriveKey("runner_mass", "kg", "g", "m_r", "runner mass", "Table 1"),
    DriveKey("load_cell_stiffness", "N/m", "N/m", "k", "load cell stiffness", "Table 1"),
    DriveKey("load_cell", "bool", "", "–", "the runner pushes against the load cell", "Section 4.2"),
    DriveKey("guide_rail", "bool", "", "–", "a rail takes the sideways force of contacts at α < 90° that "
             "no placement on the groove's two flanks cancels (else such a guide is refused)", "default"),
    DriveKey("allow_extrapolation", "bool", "", "–", "accept values outside the plausible ranges "
             "(soft limits only)", "default"),
    DriveKey("hemisphere_material.name", "str", "", "–", "name of the hemispheres' material", "Table 1"),
    DriveKey("hemisphere_material.youngs_modulus", "Pa", "GPa", "E_1", "Young's modulus of the hemispheres",
             "Table 1"),
    DriveKey("hemisphere_material.poissons_ratio", "", "", "ν_1", "Poisson's ratio of the hemispheres",
             "Table 1"),
    DriveKey("runner_material.name", "str", "", "–", "name of the runner's material", "Table 1"),
    DriveKey("runner_material.youngs_modulus", "Pa", "GPa", "E_2", "Young's modulus of the runner",
             "Table 1"),
    DriveKey("runner_material.poissons_ratio", "", "", "ν_2", "Poisson's ratio of the runner", "Table 1"),
    DriveKey("actuator.stiffness", "N/m", "N/m", "k_p", "actuator stiffness", "Table 2"),
    DriveKey("actuator.mass", "kg", "kg", "m_a", "actuator mass", "Table 2 (as printed)"),
    DriveKey("actuator.viscosity", "kg/s", "kg/s", "c_p", "actuator viscosity (or give damping_ratio)",
             f"derived from ζ = {ACTUATOR_DAMPING_RATIO:g}"),
    DriveKey("actuator.damping_ratio", "", "", "ζ", "damping ratio of the bare actuator, "
             "c_p = 2ζ√(k_p m_a) (or give viscosity)", "assumed (Table 2's column is lost)"),
    DriveKey("actuator.full_stroke_amplitude", "m", "nm", "A_max", "actuation amplitude at the full voltage",
             "Table 2"),
    DriveKey("amplifier.peak_to_peak_voltage", "V", "V", "V_pp", "amplifier peak-to-peak voltage",
             "Section 2"),
    DriveKey("amplifier.slew_rate", "V/s", "V/us", "SR", "amplifier slew rate", "Section 2"),
    DriveKey("amplifier.flyback", "flyback", "us", "t_fb", "fly-back of the saw-tooth: \"slew\" (slew-rate "
             "limited, (A/A_max)·V_pp/SR), \"fixed\" (the full-stroke V_pp/SR at every amplitude) or a "
             "stated time (\"1.5 us\"; a bare number is s)", "assumed (Section 2 gives V_pp and SR)"),
)}

#: The SI units a bare number of a drive file is read in.
SI_UNITS = {"m", "kg", "s", "N", "N/m", "kg/s", "Pa", "V", "V/s", "Hz", ""}
#: Keys of the actuators' dynamics (Eq. 3), which ideally rigid actuators do not have.
ACTUATOR_DYNAMICS = ("actuator.stiffness", "actuator.mass", "actuator.viscosity", "actuator.damping_ratio")
#: The keys of a ``[[contact_groups]]`` table, in the order a drive file lists them, with their SI unit
#: ("angle": read by :func:`passmd.runtime.units.parse_angle`).
GROUP_KEYS = {"count": "", "side": "", "contact_angle": "angle", "load_share": "", "normal_force": "N",
              "radius": "m"}


def drive_value(drive: Drive, key: str):
    """The value of a drive-file key in ``drive`` (``contacts`` by preset name)."""
    if key == "contacts":
        return {1: "one", 6: "paper-six"}[drive.contacts] if not drive.contact_groups else drive.contacts
    if key == "contact_groups":
        return [{name: value for name, value in vars(g).items() if value is not None}
                for g in drive.contact_groups]
    if key == "actuator.damping_ratio":
        return drive.actuator.damping_ratio
    value = drive
    for part in key.split("."):
        value = getattr(value, part)
    return value
