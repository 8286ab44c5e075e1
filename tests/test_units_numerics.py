"""Units by their physical meaning, range checks on the parsed value, closed forms that never
underflow, public closed forms that check their arguments, and result tables that are finite.

* A frequency counts cycles: 1 rpm is 1/60 Hz and one turn (revolution, cycle) per second is
  1 Hz. The units library reads a revolution as 2π radians and a radian as a plain number, so
  without a check ``100 rpm`` would be 10.47 Hz and ``628.3185 rad/s`` 628.3 Hz; an angular rate
  is refused with the hint f = ω/2π, an angle anywhere else is refused.
* A range check compares the parsed value (``0.4999999999999`` is a Poisson's ratio below 1/2)
  and its message shows digits that read back as that value.
* Teidelt's harmonic combination (Eqs. 11–12) is finite and between min(u₁, u₂) and twice it at
  every magnitude; a closed-form result below the smallest normal double is refused, naming the
  parameter.
* ``figure`` and ``ledger`` refuse a non-finite result cell (exit 1, one line naming the table
  and the column), except the cells a figure leaves empty by design.

Tolerances: a quantity in a unit outside the display table is the decimal number times pint's
factor, each rounded once, so it is within 2 units in the last place (rel 2**-51) of the exact
product; the harmonic combination's two forms each round at most four times (rel 2**-50).
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import subprocess
import sys
from fractions import Fraction
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from passmd import cli
from passmd.cli.result_bounds import EMPTY_BY_DESIGN, ResultError, check_table
from passmd.experiments import figure_table
from passmd.model import hertz, theory
from passmd.model.parameters import Drive
from passmd.model.tables import RUBY, STEEL
from passmd.report import evaluation
from passmd.runtime.units import _CYCLE_UNITS, QuantityError, parse_quantity, registry, to_display
from passmd.runtime.validation import check_array, check_range, format_number

TWO_ULP = 2.0**-51  # a unit factor and a decimal product, each rounded once
FOUR_ROUNDINGS = 2.0**-50  # the harmonic combination's scaled form
E_STAR, G_STAR = 150.337243e9, 120.629884e9  # Table 1's ruby on steel (test_theory's hand values)


def passmd(*argv, timeout=300):
    """``python -m passmd argv`` in a subprocess: (status, stdout, stderr)."""
    env = {**os.environ, "MPLBACKEND": "Agg"}
    done = subprocess.run([sys.executable, "-m", "passmd", *argv], capture_output=True, text=True, env=env,
                          timeout=timeout)
    return done.returncode, done.stdout, done.stderr


def assert_one_line(err: str):
    assert err.count("\n") == 1 and err.startswith("passmd") and "Traceback" not in err, err


def run_in_process(argv):
    """(status, stdout, stderr) of ``passmd argv`` in this process (for monkeypatched tables)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stderr(err):
        status = cli.main(list(argv), out=out)
    return status, out.getvalue(), err.getvalue()


# ======================================================================================
# Units by their physical meaning
# ======================================================================================


@pytest.mark.parametrize("json_output", [True, False], ids=["json", "text"])
def test_rpm_frequency_runs_at_one_sixtieth_hertz_per_rpm(json_output):
    """``--frequency '100 rpm'`` is 100/60 Hz = 1.667 Hz (the units library alone gives 10.47 Hz)."""
    argv = ["run", "--frequency", "100 rpm", "--periods", "1", "--max-points", "100", "--actuator", "rigid"]
    status, out, err = passmd(*argv, *(["--json"] if json_output else []))
    assert status == 0, err
    if json_output:
        assert json.loads(out)["frequency_Hz"] == pytest.approx(100 / 60, rel=TWO_ULP)
    else:
        assert "f = 0.00166667 kHz" in out  # 1.66667 Hz, six digits of the text output


@pytest.mark.parametrize("json_output", [True, False], ids=["json", "text"])
def test_angular_rate_frequency_is_refused_with_the_two_pi_hint(json_output):
    """``--frequency '628.3185 rad/s'`` is an angular frequency ω: refused, naming f = ω/2π ≈ 100 Hz."""
    status, out, err = passmd("run", "--frequency", "628.3185 rad/s", *(["--json"] if json_output else []))
    assert status == 2 and out == ""
    assert_one_line(err)
    assert "--frequency = '628.3185 rad/s' is an angular rate" in err
    assert "divide an angular frequency ω by 2π to get Hz (f = ω/2π ≈ 100 Hz here)" in err


