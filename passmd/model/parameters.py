"""The whole drive: the :class:`~passmd.model.parameters.Drive` record, its contact arrangement and its
plausible ranges.

A :class:`Drive` gathers the geometry, preload, friction, masses, model choices and the parts of
:mod:`passmd.model.tables` (materials, Table 2 actuator, amplifier); its contacts are the paper's
one or six (Eq. 1) or any arrangement of :class:`ContactGroup` s, whose normal forces and
moduli the drive computes once (:attr:`Drive.contact_layout`, :attr:`Drive.contact_moduli`).
Every number of a drive is checked on construction against :data:`PLAUSIBLE_RANGES`: hard limits
where the model's physics breaks (positive quantities, a Hertz contact radius a <= R/10), soft
limits two decades around Tables 1–2 where it was checked, which ``allow_extrapolation`` lifts.
The library and the command line check against this one table. All quantities are SI;
:func:`paper_drive` gives the paper's drive for one of Table 2's radii.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import NamedTuple

import numpy as np

from passmd.model import arrangement
from passmd.model.arrangement import PAPER_SIX as PAPER_SIX
from passmd.model.arrangement import ContactGroup, group_normal_forces, preset_groups
from passmd.model.hertz import _require_normal, _shear, _youngs
from passmd.model.tables import (
    ACTUATOR_DAMPING_RATIO,
    RUBY,
    STEEL,
    TABLE2_RADII,
    Actuator,
    Amplifier,
    Assumption,
    Material,
    _meta,
    _table2_actuator,
)

# Amplifier, Material, STEEL, Assumption and MOLYBDENUM stay importable from here for the modules
# that still name this module for them (passmd.experiments.model_numerics.figures and
# passmd.experiments.driving_waveform.figures); they are documented in passmd.model.tables.
from passmd.model.tables import MOLYBDENUM as MOLYBDENUM
from passmd.runtime.validation import (
    InputError,
    check_choice,
    check_positive,
    check_range,
    format_number,
    shown,
)

__all__ = [
    "ASSUMPTIONS",
    "CONTACT_RADIUS_RATIO_LIMIT",
    "HERTZ_PRESSURE_LIMIT",
    "PLAUSIBLE_RANGES",
    "ContactGroup",
    "ContactLayout",
    "Drive",
    "PlausibleRange",
    "check_contact_plausible",
    "check_drive",
    "check_plausible",
    "paper_drive",
]


class ContactLayout(NamedTuple):
    """A drive's contact groups (Eq. 1), one entry per group, read-only arrays.

    One contact: ``([F_p], [1], [R])``; the paper's six: ``([F_N1, F_N2], [2, 4], [R, R])``;
    a drive with ``contact_groups``: one entry per :class:`~passmd.model.arrangement.ContactGroup`.
    """

    normal_forces: np.ndarray  # normal force per contact, N (Eq. 1)
    counts: np.ndarray  # contacts per group (float, as the kernels take it)
    radii: np.ndarray  # hemisphere radius of each group, m


@dataclass(frozen=True)
class Drive:
    """The whole drive: geometry, preload, materials, masses and model choices.

    Defaults reproduce the paper's R = 1 mm drive at F_p = 0.4 N with μ = 0.2
    (Table 1, Section 4.2) and flexible actuators, six contacts, no load cell.
    """

    hemisphere_radius: float = field(
        default=1.0e-3, metadata=_meta("R", "m", "Table 1")
    )  # radius of the ruby hemispheres
    preload: float = field(default=0.4, metadata=_meta("F_p", "N", "Section 4"))  # preload
    friction_coefficient: float = field(
        default=0.2, metadata=_meta("μ", "–", "Table 1; Section 4.2")
    )  # 0.2 (this paper) or 0.3 (earlier work)
    contacts: int = field(default=6, metadata=_meta("n", "–", "Section 4.1"))  # 1 or 6
    actuator_model: str = field(
        default="flexible", metadata=_meta("–", "–", "Section 3.1")
    )  # "rigid" or "flexible"
    runner_mass: float = field(default=3e-3, metadata=_meta("m_r", "kg", "Table 1"))  # m_r
    load_cell_stiffness: float = field(
        default=2.5e4, metadata=_meta("k", "N/m", "Table 1")
    )  # load cell spring k (used only when load_cell is True)
    load_cell: bool = field(
        default=False, metadata=_meta("–", "–", "Section 4.2")
    )  # runner pushes against the load cell
    hemisphere_material: Material = field(default=RUBY, metadata=_meta("E_1, ν_1", "", "Table 1"))
    runner_material: Material = field(default=STEEL, metadata=_meta("E_2, ν_2", "", "Table 1"))
    actuator: Actuator | None = field(
        default=None, metadata=_meta("k_p, m_a, c_p", "", "Table 2")
    )  # None: Table 2 actuator for hemisphere_radius
    amplifier: Amplifier = field(default_factory=Amplifier, metadata=_meta("", "", "Section 2"))
    #: Lift the soft limits of :data:`PLAUSIBLE_RANGES` (never the hard ones), for exploring.
    allow_extrapolation: bool = False
    #: Any other arrangement of contacts (:class:`~passmd.model.arrangement.ContactGroup` s: count,
    #: side, contact angle, radius, normal force); empty: the paper's arrangement ``contacts`` names
    #: (1 or 6). When given, ``contacts`` is their total count and each side's groups must balance
    #: the preload (Eq. 1, :func:`passmd.model.arrangement.check_balance`).
    contact_groups: tuple = ()
    #: The guide has a rail that takes the sideways force of contacts at α < 90° which no placement on
    #: the groove's flanks cancels (assumed to add no friction along the travel); without it such a
    #: drive is refused (:func:`passmd.model.arrangement.check_sides`).
    guide_rail: bool = False

    def __post_init__(self):
        if not isinstance(self.allow_extrapolation, bool):
            raise InputError(f"allow_extrapolation = {shown(self.allow_extrapolation)} is not allowed: "
                             "must be True or False", name="allow_extrapolation",
                             value=self.allow_extrapolation)
        # each number once, against its range (a hard limit > 0 and the plausible range)
        for name in ("hemisphere_radius", "preload", "friction_coefficient", "runner_mass",
                     "load_cell_stiffness"):
            PLAUSIBLE_RANGES[name].check(name, getattr(self, name),
                                         allow_extrapolation=self.allow_extrapolation)
        if not isinstance(self.guide_rail, bool):
            raise InputError(f"guide_rail = {shown(self.guide_rail)} is not allowed: must be True or False",
                             name="guide_rail", value=self.guide_rail)
        if not isinstance(self.contact_groups, tuple) or not all(
                isinstance(g, ContactGroup) for g in self.contact_groups):
            raise InputError(f"contact_groups = {shown(self.contact_groups)} is not allowed: must be a "
                             "tuple of ContactGroup", name="contact_groups", value=self.contact_groups)
        if self.contact_groups:
            object.__setattr__(self, "contacts", sum(g.count for g in self.contact_groups))
            arrangement.check_balance(self.preload, self.contact_groups)
            arrangement.check_sides(self.preload, self.contact_groups, guide_rail=self.guide_rail)
        elif not isinstance(self.contacts, (int, np.integer)) or isinstance(self.contacts, (bool, np.bool_)) \
                or self.contacts not in (1, 6):
            raise InputError(f"contacts = {shown(self.contacts)} is not allowed: must be one of 1, 6",
                             name="contacts", value=self.contacts)
        check_choice("actuator_model", self.actuator_model, ("rigid", "flexible"))
        if not isinstance(self.load_cell, bool):
            raise InputError(f"load_cell = {shown(self.load_cell)} is not allowed: must be True or False",
                             name="load_cell", value=self.load_cell)
        for name in ("hemisphere_material", "runner_material"):
            if not isinstance(getattr(self, name), Material):
                raise InputError(f"{name} = {shown(getattr(self, name))} is not a Material", name=name,
                                 value=getattr(self, name))
        if self.actuator is None:
            actuator = _table2_actuator(self.hemisphere_radius, ACTUATOR_DAMPING_RATIO)
            object.__setattr__(self, "actuator", actuator)
        elif not isinstance(self.actuator, Actuator):
            raise InputError(f"actuator = {shown(self.actuator)} is not an Actuator", name="actuator",
                             value=self.actuator)
        if not isinstance(self.amplifier, Amplifier):
            raise InputError(f"amplifier = {shown(self.amplifier)} is not an Amplifier", name="amplifier",
                             value=self.amplifier)
        if isinstance(self.contacts, np.integer):
            object.__setattr__(self, "contacts", int(self.contacts))
        _check_parts_plausible(self, allow_extrapolation=self.allow_extrapolation)
        # computed once here, each a normal double (else refused naming the inputs), then trusted
        object.__setattr__(self, "_contact_moduli", _moduli(self))
        object.__setattr__(self, "_contact_layout", _layout(self))
        _check_contacts_plausible(self, allow_extrapolation=self.allow_extrapolation)

    def replace(self, **changes) -> Drive:
        """A copy with some fields changed (validated again).

        Changing ``hemisphere_radius`` without giving ``actuator`` picks the Table 2
        actuator of the new radius.
        """
        if "hemisphere_radius" in changes and "actuator" not in changes:
            changes["actuator"] = None
        return replace(self, **changes)

    @property
    def effective_load_cell_stiffness(self) -> float:
        """k if the load cell is engaged, else 0 (free runner)."""
        return self.load_cell_stiffness if self.load_cell else 0.0

    @property
    def contact_layout(self) -> ContactLayout:
        """Normal force per contact (Eq. 1), contacts and hemisphere radius of each contact group."""
        return self._contact_layout

    @property
    def contact_moduli(self) -> tuple[float, float]:
        """(E*, G*) of the hemisphere/runner pair, Pa (Eq. 4)."""
        return self._contact_moduli


def _moduli(drive: Drive) -> tuple[float, float]:
    """(E*, G*) of a drive's materials (checked by the drive), each a normal double."""
    h, r = drive.hemisphere_material, drive.runner_material
    args = (h.youngs_modulus, h.poissons_ratio, r.youngs_modulus, r.poissons_ratio)
    E_star, G_star = float(_youngs(*args)), float(_shear(*args))
    moduli = (("hemisphere_material.youngs_modulus", h.youngs_modulus, "Pa"),
              ("runner_material.youngs_modulus", r.youngs_modulus, "Pa"))
    _require_normal(E_star, "E*", "Pa", moduli)
    _require_normal(G_star, "G*", "Pa", moduli)
    return E_star, G_star


