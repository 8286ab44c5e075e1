"""Parameter records: paper values and clear errors on bad input."""

import math

import numpy as np
import pytest

from passmd.model import tables, theory
from passmd.model.parameters import PLAUSIBLE_RANGES, Drive, check_plausible, paper_drive
from passmd.model.tables import (
    MOLYBDENUM,
    PRELOAD_GRIDS,
    STEEL,
    Actuator,
    Amplifier,
    Material,
    actuator_for_radius,
    parameter_table,
)


def test_table2_actuators():
    a1 = actuator_for_radius(1e-3)
    assert (a1.stiffness, a1.mass, a1.full_stroke_amplitude) == (6.5e6, 2.2e-8, 202e-9)
    a2 = actuator_for_radius(0.25e-3)
    assert (a2.stiffness, a2.mass, a2.full_stroke_amplitude) == (4e6, 1.1e-8, 96e-9)
    assert a1.damping_ratio == pytest.approx(0.05, rel=1e-12)


def test_drive_holds_its_eq1_layout_once_and_read_only():
    """Eq. 1 on construction: F_p/(2 sin 45°) on the two contacts of side 1, F_p/(4 sin 45°) on the
    four of side 2; a caller cannot alter the drive's copy, and a changed preload gives a new one."""
    drive = Drive(preload=0.4)
    forces, counts, radii = drive.contact_layout
    s45 = np.sin(np.pi / 4)
    assert forces.tolist() == [0.4 / 2 / s45, 0.4 / 4 / s45] and counts.tolist() == [2, 4]
    assert radii.tolist() == [drive.hemisphere_radius] * 2
    with pytest.raises(ValueError, match="read-only"):
        forces[0] = 1.0
    assert drive.replace(preload=0.8).contact_layout.normal_forces.tolist() == (2 * forces).tolist()


def test_drive_defaults_are_the_paper_drive():
    d = paper_drive()
    assert d.runner_mass == 3e-3 and d.load_cell_stiffness == 2.5e4
    assert d.friction_coefficient == 0.2 and d.contacts == 6
    assert d.effective_load_cell_stiffness == 0.0
    assert d.replace(load_cell=True).effective_load_cell_stiffness == 2.5e4
    assert d.replace(hemisphere_radius=0.25e-3).actuator.stiffness == 4e6
    assert Amplifier().full_stroke_time == pytest.approx(2e-6, rel=1e-12)


def test_parameter_table_and_assumptions():
    rows = parameter_table(paper_drive())
    names = {r["name"] for r in rows}
    assert {"runner_mass", "actuator.viscosity", "hemisphere_material.youngs_modulus"} <= names
    assert all(r["source"] for r in rows)
    assert "actuator_viscosity" in {a.key for a in tables.ASSUMPTIONS}


BAD_NUMBERS = [0.0, -1.0, math.nan, math.inf]


@pytest.mark.parametrize("value", BAD_NUMBERS)
@pytest.mark.parametrize(
    "name",
    ["hemisphere_radius", "preload", "friction_coefficient", "runner_mass", "load_cell_stiffness"],
)
def test_drive_rejects_bad_numbers(name, value):
    with pytest.raises(ValueError, match=rf"^{name} = .*(range|number).*"):
        Drive(**{name: value})


@pytest.mark.parametrize("value", BAD_NUMBERS)
@pytest.mark.parametrize("field,error_name", [
    ("stiffness", "actuator_stiffness"), ("mass", "actuator_mass"),
    ("full_stroke_amplitude", "full_stroke_amplitude"),
])
def test_actuator_rejects_bad_numbers(field, error_name, value):
    kwargs = dict(stiffness=6.5e6, mass=2.2e-8, viscosity=0.04, full_stroke_amplitude=202e-9)
    kwargs[field] = value
    with pytest.raises(ValueError, match=rf"^{error_name} = "):
        Actuator(**kwargs)


@pytest.mark.parametrize("value", [-1.0, math.nan, math.inf])
def test_actuator_rejects_bad_viscosity(value):
    with pytest.raises(ValueError, match=r"^actuator_viscosity = .*>= 0"):
        Actuator(stiffness=6.5e6, mass=2.2e-8, viscosity=value, full_stroke_amplitude=202e-9)


@pytest.mark.parametrize("nu", [-1.0, 0.5, 0.6, -2.0, math.nan])
def test_material_rejects_bad_poisson(nu):
    with pytest.raises(ValueError, match=r"^poissons_ratio = .*> -1 and < 0.5"):
        Material(210e9, nu)