#: Units a frequency may be given in, with their size in Hz typed by hand (not from pint).
CYCLES = {"Hz": 1.0, "kHz": 1e3, "MHz": 1e6, "mHz": 1e-3, "1/s": 1.0, "/s": 1.0, "1/min": 1 / 60,
          "/min": 1 / 60, "1/h": 1 / 3600, "rpm": 1 / 60, "krpm": 1000 / 60, "rps": 1.0, "turn/s": 1.0,
          "turn/min": 1 / 60, "cycle/s": 1.0, "cycle/ms": 1e3, "revolution/minute": 1 / 60, "kiloturn/s": 1e3}
#: Angular rates: refused as frequencies.
ANGULAR = ("rad/s", "mrad/s", "rad/min", "deg/s", "degree/second", "arcmin/s", "grade/s", "turn*rad/s")


@pytest.mark.parametrize(("unit", "hz"), CYCLES.items())
def test_cycle_units_count_one_cycle_each(unit, hz):
    assert parse_quantity(f"100 {unit}", "kHz", name="--frequency") == pytest.approx(100 * hz, rel=TWO_ULP)


@pytest.mark.parametrize("unit", ANGULAR)
def test_angular_rates_are_refused_as_frequencies(unit):
    with pytest.raises(QuantityError, match=r"is an angular rate .*\(f = ω/2π ≈ .* Hz here\)$") as info:
        parse_quantity(f"6.283185307179586 {unit}", "kHz", name="--frequency")
    assert "\n" not in str(info.value)


def test_angular_frequency_hint_divides_by_two_pi():
    """The hint is ω/2π in Hz whatever the angle unit: 360 deg/s and 2π rad/s are 1 Hz."""
    for text in ("360 deg/s", "6.283185307179586 rad/s", "21600 arcmin/s"):
        with pytest.raises(QuantityError, match=r"≈ 1 Hz here"):
            parse_quantity(text, "kHz", name="--frequency")


@pytest.mark.parametrize(("text", "unit"), [
    ("0.2 rad", ""), ("11.46 deg", ""), ("1 turn", ""), ("1 cycle", ""), ("0.001 rad*m", "mm"),
    ("1 N*rad", "N"), ("1 s/turn", "us"), ("2 turn**2/s", "kHz")])
def test_angles_outside_a_frequency_are_refused(text, unit):
    """An angle (or a cycle count) has no meaning in a length, force, time or plain number; the
    units library would read ``0.2 rad`` as 0.2 and ``1 turn`` as 6.28."""
    with pytest.raises(QuantityError, match="has the wrong unit") as info:
        parse_quantity(text, unit, name="--mu")
    assert "\n" not in str(info.value)


def test_every_angle_unit_of_the_units_library_is_classified():
    """Each unit of pint's registry whose root holds a radian is either a full-cycle unit of
    ``_CYCLE_UNITS`` (read as one cycle per turn) or refused in a frequency: no unit slips
    through with a 2π factor."""
    reg = registry()
    assert {reg.get_name(n) for n in ("turn", "cycle", "revolution", "circle")} == {"turn"}
    assert _CYCLE_UNITS == {"turn", reg.get_name("rpm"), reg.get_name("rps")}
    angular = set()
    for name in list(reg._units):
        try:
            canonical = reg.get_name(name)
            root = reg.get_root_units(canonical)[1]
        except Exception:  # units pint itself cannot reduce (none of them is an angle)
            continue
        radians = dict(reg.Quantity(1.0, root).unit_items()).get("radian", 0)
        if radians:
            angular.add((canonical, radians))
    assert {"turn", "radian", "degree", "revolutions_per_minute"} <= {n for n, _ in angular}
    for name, radians in sorted(angular):
        per_time = "" if radians == 1 and "per" in name else "/s"  # rpm, rps are rates already
        text = f"1 {name}{per_time}"
        physical = reg.Quantity(1.0, f"{name}{per_time}")
        if reg.parse_unit_name(name)[0][1] in _CYCLE_UNITS:  # krpm: a prefixed full-cycle unit
            assert parse_quantity(text, "kHz") == pytest.approx(physical.to("turn/s").magnitude, rel=TWO_ULP)
        else:
            with pytest.raises(QuantityError):
                value = parse_quantity(text, "kHz")
                pytest.fail(f"{text!r} accepted as {value!r} Hz")


