"""Quantities with units at the edges of the package (command line, user input).

Inside the package everything is SI. Users type quantities with units —
``0.4N``, ``1mm``, ``0.25 mm``, ``202nm``, ``100kHz``, ``310GPa`` — which
:func:`parse_quantity` converts to SI with the units library `pint`. A bare number
is read in the *display unit* the option documents (``--radius 0.25`` is 0.25 mm).
A quantity of the wrong dimension (``--radius 3N``) raises :class:`QuantityError`,
a :class:`ValueError` naming the option, the value and the expected unit.
"""

from __future__ import annotations

import functools
import math
import re
from decimal import Decimal

__all__ = [
    "QuantityError",
    "dimension_name",
    "from_si",
    "parse_quantities",
    "parse_quantity",
    "registry",
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


class QuantityError(ValueError):
    """A quantity that cannot be read, or has the wrong dimension."""


@functools.lru_cache(maxsize=1)
def registry() -> pint.UnitRegistry:  # noqa: F821 - pint is imported on first use
    """The package's unit registry (built once, on first use; building it takes a fraction of a second)."""
    import pint

    return pint.UnitRegistry()


def _si_factor(unit: str) -> float:
    """SI magnitude of one ``unit`` (``"nm"`` → 1e-9)."""
    factor = _DISPLAY_FACTORS.get(unit)
    if factor is None:
        factor = registry().Quantity(1.0, _unit(unit)).to_base_units().magnitude
    return factor


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
        ``0.25``) which is read in ``unit``.
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
        unknown, or its dimension differs from ``unit``'s.
    """
    shown = f" (a bare number is read in {unit})" if unit else ""
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
    if not math.isfinite(float(number_text)):
        raise QuantityError(f"{name} = {text!r} is not a finite number")
    if not unit_text:
        # a bare number is in the display unit: no registry needed
        return float(Decimal(number_text) * Decimal(repr(float(_si_factor(unit)))))
    base = _DISPLAY_BASES.get(unit_text)
    if base is not None and base == _DISPLAY_BASES.get(unit):
        # a display unit of the expected dimension: no registry needed either (same factor)
        return float(Decimal(number_text) * Decimal(repr(_DISPLAY_FACTORS[unit_text])))
    display = _unit(unit)
    try:
        given = registry().parse_units(unit_text)
    except Exception as exc:  # pint's parser raises many kinds (even AssertionError for '0:')
        raise QuantityError(
            f"{name} = {text!r}: unknown unit {unit_text!r}; expected a {dimension_name(unit)}"
            f" unit such as {unit or 'a plain number'}"
        ) from exc
    if given.dimensionality != display.dimensionality:
        expected = f"a {dimension_name(unit)} such as '1{unit}'" if unit else "a plain number"
        raise QuantityError(
            f"{name} = {text!r} has the wrong unit: {given:~P} is a "
            f"{dimension_name(given)}, expected {expected}{shown}"
        )
    # Multiply in decimal so that "30nm" gives the float nearest 3e-8 (30 * 1e-9 would not).
    factor = registry().Quantity(1.0, given).to_base_units().magnitude
    return float(Decimal(number_text) * Decimal(repr(float(factor))))


def parse_quantities(text: str, unit: str, *, name: str = "value") -> list[float]:
    """Read a comma-separated list of quantities (``"0nm,30nm,-10nm,45nm"``) into SI.

    Each element follows :func:`parse_quantity`; bare numbers are in ``unit``.
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
