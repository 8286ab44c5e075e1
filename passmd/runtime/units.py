"""Quantities with units at the edges of the package (command line, user input).

Inside the package everything is SI. Users type quantities with units —
``0.4N``, ``1mm``, ``0.25 mm``, ``202nm``, ``100kHz``, ``310GPa`` — which
:func:`parse_quantity` converts to SI with the units library `pint`. A bare number
is SI: it is read where the expected unit is SI (``--preload 0.4``, a drive file's
``preload = 0.4``) and refused where the expected unit is another (``--radius 0.25``,
shown in mm, asks for ``0.25mm``), so no number is ever read in a unit nobody wrote.
A quantity of the wrong dimension (``--radius 3N``) raises :class:`QuantityError`,
a :class:`ValueError` naming the option, the value and the expected unit.

Angles are read by their physical meaning, not by pint's convention that a radian is a
plain number and a revolution is 2π of them. A frequency counts cycles: ``Hz``, ``1/s``,
``1/min`` and the full-cycle units (``turn``, ``cycle``, ``revolution``, ``rpm``, ``rps``)
are accepted, one cycle per unit (``100 rpm`` is 1.667 Hz, not pint's 10.47/s). An
angular rate (``rad/s``, ``deg/s``) is refused with the hint f = ω/2π, and an angle unit
in any other quantity is refused: pint would silently turn ``0.2 rad`` into 0.2 and
``1 turn`` into 6.28.
"""

from __future__ import annotations

import functools
import math
import re
from decimal import Decimal, localcontext

__all__ = [
    "ANGLE_UNITS",
    "QuantityError",
    "dimension_name",
    "from_si",
    "parse_angle",
    "parse_quantities",
    "parse_quantity",
    "registry",
    "round_down",
    "si_factor",
    "to_display",
]

# A number (optionally signed, decimal or scientific) followed by an optional unit.
_QUANTITY = re.compile(r"^\s*([+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)\s*(.*?)\s*$")

# Words for the dimensions the package's options use (for error messages), by example unit.
_DIMENSION_WORDS = {
    "m": "length",
    "kg": "mass",
    "s": "time",
    "Hz": "frequency",
    "N": "force",
    "Pa": "pressure (modulus)",
    "N/m": "stiffness (force per length)",
    "kg/s": "viscosity (force per velocity)",
    "": "plain number",
}


# SI factors of the display units the package shows and reads bare numbers in, so that
# formatting output, reading bare numbers and reading numbers given in a display unit
# (``150nm``, ``40kHz``) need no unit registry (building pint's takes ≈ 0.3–1 s of start-up);
# tests check each factor against pint's. Any other unit goes to pint.
_DISPLAY_FACTORS = {
    "": 1.0,
    "m": 1.0,
    "mm": 1e-3,
    "um": 1e-6,
    "nm": 1e-9,
    "s": 1.0,
    "us": 1e-6,
    "kg": 1.0,
    "g": 1e-3,
    "Hz": 1.0,
    "kHz": 1e3,
    "N": 1.0,
    "mN": 1e-3,
    "N/m": 1.0,
    "kg/s": 1.0,
    "Pa": 1.0,
    "GPa": 1e9,
    "V": 1.0,
    "V/us": 1e6,
}


# The SI unit each display unit measures in: two display units have the same dimension
# exactly when they share it (tests check this against pint's dimensionalities).
_DISPLAY_BASES = {
    "": "",
    "m": "m",
    "mm": "m",
    "um": "m",
    "nm": "m",
    "s": "s",
    "us": "s",
    "kg": "kg",
    "g": "kg",
    "Hz": "Hz",
    "kHz": "Hz",
    "N": "N",
    "mN": "N",
    "N/m": "N/m",
    "kg/s": "kg/s",
    "Pa": "Pa",
    "GPa": "Pa",
    "V": "V",
    "V/us": "V/s",
}


#: pint's canonical names of one full cycle (turn = revolution = cycle = circle) and of the
#: rates it defines; every other unit whose root holds a radian is an angle (tests check
#: this list against pint's registry).
_CYCLE_UNITS = frozenset({"turn", "revolutions_per_minute", "revolutions_per_second"})