_PREFIXES = st.sampled_from(["", "k", "M", "m"])
_NUMBERS = st.decimals(min_value="1e-6", max_value="1e6", allow_nan=False, allow_infinity=False, places=6)


@settings(max_examples=300, deadline=None)
@given(number=_NUMBERS, unit=st.sampled_from([*CYCLES, *ANGULAR, "", "Hz", "turn/s", "rpm"]),
       prefix=_PREFIXES, space=st.sampled_from(["", " "]))
def test_frequency_grammar_is_physical_or_refused(number, unit, prefix, space):
    """Hypothesis over the frequency grammar (number, optional prefix, cycle or angular unit, or
    a bare number, refused in kHz): the value is the physical one, or a one-line refusal; never a 2π
    factor."""
    space = " " if unit[:1].isdigit() else space  # "2 1/s": "21/s" would be 21 per second
    text = f"{number}{space}{prefix if unit and unit[0].isalpha() else ''}{unit}"
    try:
        value = parse_quantity(text, "kHz", name="--frequency")
    except QuantityError as exc:
        message = str(exc)
        shown = text.strip() if not unit else repr(text)  # a bare number is refused as typed
        assert "\n" not in message and message.startswith(f"--frequency = {shown}")
        assert unit or "has no unit" in message
        return
    pint_unit = f"{prefix}{unit}" if unit and unit[0].isalpha() else unit
    assert unit not in ANGULAR, f"angular rate {text!r} accepted as {value} Hz"
    assert unit, f"bare number {text!r} read in kHz"
    if pint_unit in CYCLES:
        hz = CYCLES[pint_unit]
    else:  # a prefixed cycle unit: the prefix times the hand-typed size
        hz = {"k": 1e3, "M": 1e6, "m": 1e-3}[prefix] * CYCLES[unit]
    expected = float(number) * hz
    assert value == pytest.approx(expected, rel=2 * TWO_ULP, abs=0.0)
    for wrong in (expected * 2 * math.pi, expected / (2 * math.pi)):
        assert not math.isclose(value, wrong, rel_tol=1e-6)


@settings(max_examples=200, deadline=None)
@given(number=_NUMBERS, unit=st.sampled_from(["", "%", "percent", "rad", "deg", "turn", "cycle", "mrad",
                                              "grade", "arcsec", "rpm*s"]))
def test_plain_number_grammar_refuses_angles(number, unit):
    """A plain number (``--mu``, the Poisson's ratios) takes a bare number or a percentage, never
    an angle or a cycle count (pint reads them as plain numbers 1 and 2π)."""
    text = f"{number} {unit}".strip()
    try:
        value = parse_quantity(text, "", name="--mu")
    except QuantityError as exc:
        assert unit not in ("", "%", "percent") and "\n" not in str(exc)
        return
    assert unit in ("", "%", "percent")
    assert value == pytest.approx(float(number) * (0.01 if unit else 1.0), rel=TWO_ULP)


# ======================================================================================
# Range checks on the parsed value, with true messages
# ======================================================================================


@pytest.mark.parametrize("json_output", [True, False], ids=["json", "text"])
def test_poisson_ratio_just_below_one_half_is_accepted(json_output):
    """0.4999999999999 < 1/2: accepted (it was rounded to 0.5 and refused as "= 0.5")."""
    status, out, err = passmd("theory", "--runner-poisson", "0.4999999999999",
                              *(["--json"] if json_output else []))
    assert status == 0, err
    if json_output:
        assert json.loads(out)["drive"]["runner_poissons_ratio"] == 0.4999999999999


@pytest.mark.parametrize("json_output", [True, False], ids=["json", "text"])
def test_poisson_ratio_just_above_minus_one_is_accepted_beyond_the_plausible_range(json_output):
    """-0.9999999999999 > -1: inside the hard limit of isotropic elasticity, outside the plausible
    range (refused naming its true value), accepted with --allow-extrapolation."""
    flag = ["--json"] if json_output else []
    status, _, err = passmd("theory", "--runner-poisson", "-0.9999999999999", *flag)
    assert status == 2
    assert_one_line(err)
    assert "= -0.9999999999999 is out of range: must be >= 0" in err and "-1.0" not in err
    status, _, err = passmd("theory", "--runner-poisson", "-0.9999999999999", "--allow-extrapolation", *flag)
    assert status == 0, err