def _layout(drive: Drive) -> ContactLayout:
    """Eq. 1 for a drive's groups (the paper's one or six as theirs), each force a normal double."""
    groups = drive.contact_groups or preset_groups(drive.contacts)
    # the paper's six: F_p/(2 sin 45°), F_p/(4 sin 45°) exactly
    forces = group_normal_forces(np.asarray(float(drive.preload)), groups)
    for force in reversed(forces):  # the paper's six: the smaller F_N2 first
        _require_normal(force, "the normal force per contact", "N", (("preload", drive.preload, "N"),))
    R = float(drive.hemisphere_radius)
    arrays = (np.array([float(f) for f in forces]), np.array([g.count for g in groups], dtype=float),
              np.array([R if g.radius is None else float(g.radius) for g in groups]))
    for a in arrays:
        a.setflags(write=False)
    return ContactLayout(*arrays)


# --------------------------------------------------------------------------------------
# Plausible ranges (one place): hard limits where the model's physics breaks, soft limits
# around Tables 1–2 where it was checked. Library and CLI both check against this table.
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PlausibleRange:
    """Where a parameter keeps the model valid.

    ``hard_*``: outside, the model does not apply (never lifted). ``soft_*``: the decades
    around Tables 1–2 the model was checked in; ``allow_extrapolation=True`` (CLI
    ``--allow-extrapolation``) lifts them for exploration. ``None`` leaves a side open.
    """

    unit: str
    hard_low: float | None
    soft_low: float | None
    soft_high: float | None
    hard_high: float | None
    reason: str  # why the soft limits (and, unless hard_reason says otherwise, the hard ones)
    hard_low_open: bool = True  # a hard lower bound of 0 is excluded (positive quantities)
    hard_reason: str = ""  # why the hard limits, when it differs from ``reason``

    def check(self, name: str, value, *, allow_extrapolation: bool = False, flag: str | None = None,
              scale: float = 1.0, unit: str | None = None, hint: str = "allow_extrapolation=True") -> float:
        """``float(value)`` if plausible, else ``ValueError`` naming the value, limit and why.

        ``flag``/``scale``/``unit`` let the CLI report an option as typed, in its display unit
        (``value`` and the bounds are divided by ``scale``).
        """
        v = check_range(name, value, unit=self.unit)  # a finite real number
        label, unit = (flag or name), (self.unit if unit is None else unit)
        u = f" {unit}" if unit and unit != "–" else ""

        def refuse(op: str, bound: float, kind: str) -> InputError:
            why = self.hard_reason if kind == "hard limit" and self.hard_reason else self.reason
            if kind == "hard limit" and lo == 0.0 and op.startswith(">"):
                why = "a physical quantity of this kind is positive"
            soft = kind == "plausible range"
            shown_value = f"{format_number(v, scale)}{u}" if flag else shown(value)  # CLI: display unit
            limit = f"{op} {format_number(bound, scale)}{u}"
            return InputError(f"{label} = {shown_value} is out of range: must be {limit} "
                              f"({kind}: {why}){f'; {hint} goes beyond it' if soft else ''}",
                              name=label, value=v, unit=self.unit, limits=((op, bound),),
                              why=f"{kind}: {why}", soft=soft)

        lo, hi = self.hard_low, self.hard_high
        if lo is not None and (v <= lo if self.hard_low_open else v < lo):
            raise refuse(">" if self.hard_low_open else ">=", lo, "hard limit")
        if hi is not None and v > hi:
            raise refuse("<=", hi, "hard limit")
        if not allow_extrapolation:
            if self.soft_low is not None and v < self.soft_low:
                raise refuse(">=", self.soft_low, "plausible range")
            if self.soft_high is not None and v > self.soft_high:
                raise refuse("<=", self.soft_high, "plausible range")
        return v