class QuantityError(ValueError):
    """A quantity that cannot be read, or has the wrong dimension."""


def round_down(value: float, digits: int = 4) -> float:
    """``value`` rounded down to ``digits`` significant digits: how an upper limit is printed, so that
    the printed number, typed back, stays within the limit (``passmd run``'s "Eq. 15 fits up to")."""
    if not (value > 0 and math.isfinite(value)):
        return value
    step = 10.0 ** (math.floor(math.log10(value)) - (digits - 1))
    return math.floor(value / step * (1 + 1e-12)) * step


@functools.lru_cache(maxsize=1)
def registry() -> pint.UnitRegistry:  # noqa: F821 - pint is imported on first use
    """The package's unit registry (built once, on first use; building it takes a fraction of a second)."""
    import pint

    return pint.UnitRegistry()


@functools.lru_cache(maxsize=64)
def _si_factor(unit: str) -> float:
    """SI magnitude of one ``unit`` (``"nm"`` → 1e-9); ``QuantityError`` for a unit pint does not know."""
    factor = _DISPLAY_FACTORS.get(unit)
    if factor is None:
        try:
            factor = registry().Quantity(1.0, _unit(unit)).to_base_units().magnitude
        except Exception as err:  # pint raises several error types for unknown units
            raise QuantityError(f"unit = {unit!r} is not a unit pint understands") from err
    return factor


def si_factor(unit: str) -> float:
    """SI magnitude of one display ``unit`` (``si_factor("GPa")`` → 1e9, exactly the typed factor)."""
    return float(_si_factor(unit))


def to_display(value: float, unit: str) -> float:
    """An SI value in the display ``unit``, divided in decimal (``to_display(2.5e-4, "mm")`` → 0.25).

    The shortest decimal of ``value`` divided by the unit's decimal factor, rounded once: a
    quantity parsed from ``"0.3nm"`` shows as 0.3 nm again (a binary division would give
    0.30000000000000004), and for a plain number (``unit`` ``""``) it is ``value`` itself.
    """
    with localcontext() as ctx:
        ctx.prec = 60
        return float(Decimal(repr(float(value))) / Decimal(repr(si_factor(unit))))


@functools.cache
def _unit(unit: str):
    return registry().Unit(unit) if unit else registry().dimensionless


@functools.lru_cache(maxsize=1)
def _dimension_words() -> dict:
    return {_unit(u).dimensionality: word for u, word in _DIMENSION_WORDS.items()}


def dimension_name(unit) -> str:
    """A readable name of the dimension of ``unit`` (``"mm"`` → ``"length"``)."""
    dim = (_unit(unit) if isinstance(unit, str) else unit).dimensionality
    return _dimension_words().get(dim, str(dim))