@pytest.mark.parametrize(("argv", "shown"), [
    (["--runner-poisson", "0.5000000000001"], "--runner-poisson = 0.5000000000001 is out of range"),
    (["--hemisphere-poisson", "0.5"],
     "--hemisphere-poisson = 0.5 is out of range: must be a finite number > -1 and < 0.5"),
    (["--preload", "0.99999999999mN"],
     "--preload = 0.99999999999mN (= 0.00099999999999 N) is out of range: must be >= 0.001 N"),
    (["--radius", "0.0099999999mm"], "--radius = 0.0099999999 mm is out of range: must be >= 0.01 mm"),
    (["--hemisphere-modulus", "0.999999999999GPa"], "= 0.999999999999 GPa is out of range: must be >= 1 GPa"),
])
def test_range_messages_show_the_parsed_value_to_enough_digits(argv, shown):
    """A refused value is never shown equal to the bound it violates."""
    for flag in (["--json"], []):
        status, _, err = passmd("theory", *argv, *flag)
        assert status == 2
        assert_one_line(err)
        assert shown in err


def test_format_number_reads_back_as_the_same_float():
    assert format_number(0.5) == "0.5" and format_number(-1.0) == "-1" and format_number(1e-9) == "1e-09"
    assert format_number(0.4999999999999) == "0.4999999999999"
    assert format_number(2.5e-4, 1e-3) == "0.25"  # a decimal division: not 0.25000000000000006
    assert format_number(310e9, 1e9) == "310" and format_number(float("nan")) == "nan"
    for x in (0.1 + 0.2, 1 / 3, 5e-324, 1.7976931348623157e308, -2.2250738585072014e-308):
        assert float(format_number(x)) == x


def test_validation_messages_show_numpy_values_as_numbers():
    with pytest.raises(ValueError, match=r"^x = 1e\+300 is out of range: must be a finite number <= 10 "):
        check_range("x", np.float64(1e300), upper=10.0, unit="–")
    with pytest.raises(ValueError, match=r"^x contains 0.4999999999999, which is out of range: every element "
                                         r"must be a finite number >= 0.5$"):
        check_array("x", [1.0, 0.4999999999999], 0.5)
    with pytest.raises(ValueError, match="x = '0.4' is not a number"):
        check_array("x", "0.4")
    with pytest.raises(ValueError, match="x = True is not a number"):
        check_array("x", True)


@settings(max_examples=300, deadline=None)
@given(number=st.decimals(min_value="-1e6", max_value="1e6", allow_nan=False, places=9),
       unit=st.sampled_from(["", "nm", "mm", "N", "mN", "g", "kHz", "GPa", "N/m", "V/us"]))
def test_display_value_of_a_parsed_quantity_is_the_typed_number(number, unit):
    """Range checks compare ``to_display(parse_quantity(text))``: the typed number itself for a
    plain number, within one unit in the last place of it otherwise (never a rounded copy)."""
    value = parse_quantity(f"{number}{unit}", unit)
    shown = to_display(value, unit)
    if not unit:
        assert shown == value == float(number)
    else:
        assert abs(shown - float(number)) <= math.ulp(float(number))


# ======================================================================================
# Numerically safe closed forms
# ======================================================================================

_MAGNITUDES = st.builds(lambda m, e: m * 10.0**e, st.floats(1.0, 10.0, exclude_max=True),
                        st.integers(-300, 299))


@settings(max_examples=500, deadline=None)
@given(u1=_MAGNITUDES, u2=_MAGNITUDES)
def test_harmonic_combination_is_finite_and_between_min_and_twice_min(u1, u2):
    """Eqs. 11–12 over 1e-300 … 1e300: finite, min(u₁, u₂) <= h <= 2 min(u₁, u₂), symmetric, and
    within four roundings of the exact 2 u₁ u₂ / (u₁ + u₂) (the paper's form underflows to 0 or
    overflows to inf/nan over most of this range)."""
    h = float(theory.harmonic_combination(u1, u2))
    small = min(u1, u2)
    assert math.isfinite(h) and small <= h <= 2.0 * small
    assert h == float(theory.harmonic_combination(u2, u1))
    exact = Fraction(2) * Fraction(u1) * Fraction(u2) / (Fraction(u1) + Fraction(u2))
    assert abs(Fraction(h) - exact) <= exact * Fraction(FOUR_ROUNDINGS)


