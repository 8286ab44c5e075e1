"""Quantity parsing at the package's edges (passmd.runtime.units).

Conversions are decimal (the typed number times the unit's SI factor, rounded once),
so "0.25mm" must give exactly the float 0.25e-3: equality, not a tolerance.
"""

import numpy as np
import pytest

from passmd.runtime import units
from passmd.runtime.units import QuantityError, dimension_name, from_si, parse_quantities, parse_quantity


@pytest.mark.parametrize(
    ("text", "unit", "expected"),
    [
        ("0.4N", "N", 0.4),
        ("1mm", "mm", 1e-3),
        ("0.25mm", "mm", 0.25e-3),
        ("0.25 mm", "mm", 0.25e-3),
        ("250um", "mm", 250e-6),
        ("0.4", "N", 0.4),  # a bare number: SI, where the unit is SI
        (0.4, "N", 0.4),
        ("1e-3 m", "mm", 1e-3),
        ("202nm", "nm", 202e-9),
        ("-10nm", "nm", -10e-9),
        ("100kHz", "kHz", 100e3),
        ("100 Hz", "kHz", 100.0),
        ("310GPa", "GPa", 310e9),
        ("3 mN", "N", 3e-3),
        ("2.2e-5 g", "g", 2.2e-8),
        ("6.5e6", "N/m", 6.5e6),
        ("6.5 MN/m", "N/m", 6.5e6),
        ("0.1 kg/s", "kg/s", 0.1),
        ("0.2", "", 0.2),
        ("20%", "", 0.2),
    ],
)
def test_parse_quantity_to_si(text, unit, expected):
    assert parse_quantity(text, unit, name="--x") == expected


@pytest.mark.parametrize(
    ("text", "unit", "fragment"),
    [
        ("3N", "mm", "--radius = '3N' has the wrong unit: N is a force, expected a length such as '1mm'"),
        ("1 s", "kHz", "expected a frequency"),
        ("0.2N", "", "expected a plain number"),
        ("1 m**2", "mm", "has the wrong unit"),
        ("1 foo", "mm", "unknown unit 'foo'"),
        ("abc", "mm", "is not a quantity"),
        ("nan", "mm", "is not a quantity"),
        ("", "N", "is not a quantity"),
        ("0.25", "mm", "--radius = 0.25 has no unit: write one, e.g. 0.25m or 0.25mm (an option shown in mm "
                       "takes no bare number; a bare number is SI only where the option is shown in SI)"),
        (0.25, "mm", "--radius = 0.25 has no unit"),
        ("40", "kHz", "--radius = 40 has no unit: write one, e.g. 40Hz or 40kHz"),
        ("1e999", "mm", "--radius = 1e999 has no unit"),
    ],
)
def test_parse_quantity_errors_name_option_value_and_unit(text, unit, fragment):
    with pytest.raises(QuantityError) as info:
        parse_quantity(text, unit, name="--radius")
    assert fragment in str(info.value)
    assert "--radius" in str(info.value)
    assert isinstance(info.value, ValueError)


def test_parse_quantity_rejects_non_finite_and_bool():
    with pytest.raises(QuantityError, match="not a finite number"):
        parse_quantity(float("inf"), "N", name="--preload")
    with pytest.raises(QuantityError, match="not a quantity"):
        parse_quantity(True, "N", name="--preload")


def test_parse_quantities_list():
    assert parse_quantities("0nm,30nm,-10nm,45nm", "nm", name="--path") == [0.0, 30e-9, -10e-9, 45e-9]
    with pytest.raises(QuantityError, match="^--path = 45 has no unit"):
        parse_quantities("0nm,45", "nm", name="--path")
    assert parse_quantities("0.01um, 20 nm", "nm") == [10e-9, 20e-9]
    with pytest.raises(QuantityError, match="comma-separated"):
        parse_quantities("0nm,,3nm", "nm", name="--path")
    with pytest.raises(QuantityError, match="--path = '3N' has the wrong unit"):
        parse_quantities("0nm,3N", "nm", name="--path")


def test_from_si_inverts_parse():
    # Division by the unit factor: a round trip within one rounding (rtol 1e-15).
    assert from_si(202e-9, "nm") == pytest.approx(202.0, rel=1e-15)
    np.testing.assert_allclose(from_si(np.array([1e3, 2e5]), "kHz"), [1.0, 200.0], rtol=1e-15)
    assert dimension_name("N/m") == "stiffness (force per length)"
    assert dimension_name("mm") == "length"


def test_display_factors_are_pints():
    """Bare numbers and output use a table of display-unit factors (no registry at start-up);
    each must be exactly the factor pint gives."""

    for unit, factor in units._DISPLAY_FACTORS.items():
        expected = units.registry().Quantity(1.0, units._unit(unit)).to_base_units().magnitude
        assert factor == expected, unit


def test_display_units_share_a_base_exactly_when_pint_gives_them_one_dimension():
    """A number given in a display unit (``150nm``, ``40kHz``) is read without the registry when
    the unit's base is the expected one; that must be pint's dimension check."""

    assert units._DISPLAY_BASES.keys() == units._DISPLAY_FACTORS.keys()
    for a in units._DISPLAY_BASES:
        for b in units._DISPLAY_BASES:
            same = units._unit(a).dimensionality == units._unit(b).dimensionality
            assert (units._DISPLAY_BASES[a] == units._DISPLAY_BASES[b]) == same, (a, b)


def test_the_unit_registry_is_built_once():
    """pint's registry takes a fraction of a second to build: every parse shares one."""
    assert units.registry() is units.registry()


@pytest.mark.parametrize(("value", "digits", "expected"), [
    (9.75596, 4, 9.755), (9.755, 4, 9.755), (123456.0, 3, 123000.0), (0.0012349, 2, 0.0012)])
def test_round_down_keeps_an_upper_limit_within_it(value, digits, expected):
    shown = units.round_down(value, digits)
    assert shown == pytest.approx(expected, rel=1e-12)
    assert shown <= value