def parse_quantity(text, unit: str, *, name: str = "value") -> float:
    """Read one quantity and return its magnitude in SI base units.

    Parameters
    ----------
    text : str or real
        ``"0.25mm"``, ``"0.25 mm"``, ``"250um"``, or a bare number (``"0.25"`` or
        ``0.25``), which is SI: read where ``unit`` is SI, refused where it is not.
    unit : str
        The display unit (``"mm"``, ``"nm"``, ``"N"``, ``"kHz"``, ``"GPa"``, ``"g"``,
        ``"N/m"``, ``"kg/s"``; ``""`` for a plain number). It also fixes the
        dimension the quantity must have.
    name : str
        Name used in error messages (e.g. the option, ``"--radius"``).

    Returns
    -------
    float
        The value in SI base units (m, kg, s, N, Pa, Hz).

    Raises
    ------
    QuantityError
        If the text is not a finite number with an optional unit, the unit is
        unknown, or its dimension differs from ``unit``'s; or a bare number where ``unit``
        is not SI (naming ``name``, the number and both units it may be written in).
    """
    shown = f" (a bare number is read in {unit})" if unit and _DISPLAY_FACTORS.get(unit) == 1.0 else ""
    if isinstance(text, bool):
        raise QuantityError(f"{name} = {text!r} is not a quantity: give a number{shown}")
    if isinstance(text, (int, float)):
        number_text, unit_text = repr(float(text)), ""
    else:
        match = _QUANTITY.match(str(text))
        if match is None:
            example = f"'1{unit}'" if unit else "'0.2'"
            raise QuantityError(
                f"{name} = {text!r} is not a quantity: give a number with an optional unit, "
                f"e.g. {example}{shown}"
            )
        number_text, unit_text = match.group(1), match.group(2)
    if not unit_text and _si_factor(unit) != 1.0 and _QUANTITY.match(str(text)):  # bare, unit not SI
        typed, si = str(text).strip(), _DISPLAY_BASES.get(unit, "")
        raise QuantityError(f"{name} = {typed} has no unit: write one, e.g. {typed}{si} or {typed}{unit} "
                            f"(an option shown in {unit} takes no bare number; a bare number is SI only "
                            "where the option is shown in SI)")
    if not math.isfinite(float(number_text)):
        raise QuantityError(f"{name} = {text!r} is not a finite number")
    if not unit_text:  # a bare number in an SI unit: no registry needed
        return float(Decimal(number_text) * Decimal(repr(float(_si_factor(unit)))))
    base = _DISPLAY_BASES.get(unit_text)
    if base is not None and base == _DISPLAY_BASES.get(unit):
        # a display unit of the expected dimension: no registry needed either (same factor)
        return float(Decimal(number_text) * Decimal(repr(_DISPLAY_FACTORS[unit_text])))
    display = _unit(unit)
    try:
        given = registry().parse_units("1" + unit_text if unit_text.startswith("/") else unit_text)  # 100/min
    except Exception as exc:  # pint's parser raises many kinds (even AssertionError for '0:')
        raise QuantityError(
            f"{name} = {text!r}: unknown unit {unit_text!r}; expected a {dimension_name(unit)}"
            f" unit such as {unit or 'a plain number'}"
        ) from exc
    if given.dimensionality != display.dimensionality:
        raise QuantityError(
            f"{name} = {text!r} has the wrong unit: {given:~P} is a "
            f"{dimension_name(given)}, expected {_expected(unit)}{shown}"
        )
    factor, inverse = _physical_factor(given, unit, name=name, text=text, number=float(number_text))
    # Multiply in decimal so that "30nm" gives the float nearest 3e-8 (30 * 1e-9 would not).
    return _times(number_text, factor, inverse)


def _root_radians(name: str) -> int:
    """Exponent of the radian in the root units of one pint unit name (``"rpm"`` → 1)."""
    reg = registry()
    _, root = reg.get_root_units(name)
    return int(dict(reg.Quantity(1.0, root).unit_items()).get("radian", 0))


def _physical_factor(given, unit: str, *, name: str, text, number: float) -> tuple[float, float]:
    """SI factor of the pint unit ``given`` read by its physical meaning (see the module's docstring),
    and the factor back (one SI unit in ``given``).

    ``given`` already has the dimension of ``unit`` in pint's sense, where an angle is a plain
    number. A full-cycle unit counts one cycle in a frequency; any other angle is refused.
    """
    reg = registry()
    cycles, angles = 0, []
    for unit_name, exponent in reg.Quantity(1.0, given).unit_items():
        if _root_radians(unit_name) == 0:
            continue
        if reg.parse_unit_name(unit_name)[0][1] in _CYCLE_UNITS:
            cycles += exponent
        else:
            angles.append(unit_name)
    frequency = _is_frequency(unit)
    if angles and frequency:
        omega = number * reg.Quantity(1.0, given).to_base_units().magnitude  # in rad/s
        raise QuantityError(
            f"{name} = {text!r} is an angular rate ({given:~P}), not a frequency: a frequency counts "
            f"cycles (Hz, kHz, rpm, turn/s); divide an angular frequency ω by 2π to get Hz "
            f"(f = ω/2π ≈ {omega / (2.0 * math.pi):.6g} Hz here)"
        )
    if angles or (cycles and not frequency):
        kind = "an angle" if angles else "a number of cycles"
        raise QuantityError(
            f"{name} = {text!r} has the wrong unit: {given:~P} holds {kind} (which the units library "
            f"would read as a plain number, 1 turn = 6.28), expected {_expected(unit)}"
        )
    if cycles not in (0, 1):
        raise QuantityError(f"{name} = {text!r} has the wrong unit: {given:~P} is not cycles per time, "
                            f"expected {_expected(unit)}")
    # one cycle per turn: to cycles per second (pint cancels the turn exactly: krpm -> 16.666...67)
    si = reg.turn / reg.second if cycles else reg.Quantity(1.0, given).to_base_units().units
    return (reg.Quantity(1.0, given).to(si).magnitude, reg.Quantity(1.0, si).to(given).magnitude)