def test_harmonic_combination_keeps_the_papers_form_at_ordinary_magnitudes():
    """Where 2 u₁ u₂ and u₁ + u₂ are normal doubles the result is the paper's expression bit for
    bit: every ledger baseline and snapshot was computed with it."""
    rng = np.random.default_rng(7)
    u1, u2 = 10.0 ** rng.uniform(-12, -3, 2000), 10.0 ** rng.uniform(-12, -3, 2000)
    np.testing.assert_array_equal(theory.harmonic_combination(u1, u2), 2.0 * u1 * u2 / (u1 + u2))
    assert float(theory.harmonic_combination(1e-300, 1e-300)) == 1e-300  # the paper's form gives 0
    assert float(theory.harmonic_combination(1e300, 1e300)) == 1e300  # ... and inf / inf = nan


@pytest.mark.parametrize("json_output", [True, False], ids=["json", "text"])
def test_theory_at_a_preload_below_double_precision_is_refused_naming_the_preload(json_output):
    """``passmd theory --preload 1e-300 --allow-extrapolation``: the Hertz contact radius cubed is
    subnormal there (A_c would print as 0 nm), so it is refused, naming the option as typed."""
    status, out, err = passmd("theory", "--preload", "1e-300", "--allow-extrapolation",
                              *(["--json"] if json_output else []))
    assert status == 2 and out == ""
    assert_one_line(err)
    assert "--preload 1e-300" in err and "below the smallest normal double" in err


@pytest.mark.parametrize("json_output", [True, False], ids=["json", "text"])
def test_theory_at_a_tiny_representable_preload_is_finite_and_positive(json_output):
    """At 1e-290 N every closed form is a normal double; A_c lies between the two sides' presliding
    displacements (Eq. 11: between min(u₁, u₂) and twice it)."""
    status, out, err = passmd("theory", "--preload", "1e-290", "--allow-extrapolation",
                              *(["--json"] if json_output else []))
    assert status == 0, err
    if not json_output:
        assert "A_c, rigid actuators (Eq. 7/11)        0 nm" not in out
        assert "e-192 nm" in out  # A_c ≈ 2.07e-192 nm
        return
    data = json.loads(out)
    u1, u2 = data["presliding_m"]
    assert min(u1, u2) <= data["critical_amplitude_rigid_m"] <= 2 * min(u1, u2)
    for key in ("contact_radius_m", "indentation_m", "presliding_m", "actuator_deformation_m"):
        assert all(x >= np.finfo(float).tiny for x in data[key]), key


@pytest.mark.parametrize(("call", "message"), [
    (lambda: hertz.hertz_contact_radius(1e-300, 1e-3, E_STAR),
     r"^normal_force = 1e-300 N \(with radius = 0.001 m, E_star = 150337243000.0 Pa\) is out of range: the "
     r"Hertz "
     r"contact radius cubed"),
    (lambda: theory.presliding_displacement(0.4, 1e-3, E_STAR, G_STAR, 1e-310),
     r"^normal_force = 0.4 N \(with friction_coefficient = 1e-310\) is out of range: the presliding"),
    (lambda: theory.actuator_deformation(0.2, 1e-303, 6.5e6, 3e-3, 2.2e-8),
     r"^normal_force = 1e-303 N .* the actuator deformation u_x,a = .* m is below the smallest normal"),
    (lambda: theory.normal_forces(1e-308),
     r"^preload = 1e-308 N is out of range: the normal force per contact"),
    (lambda: hertz.hertz_normal_force(1e-110, 1e-3, E_STAR), r"^contact_radius = 1e-110 m is out of range"),
    (lambda: theory.drive_theory(Drive(preload=1e-300, allow_extrapolation=True)),
     r"^preload = 1e-300 N \(with hemisphere_radius = 0.001 m, E\* = .* Pa\) is out of range"),
    (lambda: theory.drive_theory(Drive(friction_coefficient=1e-305, allow_extrapolation=True)),
     r"^preload = 0.4 N \(with friction_coefficient = 1e-305\) is out of range: the presliding displacement"),
])
def test_closed_forms_refuse_results_below_double_precision(call, message):
    """A positive result below 2.2e-308 keeps a few significant digits: refused, naming the
    parameter (its value and the others it was computed from) and the limit."""
    with pytest.raises(ValueError, match=message) as info:
        call()
    assert "(hard limit: double precision" in str(info.value)


