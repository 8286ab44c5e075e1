"""Drive files (passmd.model.drive_file, ``--drive FILE``, ``passmd drive``): what a file says is the
drive that runs, bare numbers are SI, options replace the file's values, a refused key or value
is one line naming the file and the key as typed, and ``drive_toml`` round-trips exactly."""

from __future__ import annotations

import json
import math

import pytest

from passmd.cli import main
from passmd.model.drive_file import DRIVE_KEYS, drive_toml, load_drive, read_drive_file, resolve
from passmd.model.parameters import Drive
from passmd.model.tables import RUBY, Actuator, Material, actuator_for_radius, actuator_viscosity

#: The new user's drive of the README (R = 0.5 mm, between Table 2's rows).
MINE = """\
hemisphere_radius = "0.5 mm"
preload = 0.6
friction_coefficient = 0.25
runner_mass = "5 g"
[actuator]
stiffness = "5e6 N/m"
mass = "1.5e-8 kg"
"""


def run(argv, capsys):
    status = main(argv)
    captured = capsys.readouterr()
    return status, captured.out, captured.err


@pytest.fixture
def mine(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text(MINE, encoding="utf-8")
    return path


def test_file_values_units_and_derived_parameters(mine):
    drive = load_drive(mine)
    table2 = actuator_for_radius(0.5e-3)  # interpolated between Table 2's rows
    assert drive.hemisphere_radius == 0.5e-3 and drive.preload == 0.6 and drive.runner_mass == 5e-3
    assert drive.actuator.stiffness == 5e6 and drive.actuator.mass == 1.5e-8
    assert drive.actuator.full_stroke_amplitude == table2.full_stroke_amplitude
    assert drive.actuator.viscosity == actuator_viscosity(5e6, 1.5e-8)  # ζ = 0.05 of the file's k_p, m_a
    _, sources = resolve(read_drive_file(mine))
    assert sources["actuator.full_stroke_amplitude"] == "Table 2 interpolated at R = 0.5 mm"
    assert sources["actuator.viscosity"].startswith("derived from ζ = 0.05")
    assert sources["runner_material.youngs_modulus"] == "default (Table 1)"
    assert sources["preload"] == "given"


def test_bare_numbers_in_a_file_are_si(tmp_path):
    path = tmp_path / "d.toml"
    path.write_text("hemisphere_radius = 0.0005\nrunner_mass = 0.005\n[actuator]\nmass = 1.5e-8\n")
    drive = load_drive(path)
    assert (drive.hemisphere_radius, drive.runner_mass, drive.actuator.mass) == (0.5e-3, 5e-3, 1.5e-8)


@pytest.mark.parametrize("drive", [
    Drive(),
    Drive(hemisphere_radius=0.25e-3, contacts=1, actuator_model="rigid"),
    Drive(hemisphere_radius=0.5e-3, preload=0.6123456789, friction_coefficient=0.25, runner_mass=5.3e-3,
          load_cell=True, hemisphere_material=Material(400e9, 0.29, "sapphire"),
          runner_material=Material(310e9, 0.31, "molybdenum"),
          actuator=Actuator(5e6, 1.5e-8, 0.0123456789, 131e-9)),
    Drive(hemisphere_material=RUBY, actuator=Actuator(6.5e6, 2.2e-8, 0.0, 202e-9), allow_extrapolation=True),
])
def test_drive_toml_reads_back_to_an_equal_drive(drive, tmp_path):
    path = tmp_path / "d.toml"
    path.write_text(drive_toml(drive), encoding="utf-8")
    assert load_drive(path) == drive


def test_template_is_the_papers_drive_with_units_and_sources(tmp_path, capsys):
    status, out, _ = run(["drive", "template"], capsys)
    assert status == 0
    for key in DRIVE_KEYS:
        if key not in ("actuator.damping_ratio", "contact_groups"):  # c_p itself; the preset "contacts"
            assert f"{key.rpartition('.')[2]} = " in out, key
    assert "[[contact_groups]]" in out  # how to describe another arrangement
    assert '"1 mm"' in out and "Table 1" in out and "Table 2" in out and "[kg]" in out
    path = tmp_path / "t.toml"
    path.write_text(out, encoding="utf-8")
    assert load_drive(path) == Drive()


@pytest.mark.parametrize(("text", "fragments"), [
    ("[actuator]\nmass = -1\n", ("actuator.mass = -1 is out of range: must be > 0 kg",)),
    ("actuator.mass = \"3 N\"\n", ("actuator.mass = '3 N' has the wrong unit",)),
    ("preload = 1000\n", ("preload = 1000 is out of range: must be <= 100 N", "allow_extrapolation = true")),
    ("actuator.mas = 1\n", ("unknown key 'actuator.mas'", "actuator.mass")),
    ("contacts = 4\n", ("contacts = 4: must be one of 'one', 'paper-six'",)),
    ("load_cell = 1\n", ("load_cell = 1: must be true or false",)),
    ("[actuator]\nviscosity = 0.1\ndamping_ratio = 0.1\n", ("both given",)),
    ("preload = \n", ("not a TOML file",)),
    # a quantity derived from a key (ζ from c_p) names the key as the file has it, not an option
    ("[actuator]\nviscosity = 8.0\n", ("the damping ratio", "derived from actuator.viscosity = 8.0",
                                        "is 10.58", "must be <= 10",
                                        "lower actuator.viscosity to at most 7.563 (SI)",
                                        "allow_extrapolation = true")),
])
def test_refused_file_is_one_line_naming_file_key_and_range(text, fragments, tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ValueError) as caught:
        load_drive(path)
    status, out, err = run(["theory", "--drive", str(path)], capsys)
    for message in (str(caught.value), err):
        assert message.strip().count("\n") == 0, message
        assert str(path) in message
        for fragment in fragments:
            assert fragment in message, message
    assert status == 2 and out == ""


def test_options_replace_file_values_and_show_says_where_each_came_from(mine, capsys):
    status, out, _ = run(["drive", "show", "--drive", str(mine), "--preload", "0.3", "--json"], capsys)
    assert status == 0
    rows = {row["key"]: row for row in json.loads(out)["parameters"]}
    assert rows["preload"]["value"] == 0.3 and rows["preload"]["source"] == "option --preload"
    assert rows["runner_mass"]["value"] == 5e-3 and rows["runner_mass"]["source"] == f"given in {mine}"
    assert rows["runner_mass"]["unit"] == "kg"
    assert rows["actuator.full_stroke_amplitude"]["source"] == "Table 2 interpolated at R = 0.5 mm"
    assert rows["actuator.viscosity"]["value"] == actuator_viscosity(5e6, 1.5e-8)
    status, out, _ = run(["theory", "--drive", str(mine), "--preload", "0.3", "--json"], capsys)
    drive = json.loads(out)["drive"]
    assert drive["preload_N"] == 0.3 and drive["runner_mass_kg"] == 5e-3
    assert drive["hemisphere_radius_m"] == 5e-4
    status, out, _ = run(["drive", "show", "--drive", str(mine)], capsys)
    assert "Table 2 interpolated at R = 0.5 mm" in out and "option --" not in out


def test_human_output_shows_the_drive_used(mine, capsys):
    status, out, _ = run(["theory", "--drive", str(mine)], capsys)
    assert status == 0
    assert "m_r = 5 g" in out and "k_p = 5e+06 N/m, m_a = 1.5e-08 kg" in out and "A_max = 131.333 nm" in out


@pytest.mark.parametrize(("argv", "fragment"), [
    (["theory", "--actuator-mass", "1.5e-5"], "--actuator-mass = 1.5e-5 has no unit: write one, e.g. "
                                              "1.5e-5kg"),
    (["theory", "--radius", "0.5"], "--radius = 0.5 has no unit"),
    (["run", "--frequency", "40"], "--frequency = 40 has no unit"),
    (["contact", "--path", "0nm,30"], "--path = 30 has no unit"),
])
def test_bare_number_of_an_option_not_shown_in_si_is_refused(argv, fragment, capsys):
    status, out, err = run(argv, capsys)
    assert status == 2 and out == ""
    assert fragment in err and err.count("\n") == 1


def test_bare_number_of_an_option_shown_in_si_is_si(capsys):
    status, out, _ = run(["theory", "--actuator-stiffness", "5e6", "--preload", "0.6", "--json"], capsys)
    drive = json.loads(out)["drive"]
    assert status == 0 and drive["actuator_stiffness_N_per_m"] == 5e6 and drive["preload_N"] == 0.6


def test_readme_drive_file_example_reads(tmp_path):
    import re
    from pathlib import Path

    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text(encoding="utf-8")
    section = readme[readme.index("## Your own drive"):]
    example = re.search(r"```toml\n(.*?)```", section, re.S).group(1)
    path = tmp_path / "mydrive.toml"
    path.write_text(example, encoding="utf-8")
    drive = load_drive(path)
    assert (drive.hemisphere_radius, drive.preload, drive.actuator.mass) == (0.5e-3, 0.6, 1.5e-8)


GROUPS = """\
preload = "0.5 N"
actuator_model = "rigid"
[[contact_groups]]
count = 1
load_share = 1.0
[[contact_groups]]
count = 3
normal_force = "0.1667 N"
radius = "0.5 mm"
"""


def test_contact_groups_from_a_file_run_and_read_back(tmp_path, capsys):
    from passmd.model.parameters import ContactGroup

    path = tmp_path / "groups.toml"
    path.write_text(GROUPS, encoding="utf-8")
    drive = load_drive(path)
    assert drive.contact_groups == (ContactGroup(1, load_share=1.0),
                                    ContactGroup(3, normal_force=0.1667, radius=0.5e-3))
    assert drive.contacts == 4
    again = tmp_path / "again.toml"
    again.write_text(drive_toml(drive), encoding="utf-8")
    assert load_drive(again) == drive
    status, out, _ = run(["run", "--drive", str(path), "--periods", "2", "--max-points", "10", "--json"],
                         capsys)
    data = json.loads(out)
    assert status == 0 and data["drive"]["contacts"] == 4
    assert data["drive"]["contact_groups"][1] == {"count": 3, "load_share": None, "normal_force_N": 0.1667,
                                                  "radius_m": 0.5e-3, "contact_angle_rad": math.pi / 2,
                                                  "side": None}
    status, out, _ = run(["theory", "--drive", str(path), "--contacts", "6", "--json"], capsys)
    assert json.loads(out)["drive"]["contacts"] == 6 and "contact_groups" not in json.loads(out)["drive"]


@pytest.mark.parametrize(("text", "fragment"), [
    ("[[contact_groups]]\ncount = 2\nload_share = 0.5\nnormal_force = 0.2\n",
     "contact_groups[0] gives both load_share and normal_force"),
    ("[[contact_groups]]\ncount = 2\ncontact_angle = 45\n",
     "contact_groups[0].contact_angle = 45 is out of range: must be > 0 and <= 90 deg"),
    ("[[contact_groups]]\ncount = 2\ncontact_angle = \"45 N\"\n",
     "contact_groups[0].contact_angle = '45 N' is not an angle"),
    ("[[contact_groups]]\ncount = 2\nside = 3\n", "contact_groups[0].side = 3: must be 1 or 2"),
    ("preload = 0.9\n[[contact_groups]]\ncount = 2\nload_share = 0.9\n[[contact_groups]]\ncount = 4\n"
     "load_share = 0.9\n",
     "bad.toml: contact_groups[0]: the normal forces on side 1 do not balance the preload"),
    ("[[contact_groups]]\ncount = 0\nload_share = 1.0\n", "contact_groups[0].count = 0: must be an integer"),
    ("[[contact_groups]]\ncount = 2\nshare = 1.0\n", "contact_groups[0].share is not a key of a contact"),
    ("[[contact_groups]]\ncount = 2\nnormal_force = \"2 mm\"\n", "contact_groups[0].normal_force = '2 mm'"),
    ("contacts = \"one\"\n[[contact_groups]]\ncount = 2\nload_share = 0.5\n", "contacts and contact_groups"),
])
def test_bad_contact_groups_are_one_line_naming_the_table(text, fragment, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ValueError) as caught:
        load_drive(path)
    assert fragment in str(caught.value) and "\n" not in str(caught.value)