_TWO_DECADES = "two decades either side of Tables 1–2, where the model was checked"
#: Ranges of the drive's parameters (SI). Keys: Drive fields, ``actuator.*``,
#: ``amplifier.*``, ``material.*`` (both materials), and the waveform's ``frequency``.
PLAUSIBLE_RANGES: dict[str, PlausibleRange] = {
    "hemisphere_radius": PlausibleRange("m", 0.0, 10e-6, 100e-3, None,
                                        "Table 2's 0.25–1 mm, " + _TWO_DECADES),
    "preload": PlausibleRange("N", 0.0, 1e-3, 100.0, None, "Section 4's 0.1–1 N, " + _TWO_DECADES),
    "friction_coefficient": PlausibleRange(
        "–", 0.0, 0.01, 1.0, None,
        "dry friction of ruby on steel is 0.1–0.3 (Table 1: 0.2, earlier work 0.3); beyond 1 the "
        "Cattaneo–Mindlin traction of a Hertz contact is no longer a small perturbation"),
    "runner_mass": PlausibleRange("kg", 0.0, 3e-5, 0.3, None, "Table 1's 3 g, " + _TWO_DECADES),
    "load_cell_stiffness": PlausibleRange("N/m", 0.0, 250.0, 2.5e6, None,
                                          "Table 1's 2.5e4 N/m, " + _TWO_DECADES),
    "material.youngs_modulus": PlausibleRange(
        "Pa", 0.0, 1e9, 1.2e12, None,
        "engineering solids from polymers (1 GPa) to diamond (1.2 TPa); Table 1: 210–370 GPa"),
    "material.poissons_ratio": PlausibleRange(
        "–", -1.0, 0.0, 0.5, 0.5, "isotropic elasticity needs -1 < ν < 0.5; Table 1: 0.33"),
    "actuator.stiffness": PlausibleRange("N/m", 0.0, 4e4, 6.5e8, None,
                                         "Table 2's 4–6.5e6 N/m, " + _TWO_DECADES),
    "actuator.mass": PlausibleRange("kg", 0.0, 1.1e-10, 2.2e-6, None,
                                    "Table 2's 1.1–2.2e-8 kg (as printed), " + _TWO_DECADES),
    "actuator.damping_ratio": PlausibleRange(
        "–", 0.0, None, 10.0, None,
        "c_p up to ten times critical damping of the bare actuator (the default is ζ = 0.05)",
        hard_low_open=False),
    "actuator.full_stroke_amplitude": PlausibleRange(
        "m", 0.0, 0.96e-9, 20.2e-6, 10.0, "Table 2's 96–202 nm, " + _TWO_DECADES,
        hard_reason="beyond 10 m of travel, double-precision rounding of positions (2.2e-16 relative) "
        "exceeds 1e-6 of the ~10 nm presliding displacement"),
    "amplifier.peak_to_peak_voltage": PlausibleRange("V", 0.0, 3.0, 3e4, None,
                                                     "Section 2's 300 V_pp, " + _TWO_DECADES),
    "amplifier.slew_rate": PlausibleRange("V/s", 0.0, 1.5e6, 1.5e10, None,
                                          "Section 2's 150 V/µs, " + _TWO_DECADES),
    "frequency": PlausibleRange(
        "Hz", 1e-3, 1.0, 1e6, None,
        "the paper drives from 100 Hz (Fig. 9a) to 130 kHz (Fig. 9b); two decades below, one above",
        hard_reason="below 1 mHz a period is too long for its µs fly-back to stay resolvable in "
        "double-precision time"),
}
#: Where the paper is silent about the drive's ranges (the drive's parts: passmd.model.tables).
ASSUMPTIONS: tuple[Assumption, ...] = (
    Assumption(
        key="plausible_ranges",
        symbol="–",
        value="soft: two decades around Tables 1–2, μ ≤ 1, p0 ≤ 10 GPa; hard: a ≤ R/10, positive quantities",
        unit="–",
        rationale=(
            "The paper gives the model's parameters, not where it stops applying. Hard limits follow "
            "from its physics (Hertz/MDR need a ≤ R/10); soft limits keep inputs within two decades of "
            "the tabulated values, where the model was checked (PLAUSIBLE_RANGES gives each reason)."
        ),
        sensitivity="None of the paper's figures (all inside the soft limits); other inputs are refused "
                    "unless allow_extrapolation / --allow-extrapolation.",
    ),
)

