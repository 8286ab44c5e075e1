"""The paper's tables: materials (Table 1), actuators (Table 2), amplifier (Section 2).

Every value cites where it comes from in Nguyen et al. (2018) (Table 1, Table 2, Section 2).
Where the paper is silent, the value is an *assumption*: it is defined once here, listed in
``ASSUMPTIONS`` (an :class:`Assumption` each) and shown in the book's assumptions table; this
module also holds Table 2's actuator for any hemisphere radius (:func:`actuator_for_radius`,
interpolated between the tabulated rows) and the preload grids of the critical-amplitude
figures. All quantities are SI (m, kg, s, N, Pa). Records are frozen dataclasses validated in
``__post_init__``; each field carries its paper symbol, unit and source in its metadata, which
:func:`parameter_table` turns into the book's parameter tables. The whole drive built from these
parts is :class:`passmd.model.parameters.Drive`.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, fields

import numpy as np

from passmd.runtime.validation import InputError, check_positive, check_range, shown

__all__ = [
    "ACTUATOR_DAMPING_RATIO",
    "ASSUMPTIONS",
    "FLYBACK_RULES",
    "Actuator",
    "Amplifier",
    "Assumption",
    "MOLYBDENUM",
    "Material",
    "PRELOAD_GRIDS",
    "RUBY",
    "STEEL",
    "TABLE2_RADII",
    "actuator_for_radius",
    "actuator_viscosity",
    "check_flyback_rule",
    "parameter_table",
    "table2_source",
]


def _meta(symbol: str, unit: str, source: str) -> dict:
    return {"symbol": symbol, "unit": unit, "source": source}


@dataclass(frozen=True)
class Assumption:
    """A value the paper does not give, with its default and why."""

    key: str  # identifier used in code and in the book
    symbol: str  # the paper's (or our) symbol
    value: str  # default, formatted for display
    unit: str  # display unit
    rationale: str  # why this default
    sensitivity: str  # where its effect is shown

    def __post_init__(self):
        # the unit is shown once, after the symbol or the number: a value that ends in it too
        # ("0.1 N" with unit "N") would read "0.1 N N"
        if self.unit not in ("", "–", "-") and re.search(rf"(^|[\s\d]){re.escape(self.unit)}$",
                                                           self.value.rstrip()):
            raise InputError(f"value = {self.value!r} of assumption {self.key!r} is not allowed: it ends in "
                             f"its unit {self.unit!r}, which is shown once (leave it out of the value)",
                             name="value", value=self.value)


# --------------------------------------------------------------------------------------
# Assumptions where the paper is silent about its tables (the book renders ASSUMPTIONS).
# --------------------------------------------------------------------------------------

#: Damping ratio ζ of the bare actuator used to derive the viscosity
#: c_p = 2 ζ sqrt(k_p m_a). Table 2's "Viscosity Factor" column was lost.
ACTUATOR_DAMPING_RATIO = 0.05


# --------------------------------------------------------------------------------------
# Records
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Material:
    """Isotropic elastic material."""

    youngs_modulus: float = field(metadata=_meta("E", "Pa", "Table 1"))  # Young's modulus E
    poissons_ratio: float = field(metadata=_meta("ν", "–", "Table 1"))  # Poisson's ratio ν
    name: str = ""  # label for tables and plots

    def __post_init__(self):
        if not isinstance(self.name, str):
            raise InputError(f"name = {self.name!r} is not allowed: must be a str", name="name",
                             value=self.name)
        check_positive("youngs_modulus", self.youngs_modulus, "Pa")
        check_range(
            "poissons_ratio", self.poissons_ratio, -1.0, 0.5, lower_open=True, upper_open=True
        )

    @property
    def shear_modulus(self) -> float:
        """Shear modulus G = E / (2 (1 + ν)) in Pa."""
        return self.youngs_modulus / (2.0 * (1.0 + self.poissons_ratio))


#: Ruby hemispheres, Table 1 (E_1 = 370 GPa, ν_1 = 0.33).
RUBY = Material(370e9, 0.33, "ruby")
#: Steel runner, Table 1 (E_2 = 210 GPa, ν_2 = 0.33).
STEEL = Material(210e9, 0.33, "steel")
#: Molybdenum runner, Section 5.2 / Fig. 10c (E_2 = 310 GPa; ν assumed, see ASSUMPTIONS).
MOLYBDENUM = Material(310e9, 0.33, "molybdenum")


@dataclass(frozen=True)
class Actuator:
    """One piezo actuator as a mass–spring–damper (Eq. 3)."""

    stiffness: float = field(metadata=_meta("k_p", "N/m", "Table 2"))  # k_p
    mass: float = field(metadata=_meta("m_a", "kg", "Table 2 (as printed)"))  # m_a
    viscosity: float = field(metadata=_meta("c_p", "kg/s", "assumed (Table 2 lost)"))  # c_p
    full_stroke_amplitude: float = field(
        metadata=_meta("A_max", "m", "Table 2 amplitude range at 300 V_pp")
    )  # actuation amplitude at the full 300 V_pp stroke

    def __post_init__(self):
        check_positive("actuator_stiffness", self.stiffness, "N/m")
        check_positive("actuator_mass", self.mass, "kg")
        check_range("actuator_viscosity", self.viscosity, 0.0, unit="kg/s")
        check_positive("full_stroke_amplitude", self.full_stroke_amplitude, "m")

    @property
    def natural_frequency(self) -> float:
        """Bare actuator natural frequency √(k_p/m_a)/(2π) in Hz."""
        return float(np.sqrt(self.stiffness / self.mass) / (2 * np.pi))

    @property
    def damping_ratio(self) -> float:
        """ζ = c_p / (2 √(k_p m_a))."""
        return self.viscosity / (2.0 * np.sqrt(self.stiffness * self.mass))


#: Hemisphere radii of Table 2 with (k_p [N/m], m_a [kg], A_max [m]).
#: m_a is printed as 1.1e-5 g and 2.2e-5 g; used as printed (see the model chapter).
TABLE2_RADII: dict[float, tuple[float, float, float]] = {
    0.25e-3: (4.0e6, 1.1e-8, 96e-9),
    1.0e-3: (6.5e6, 2.2e-8, 202e-9),
}


def actuator_for_radius(
    hemisphere_radius: float, damping_ratio: float = ACTUATOR_DAMPING_RATIO
) -> Actuator:
    """Table 2 actuator for a hemisphere radius R.

    Parameters
    ----------
    hemisphere_radius : float
        R in m. Table 2 rows (0.25 mm, 1 mm) are exact; other radii interpolate
        linearly and are clamped outside (an assumption, see ``ASSUMPTIONS``).
    damping_ratio : float
        ζ of the bare actuator; c_p = 2 ζ √(k_p m_a).
    """
    radius = check_positive("hemisphere_radius", hemisphere_radius, "m")
    return _table2_actuator(radius, check_range("damping_ratio", damping_ratio, 0.0, unit="–"))


def table2_source(radius: float) -> str:
    """Where a radius's actuator comes from in Table 2: a row, interpolated or clamped."""
    radii = sorted(TABLE2_RADII)
    if any(math.isclose(radius, r, rel_tol=1e-9) for r in radii):
        return f"Table 2 (R = {radius * 1e3:g} mm)"
    if radii[0] < radius < radii[-1]:
        return f"Table 2 interpolated at R = {radius * 1e3:.4g} mm"
    return f"Table 2 clamped (R = {radius * 1e3:.4g} mm outside {radii[0] * 1e3:g}–{radii[-1] * 1e3:g} mm)"