def test_closed_forms_keep_zero_force_at_zero():
    """F_N = 0 is no contact, not an underflow: a = 0, u_x,max = 0."""
    np.testing.assert_array_equal(hertz.hertz_contact_radius([0.0, 0.4], 1e-3, E_STAR)[:1], [0.0])
    assert float(theory.presliding_displacement(0.0, 1e-3, E_STAR, G_STAR, 0.2)) == 0.0
    assert float(theory.actuator_deformation(0.2, 0.0, 6.5e6, 3e-3, 2.2e-8)) == 0.0


# ======================================================================================
# Public closed forms check their arguments
# ======================================================================================

_NU, _E = RUBY.poissons_ratio, RUBY.youngs_modulus


@pytest.mark.parametrize(("call", "error", "message"), [
    (lambda: hertz.effective_youngs_modulus(-1, _NU, STEEL.youngs_modulus, _NU), ValueError,
     r"^E1 contains -1, which is out of range: every element must be a finite number > 0 \(Pa\)$"),
    (lambda: hertz.effective_shear_modulus(_E, -1.0, STEEL.youngs_modulus, _NU), ValueError,
     r"^nu1 contains -1, which is out of range: every element must be a finite number > -1 and <= 0.5$"),
    (lambda: hertz.effective_youngs_modulus(_E, _NU, STEEL.youngs_modulus, 0.6), ValueError,
     r"^nu2 contains 0.6"),
    (lambda: theory.presliding_displacement(0.4, 1e-3, E_STAR, G_STAR, friction_coefficient=-0.2), ValueError,
     r"^friction_coefficient contains -0.2, which is out of range: every element must be a finite .* > 0$"),
    (lambda: theory.presliding_displacement(0.4, 1e-3, E_STAR, G_STAR, mu=-0.2), TypeError, "mu"),
    (lambda: theory.presliding_displacement(-0.4, 1e-3, E_STAR, G_STAR, 0.2), ValueError,
     r"^normal_force contains -0.4, .* >= 0 \(N\)$"),
    (lambda: theory.presliding_displacement(0.4, 0.0, E_STAR, G_STAR, 0.2), ValueError,
     r"^radius contains 0, "),
    (lambda: theory.normal_forces(0.4, contacts=True), TypeError,
     r"^contacts = True is not allowed: must be the integer 1 or 6$"),
    (lambda: theory.normal_forces(0.4, contacts=3), ValueError,
     r"^contacts = 3 is not allowed: must be one of 1, 6$"),
    (lambda: theory.normal_forces(0.4, contacts=6.0), TypeError, r"^contacts = 6.0 is not allowed"),
    (lambda: theory.normal_forces("0.4"), ValueError, r"^preload = '0.4' is not a number"),
    (lambda: theory.drive_theory("not a drive"), TypeError,
     r"^drive = 'not a drive' is not allowed: must be a passmd.model.parameters.Drive$"),
    (lambda: theory.contact_moduli(None), TypeError, r"^drive = None is not allowed"),
    (lambda: theory.runner_frequency(3), TypeError, r"^drive = 3 is not allowed"),
    (lambda: theory.friction_limit({}), TypeError, r"^drive = \{\} is not allowed"),
    (lambda: hertz.hertz_contact_radius(0.4, 1e-3, -E_STAR), ValueError,
     r"^E_star contains -150337243000.0, "),
    (lambda: hertz.tangential_stiffness(0.4, 1e-3, E_STAR, 0.0), ValueError, r"^G_star contains 0, "),
    (lambda: theory.actuator_deformation(0.2, 0.4, 6.5e6, 0.0, 2.2e-8), ValueError,
     r"^runner_mass contains 0, "),
    (lambda: theory.harmonic_combination(-1e-9, 2e-9), ValueError, r"^u1 contains -1e-09, .* > 0 \(m\)$"),
    (lambda: theory.harmonic_combination(1e-9, np.inf), ValueError, r"^u2 contains inf, "),
    (lambda: hertz.cattaneo_mindlin_force(1e-9, 0.4, 0.0, 0.2), ValueError, r"^presliding contains 0, "),
    (lambda: hertz.masing_branch_force(0.0, 1e-9, 0.01, 0, 0.4, 4e-8, 0.2), ValueError,
     r"^direction = 0 is not allowed: must be one of 1, -1$"),
    (lambda: hertz.masing_branch_force(np.nan, 1e-9, 0.01, 1, 0.4, 4e-8, 0.2), ValueError,
     r"^u contains nan"),
])
def test_public_closed_forms_refuse_bad_arguments(call, error, message):
    """Negative moduli, ν outside (-1, 1/2], μ <= 0, ``contacts=True`` and a non-drive are refused
    naming the parameter, never turned into negative moduli or displacements or an AttributeError."""
    with pytest.raises(error, match=message):
        call()