#: Hard limit on the Hertz contact radius: a <= R/10. Hertz's half-space solution and the
#: MDR both assume a contact small against the sphere (K.L. Johnson, Contact Mechanics, §4.2).
CONTACT_RADIUS_RATIO_LIMIT = 0.1
#: Soft limit on the peak Hertz pressure p0 = 3 F_N / (2π a²): 10 GPa. Hardened bearing steel
#: first yields at p0 ≈ 1.6 Y ≈ 3 GPa and ruby's compressive strength is 2–3 GPa; the paper's
#: own grids reach 2.9 GPa (R = 0.25 mm, F_p = 0.5 N). Beyond 10 GPa the contact is far outside
#: the elastic regime the Hertz/MDR model describes.
HERTZ_PRESSURE_LIMIT = 10e9


def _hertz(normal_force: float, radius: float, E_star: float) -> tuple[float, float]:
    """(a, p0) of a Hertz contact (a = (3 F R / 4E*)^(1/3), p0 = 3F / (2π a²))."""
    a = (3.0 * normal_force * radius / (4.0 * E_star)) ** (1.0 / 3.0)
    return a, 3.0 * normal_force / (2.0 * np.pi * a * a)


def check_contact_plausible(normal_force: float, radius: float, E_star: float, *,
                            allow_extrapolation: bool = False, names: str = "normal_force, radius",
                            hint: str = "allow_extrapolation=True", sources: tuple[str, ...] = ()) -> None:
    """Refuse a contact outside Hertz's assumptions: a > R/10 (hard), p0 > 10 GPa (soft).

    Raises
    ------
    InputError
        A ``ValueError`` naming the parameters (``names``), the contact radius or pressure and
        the limit; its ``sources`` are ``sources`` (the inputs, named like the drive's fields).
    """
    def refuse(detail: str, soft: bool = False) -> InputError:
        hinted = f"{detail}; {hint} goes beyond it" if soft else detail
        return InputError(f"{names}: {hinted}", name=names, sources=sources, detail=detail, soft=soft)

    a = (3.0 * float(normal_force) * float(radius) / (4.0 * float(E_star))) ** (1.0 / 3.0)
    if not a > 0.0:  # the product underflows below the smallest double: no contact to model
        raise refuse(f"the Hertz contact radius a = (3 F R / 4E*)^(1/3) = {a:.4g} m underflows; "
                     "must be > 0 (hard limit: double precision)")
    with np.errstate(all="ignore"):
        a, p0 = _hertz(float(normal_force), float(radius), float(E_star))
    ratio = a / radius
    if not np.isfinite(ratio) or ratio > CONTACT_RADIUS_RATIO_LIMIT:
        raise refuse(f"the Hertz contact radius a = {a:.4g} m is {ratio:.3g} R; must be <= "
                     f"{CONTACT_RADIUS_RATIO_LIMIT:g} R (hard limit: Hertz and the MDR need a contact small "
                     "against the sphere)")
    if not allow_extrapolation and not p0 <= HERTZ_PRESSURE_LIMIT:
        raise refuse(f"the peak Hertz pressure p0 = {p0 / 1e9:.4g} GPa is out of range: must be <= "
                     f"{HERTZ_PRESSURE_LIMIT / 1e9:g} GPa (plausible range: beyond it ruby and steel are far "
                     "outside the elastic regime the model describes)", soft=True)