def _table2_actuator(radius: float, zeta: float) -> Actuator:
    """:func:`actuator_for_radius` of a radius > 0 and a ζ >= 0 the caller has checked."""
    radii = np.array(sorted(TABLE2_RADII))
    rows = np.array([TABLE2_RADII[r] for r in radii])
    k_p, m_a, a_max = (float(np.interp(radius, radii, rows[:, j])) for j in range(3))
    return Actuator(stiffness=k_p, mass=m_a, viscosity=2.0 * zeta * np.sqrt(k_p * m_a),
                    full_stroke_amplitude=a_max)


def actuator_viscosity(stiffness: float, mass: float, damping_ratio: float = ACTUATOR_DAMPING_RATIO) -> float:
    """Viscosity c_p = 2 ζ √(k_p m_a) of an actuator (Eq. 3) whose bare damping ratio is ζ."""
    stiffness = check_positive("stiffness", stiffness, "N/m")
    mass = check_positive("mass", mass, "kg")
    return 2.0 * check_range("damping_ratio", damping_ratio, 0.0, unit="–") * np.sqrt(stiffness * mass)


#: Named fly-back rules of the saw-tooth's fast edge (Section 2; assumption ``flyback_duration``):
#: ``"slew"``, slew-rate limited, (A/A_max)·V_pp/SR (shorter at small amplitudes); ``"fixed"``, the
#: full-stroke time V_pp/SR at every amplitude. A rule may also be a stated time in s.
FLYBACK_RULES = ("slew", "fixed")


def check_flyback_rule(name: str, value) -> str | float:
    """``value`` if it is a fly-back rule: ``"slew"``, ``"fixed"`` or a stated time (s, finite, > 0)."""
    if isinstance(value, str):
        if value in FLYBACK_RULES:
            return value
        raise InputError(f"{name} = {value!r} is not allowed: must be 'slew', 'fixed' or a time in s (> 0)",
                         name=name, value=value)
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise InputError(f"{name} = {shown(value)} is not allowed: must be 'slew', 'fixed' or a time in s "
                         "(> 0)", name=name, value=value)
    return check_positive(name, float(value), "s")