def _expected(unit: str) -> str:
    """What a quantity of ``unit`` may be given in, for messages (``"a length such as '1mm'"``)."""
    if not unit:
        return "a plain number"
    return f"a {dimension_name(unit)} such as '1{unit}'" + (" or '1 rpm'" if _is_frequency(unit) else "")


def _is_frequency(unit: str) -> bool:
    return _unit(unit).dimensionality == _unit("Hz").dimensionality


def _times(number_text: str, factor: float, inverse: float) -> float:
    """``number_text`` × ``factor`` in decimal, rounded once to a float.

    When the unit's inverse factor is the shorter decimal (a minute is 60 s, but 1/60 Hz has 17
    digits), divide by it instead: ``100 rpm`` is then the float nearest 5/3 Hz.
    """
    with localcontext() as ctx:
        ctx.prec = 60
        if len(repr(float(inverse))) < len(repr(float(factor))):
            return float(Decimal(number_text) / Decimal(repr(float(inverse))))
        return float(Decimal(number_text) * Decimal(repr(float(factor))))


#: Angle units :func:`parse_angle` reads, and the radians in one of each (a bare number is rad, SI).
ANGLE_UNITS = {"rad": 1.0, "radian": 1.0, "radians": 1.0, "deg": None, "degree": None, "degrees": None,
               "°": None}


def parse_angle(text, *, name: str = "angle") -> float:
    """Read an angle (``"45 deg"``, ``"45°"``, ``"0.785 rad"``, a bare number in rad) in radians.

    Angles are kept out of :func:`parse_quantity` (pint reads a radian as a plain number); this
    is the one place an angle is read. Degrees convert by ``math.radians``, so ``"45 deg"``
    is exactly ``math.pi / 4``.

    Raises
    ------
    QuantityError
        Not a finite number with one of the units :data:`passmd.runtime.units.ANGLE_UNITS`.
    """
    if isinstance(text, bool):
        raise QuantityError(f"{name} = {text!r} is not an angle: give e.g. \"45 deg\"")
    if isinstance(text, (int, float)):
        number_text, unit_text = repr(float(text)), ""
    else:
        match = _QUANTITY.match(str(text).replace("°", " °"))
        if match is None or match.group(2) not in ("", *ANGLE_UNITS):
            raise QuantityError(f"{name} = {text!r} is not an angle: give a number with deg or rad, e.g. "
                                "\"45 deg\" (a bare number is in rad)")
        number_text, unit_text = match.group(1), match.group(2)
    value = float(number_text)
    if not math.isfinite(value):
        raise QuantityError(f"{name} = {text!r} is not a finite number")
    return value if ANGLE_UNITS.get(unit_text, 1.0) is not None else math.radians(value)


def parse_quantities(text: str, unit: str, *, name: str = "value") -> list[float]:
    """Read a comma-separated list of quantities (``"0nm,30nm,-10nm,45nm"``) into SI.

    Each element follows :func:`parse_quantity` (a bare number is SI, refused where ``unit`` is not).
    """
    parts = str(text).split(",")
    if not parts or any(not p.strip() for p in parts):
        raise QuantityError(
            f"{name} = {text!r} is not a comma-separated list of quantities, e.g. '0{unit},30{unit}'"
        )
    return [parse_quantity(p, unit, name=name) for p in parts]


def from_si(value, unit: str):
    """Convert an SI magnitude (scalar or array) to ``unit`` (``from_si(2e-7, "nm")`` → 200)."""
    return value / _si_factor(unit)