def check_drive(drive) -> Drive:
    """``drive`` if it is a :class:`Drive`, else ``ValueError`` naming it (public functions' check)."""
    if not isinstance(drive, Drive):
        raise InputError(f"drive = {shown(drive)} is not a Drive", name="drive", value=drive)
    return drive


def check_plausible(drive: Drive, *, allow_extrapolation: bool = False) -> None:
    """Check every parameter of a drive against :data:`PLAUSIBLE_RANGES` and the contact limits.

    Raises
    ------
    InputError
        A ``ValueError``: the first parameter outside its range, naming it (the field,
        dotted for a part: ``"actuator.mass"``), its value, the limit and why. The damping
        ratio ζ = c_p / (2√(k_p m_a)) is refused as a quantity computed from
        ``actuator.viscosity``.
    """
    check_drive(drive)
    for name in ("hemisphere_radius", "preload", "friction_coefficient", "runner_mass",
                 "load_cell_stiffness"):
        PLAUSIBLE_RANGES[name].check(name, getattr(drive, name), allow_extrapolation=allow_extrapolation)
    _check_parts_plausible(drive, allow_extrapolation=allow_extrapolation)
    _check_contacts_plausible(drive, allow_extrapolation=allow_extrapolation)


def _check_parts_plausible(drive: Drive, *, allow_extrapolation: bool) -> None:
    """:func:`check_plausible` but for the drive's own numbers (``Drive`` checks them first)."""
    r = PLAUSIBLE_RANGES
    kw = {"allow_extrapolation": allow_extrapolation}
    for which in ("hemisphere_material", "runner_material"):
        material = getattr(drive, which)
        r["material.youngs_modulus"].check(f"{which}.youngs_modulus", material.youngs_modulus, **kw)
        r["material.poissons_ratio"].check(f"{which}.poissons_ratio", material.poissons_ratio, **kw)
    act, amp = drive.actuator, drive.amplifier
    for name in ("stiffness", "mass"):
        r[f"actuator.{name}"].check(f"actuator.{name}", getattr(act, name), **kw)
    try:
        r["actuator.damping_ratio"].check("actuator.damping_ratio", act.damping_ratio, **kw)
    except InputError as exc:
        raise exc.derived_from("actuator.viscosity", act.viscosity, 2.0 * np.sqrt(act.stiffness * act.mass),
                               "the damping ratio ζ = c_p / (2√(k_p m_a))") from None
    r["actuator.full_stroke_amplitude"].check("actuator.full_stroke_amplitude", act.full_stroke_amplitude,
                                              **kw)
    for name in ("peak_to_peak_voltage", "slew_rate"):
        r[f"amplifier.{name}"].check(f"amplifier.{name}", getattr(amp, name), **kw)