@pytest.mark.parametrize("value", BAD_NUMBERS)
def test_material_rejects_bad_modulus(value):
    with pytest.raises(ValueError, match=r"^youngs_modulus = "):
        Material(value, 0.3)


@pytest.mark.parametrize("value", BAD_NUMBERS)
@pytest.mark.parametrize("name", ["peak_to_peak_voltage", "slew_rate"])
def test_amplifier_rejects_bad_numbers(name, value):
    with pytest.raises(ValueError, match=rf"^{name} = "):
        Amplifier(**{name: value})


def test_choices_and_types():
    with pytest.raises(ValueError, match=r"^contacts = 3 .*1, 6"):
        Drive(contacts=3)
    with pytest.raises(ValueError, match=r"^actuator_model = 'soft'"):
        Drive(actuator_model="soft")
    with pytest.raises(ValueError, match=r"^preload = 'a' is not a number"):
        Drive(preload="a")
    with pytest.raises(ValueError, match=r"^hemisphere_radius = 0.0005 is not a paper radius"):
        paper_drive(0.5e-3)


def test_theory_rejects_bad_arrays():
    with pytest.raises(ValueError, match=r"^preload contains nan"):
        theory.normal_forces(np.array([0.1, np.nan]))
    with pytest.raises(ValueError, match=r"^preload contains -0.1"):
        theory.normal_forces([-0.1])


# --------------------------------------------------------------------------------------
# Plausible ranges (PLAUSIBLE_RANGES): hard limits never lifted, soft ones on request
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("changes, match", [
    ({"friction_coefficient": 2.0}, "friction_coefficient = 2.0 is out of range: must be <= 1"),
    ({"runner_mass": 1e30}, "runner_mass = 1e\\+30 is out of range: must be <= 0.3 kg"),
    ({"preload": 1e-30}, "preload = 1e-30 is out of range: must be >= 0.001 N"),
    ({"load_cell_stiffness": 1e30}, "load_cell_stiffness"),
    ({"hemisphere_material": Material(0.5e9, 0.33)}, "hemisphere_material.youngs_modulus"),
    ({"amplifier": Amplifier(slew_rate=3e19)}, "amplifier.slew_rate"),
])
def test_soft_limits_refuse_and_can_be_lifted(changes, match):
    with pytest.raises(ValueError, match=match):
        Drive(**changes)
    assert Drive(**changes, allow_extrapolation=True)  # exploring beyond Tables 1–2


@pytest.mark.parametrize("changes", [
    {"hemisphere_radius": 1e-30},  # the contact would be larger than the sphere
    {"preload": 1e6},
    {"hemisphere_material": Material(1e-21, 0.33)},
])
def test_hard_limits_are_never_lifted(changes):
    with pytest.raises(ValueError, match="hard limit"):
        Drive(**changes, allow_extrapolation=True)


@pytest.mark.parametrize("changes, match", [
    ({"contacts": 6.0}, "contacts = 6.0 is not allowed"),
    ({"contacts": True}, "contacts = True is not allowed"),
    ({"amplifier": "x"}, "amplifier = 'x' is not an Amplifier"),
    ({"allow_extrapolation": 1}, "allow_extrapolation = 1 is not allowed"),
])
def test_constructors_check_types(changes, match):
    with pytest.raises(ValueError, match=match):
        Drive(**changes)


def test_every_paper_configuration_is_inside_the_soft_limits():
    """Tables 1–2 radii over the preload grids, both runner materials, both actuator models."""
    for radius, grid in PRELOAD_GRIDS.items():
        for preload in grid:
            for runner in (STEEL, MOLYBDENUM):
                for contacts in (1, 6):
                    drive = paper_drive(radius, float(preload), runner_material=runner, contacts=contacts,
                                        friction_coefficient=0.3)
                    check_plausible(drive)  # no allow_extrapolation needed
    assert set(PLAUSIBLE_RANGES) >= {"preload", "friction_coefficient", "runner_mass", "frequency"}
    for rng in PLAUSIBLE_RANGES.values():
        assert rng.reason  # every limit says why


def test_contact_radius_underflow_is_refused_with_the_parameters_named():
    """A preload so small that (3 F R / 4E*)^(1/3) underflows to 0 has no contact to model."""
    from passmd.model.parameters import check_contact_plausible

    with pytest.raises(ValueError, match=r"preload: the Hertz contact radius .* underflows"):
        check_contact_plausible(1e-320, 1e-3, 1e11, allow_extrapolation=True, names="preload")