# ======================================================================================
# figure and ledger: every result column finite
# ======================================================================================


@pytest.fixture
def nan_figure(monkeypatch):
    """A stand-in panel fig99z whose (e.g. cached) result holds a NaN in a computed column."""
    spec = SimpleNamespace(name="fig99z", title="a stand-in panel")
    frame = pd.DataFrame({"amplitude_nm": [10.0, 20.0, 30.0], "steady_step_nm": [0.0, np.nan, 5.0],
                          "actuator_model": ["rigid"] * 3})
    monkeypatch.setattr(figure_table, "figure_names", lambda: ["fig99z"])
    monkeypatch.setattr(figure_table, "figure_spec", lambda name: spec)
    monkeypatch.setattr(figure_table, "figure_data", lambda name, config: frame)
    monkeypatch.setattr(figure_table, "figure_plot",
                        lambda name, data: pytest.fail("plotted a non-finite result"))
    return frame


@pytest.mark.parametrize("json_output", [True, False], ids=["json", "text"])
def test_figure_with_a_nan_result_exits_1_naming_the_figure_and_column(nan_figure, tmp_path, json_output):
    status, out, err = run_in_process(["figure", "fig99z", "--profile", "quick", "--out", str(tmp_path),
                                       "--executor", "serial", *(["--json"] if json_output else [])])
    assert status == 1 and out == ""
    assert_one_line(err)
    assert "fig99z: column steady_step_nm is not finite (nan in row 1, 1 of 3 rows)" in err
    assert list(tmp_path.iterdir()) == []  # nothing written


@pytest.mark.parametrize("json_output", [True, False], ids=["json", "text"])
def test_ledger_with_a_nan_result_exits_1_naming_the_table_and_column(monkeypatch, tmp_path, json_output):
    def damaged(config):
        table = evaluation.closed_form_results(config).copy()
        table.loc[2, "tangential_stiffness_N_per_m"] = np.nan
        return {"closed_forms": table}

    monkeypatch.setattr(evaluation, "collect_results", damaged)
    baseline = tmp_path / "baseline.csv"
    status, out, err = run_in_process(["ledger", "--write-baseline", str(baseline),
                                       *(["--json"] if json_output else [])])
    assert status == 1 and out == "" and not baseline.exists()
    assert_one_line(err)
    assert "closed_forms: column tangential_stiffness_N_per_m is not finite (nan in row 2" in err


def test_cells_empty_by_design_pass_and_infinities_never_do():
    """A figure's declared empty cells (e.g. no critical amplitude up to the full stroke) pass;
    the same NaN in an undeclared figure, or an infinity anywhere, is refused."""
    assert set(EMPTY_BY_DESIGN) <= set(figure_table.figure_names()) | set(figure_table.READING_TABLES)
    frame = pd.DataFrame({"preload_N": [0.1, 0.2], "critical_amplitude_nm": [25.0, np.nan],
                          "bracket_high_nm": [26.0, np.nan], "actuator_model": ["rigid", "rigid"]})
    check_table("fig5b", frame)
    with pytest.raises(ResultError, match="fig5a: column critical_amplitude_nm is not finite"):
        check_table("fig5a", frame)
    with pytest.raises(ResultError, match=r"fig5b: column critical_amplitude_nm is not finite \(inf in row"):
        check_table("fig5b", frame.assign(critical_amplitude_nm=[25.0, np.inf]))
    check_table("fig5b", frame.assign(label=[None, "x"], flag=[True, False]))  # text and flags are no results