def _check_contacts_plausible(drive: Drive, *, allow_extrapolation: bool) -> None:
    """Each contact group of a drive against Hertz's assumptions (:func:`check_contact_plausible`)."""
    E_star, _ = drive.contact_moduli
    forces, _, radii = drive.contact_layout  # Eq. 1; the most loaded contact first (it fails first)
    for g in np.argsort(-forces / radii ** 2, kind="stable"):  # a/R and p0 grow as (F/R²)^(1/3)
        check_contact_plausible(forces[g], radii[g], E_star, names="preload, hemisphere_radius, materials",
                                sources=_CONTACT_SOURCES, allow_extrapolation=allow_extrapolation)


#: The drive's fields the Hertz contact of :func:`check_contact_plausible` depends on.
_CONTACT_SOURCES = ("preload", "hemisphere_radius", "hemisphere_material.youngs_modulus",
                    "hemisphere_material.poissons_ratio", "runner_material.youngs_modulus",
                    "runner_material.poissons_ratio")


def paper_drive(hemisphere_radius: float = 1.0e-3, preload: float = 0.4, **changes) -> Drive:
    """The paper's drive for one of Table 2's radii (1 mm or 0.25 mm).

    Raises ``ValueError`` for radii Table 2 does not list; use :class:`Drive`
    directly for other radii.
    """
    radius = check_positive("hemisphere_radius", hemisphere_radius, "m")
    if not any(np.isclose(radius, r, rtol=1e-9, atol=0) for r in TABLE2_RADII):
        raise ValueError(
            f"hemisphere_radius = {shown(hemisphere_radius)} is not a paper radius: must be one of "
            + ", ".join(f"{r:g}" for r in sorted(TABLE2_RADII))
            + " (m)"
        )
    return Drive(hemisphere_radius=radius, preload=preload, **changes)