@dataclass(frozen=True)
class Amplifier:
    """Driving electronics (Section 2) and the rule of the saw-tooth's fly-back they give."""

    peak_to_peak_voltage: float = field(
        default=300.0, metadata=_meta("V_pp", "V", "Section 2")
    )  # maximal amplitude 300 V_pp
    slew_rate: float = field(
        default=150e6, metadata=_meta("SR", "V/s", "Section 2 (150 V/µs)")
    )  # typical slew rate
    #: how long the fast edge takes (:data:`FLYBACK_RULES`, or a stated time in s)
    flyback: str | float = field(
        default="slew",
        metadata=_meta("t_fb", "rule or s", "assumed (flyback_duration): Section 2 gives V_pp, SR"),
    )

    def __post_init__(self):
        check_positive("peak_to_peak_voltage", self.peak_to_peak_voltage, "V")
        check_positive("slew_rate", self.slew_rate, "V/s")
        object.__setattr__(self, "flyback", check_flyback_rule("flyback", self.flyback))

    @property
    def full_stroke_time(self) -> float:
        """Shortest fly-back of a full 300 V stroke, V_pp / SR (2 µs)."""
        return self.peak_to_peak_voltage / self.slew_rate


#: Preload grids of the critical-amplitude figures (assumption ``preload_grids``).
PRELOAD_GRIDS: dict[float, np.ndarray] = {
    1.0e-3: np.round(np.arange(1, 11) * 0.1, 10),
    0.25e-3: np.round(np.arange(1, 6) * 0.1, 10),
}

ASSUMPTIONS: tuple[Assumption, ...] = (
    Assumption(
        key="actuator_viscosity",
        symbol="c_p",
        value=f"2·ζ·√(k_p m_a) with the damping ratio ζ = {ACTUATOR_DAMPING_RATIO:g} (dimensionless)",
        unit="kg/s",
        rationale=(
            "Table 2's 'Viscosity Factor' column is lost in the available text. A bare "
            "piezo actuator is lightly damped; ζ = 0.05 (Q = 10) is a typical order."
        ),
        sensitivity="Critical-amplitude chapters: A_c over a decade of c_p either side.",
    ),
    Assumption(
        key="preload_grids",
        symbol="F_p",
        value=" and ".join(f"{grid[0]:g}–{grid[-1]:.1f} at R = {radius * 1e3:g} mm" for radius, grid in
                           PRELOAD_GRIDS.items())
        + f", in steps of {PRELOAD_GRIDS[1.0e-3][1] - PRELOAD_GRIDS[1.0e-3][0]:.1g}",
        unit="N",
        rationale=(
            "Table 2's 'Preload Range' column is lost; its header gives the 0.1 N step. "
            "The ranges are those the text uses (Figs. 7 and 10: 0.1, 0.3, 0.4, 0.8, 1 N "
            "for R = 1 mm; 0.2, 0.4 N for R = 0.25 mm)."
        ),
        sensitivity="Only the extent of the Fig. 5b/6 grids; no result depends on it.",
    ),
    Assumption(
        key="molybdenum_poisson",
        symbol="ν_2 (Mo)",
        value="0.33",
        unit="–",
        rationale=(
            "Section 5.2 gives only E_2 = 310 (printed 'MPa', a typo for GPa given "
            "Table 1) for molybdenum; ν is kept at Table 1's 0.33 so only E changes."
        ),
        sensitivity="Fig. 10c only.",
    ),
    Assumption(
        key="actuator_other_radii",
        symbol="k_p(R), m_a(R), A_max(R)",
        value="linear in R between Table 2's rows, constant outside",
        unit="–",
        rationale=(
            "Table 2 gives actuators for R = 0.25 mm and 1 mm only. Other radii (CLI "
            "sizing) interpolate; the paper's figures use the tabulated radii only."
        ),
        sensitivity="None of the paper's figures; CLI results at other radii.",
    ),
)


def parameter_table(record) -> list[dict]:
    """Rows (name, symbol, value, unit, source) describing a parameter record.

    Nested records (materials, actuator, amplifier) are expanded with a dotted name.
    The book renders these rows instead of retyping Tables 1–2.
    """
    if not hasattr(record, "__dataclass_fields__") or isinstance(record, type):
        raise InputError(f"record = {shown(record)} is not a parameter record (a Drive, Material, Actuator "
                         "or Amplifier)", name="record", value=record)
    rows: list[dict] = []
    for f in fields(record):
        if not f.metadata:  # labels such as Material.name are not parameters
            continue
        value = getattr(record, f.name)
        if hasattr(value, "__dataclass_fields__"):
            for sub in parameter_table(value):
                sub["name"] = f"{f.name}.{sub['name']}"
                rows.append(sub)
            continue
        rows.append(
            {
                "name": f.name,
                "symbol": f.metadata.get("symbol", ""),
                "value": value,
                "unit": f.metadata.get("unit", ""),
                "source": f.metadata.get("source", ""),
            }
        )
    return rows
