"""Inputs are validated at the boundary, once (the standards: records validate on construction,
public functions check their arguments, internal code trusts them), as a user sees it.

- A refused option is one line naming the option as typed, its value and the allowed range.
- The range that line states is the range that holds all the way to the simulation: a value on
  the stated bound runs to the end, a value just past it is refused by the option. A check inside
  the package with another range (or with the default plausible ranges where the user lifted them
  with ``--allow-extrapolation``) would refuse a value the option accepted, or a run the user
  asked for.
- A drive built with ``allow_extrapolation=True`` is trusted by everything it reaches (its
  contacts, its waveform, the simulation); the public constructors given bare numbers check them.

Runs are one period of a one-contact rigid drive (cheap); each runs to its printed result.
"""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest
from cli_runs import run_main

import passmd
from passmd.model.mdr_contact import MDRContact

#: One run, cheap enough to repeat for every case (a saw-tooth period of a rigid one-contact drive).
CHEAP = ["--contacts", "1", "--actuator", "rigid", "--periods", "1", "--max-points", "10", "--json"]

#: SI per unit of the units the cases type.
SI = {"N": 1.0, "mm": 1e-3, "g": 1e-3, "kHz": 1e3, "nm": 1e-9, "": 1.0}

#: (option, a value far out of range as a user might type it, the unit, where the JSON output
#: shows the value in SI). Both sides of a range where both are limited.
CASES = [
    ("--preload", "1e9", "N", ("drive", "preload_N")),
    ("--preload", "1e-9", "N", ("drive", "preload_N")),
    ("--radius", "1e9", "mm", ("drive", "hemisphere_radius_m")),
    ("--mu", "1e9", "", ("drive", "friction_coefficient")),
    ("--runner-mass", "1e9", "g", ("drive", "runner_mass_kg")),
    ("--runner-mass", "1e-9", "g", ("drive", "runner_mass_kg")),
    ("--frequency", "1e-4", "kHz", ("frequency_Hz",)),
    ("--amplitude", "1e9", "nm", ("amplitude_m",)),
]
IDS = [f"{flag}={value}" for flag, value, _, _ in CASES]

#: A range refusal: the option as typed, its value in the option's unit, the bound and its unit.
REFUSAL = re.compile(r"^passmd run: error: (?P<flag>--[a-z-]+) = (?P<value>\S+)(?: (?P<unit>[^\s(,;]+))? "
                     r"is out of range: must be (?P<op><=|>=|<|>) (?P<bound>\S+?)"
                     r"(?: (?P<bound_unit>[^\s(,;]+))?(?: \(|,|;|$)")


def refusal(argv) -> re.Match:
    """The one line refusing ``argv``, parsed."""
    status, out, err = run_main(argv)
    assert status == 2 and out == "", (status, out, err)
    assert err.count("\n") == 1 and "Traceback" not in err, err
    match = REFUSAL.match(err)
    assert match, err
    return match


def shown_in_json(out: str, path) -> float:
    value = json.loads(out)
    for key in path:
        value = value[key]
    return value


@pytest.mark.parametrize(("flag", "value", "unit", "path"), CASES, ids=IDS)
def test_a_refused_option_is_one_line_naming_it_as_typed_its_value_and_its_range(flag, value, unit, path):
    line = refusal(["run", flag, f"{value}{unit}", *CHEAP])
    assert line["flag"] == flag
    assert float(line["value"]) == float(value)  # the value as typed, in the unit typed
    assert (line["unit"] or "") == unit and (line["bound_unit"] or "") == unit
    assert math.isfinite(float(line["bound"]))


@pytest.mark.parametrize(("flag", "value", "unit", "path"), CASES, ids=IDS)
def test_the_range_a_refusal_states_is_the_range_that_holds_up_to_the_result(flag, value, unit, path):
    line = refusal(["run", flag, f"{value}{unit}", *CHEAP])
    bound, op = float(line["bound"]), line["op"]
    # on the bound as the message shows it (just inside an open one): the whole run, every check
    # inside the package included, accepts it
    inside = line["bound"] if op in ("<=", ">=") else repr(bound * (1 - 1e-6 if op == "<" else 1 + 1e-6))
    status, out, err = run_main(["run", flag, f"{inside}{unit}", *CHEAP])
    assert status == 0, err
    assert shown_in_json(out, path) == pytest.approx(float(inside) * SI[unit], rel=1e-12)
    # just past it: refused by the option, with the same range
    past = bound * (1 + 1e-6) if op.startswith("<") else bound * (1 - 1e-6)
    again = refusal(["run", flag, f"{past!r}{unit}", *CHEAP])
    assert (again["flag"], again["op"], again["bound"]) == (flag, op, line["bound"])


SOFT = [case for case in CASES if case[0] != "--amplitude"]  # the full stroke is a hard limit


@pytest.mark.parametrize(("flag", "value", "unit", "path"), SOFT, ids=[f"{c[0]}={c[1]}" for c in SOFT])
def test_allow_extrapolation_holds_all_the_way_to_the_result(flag, value, unit, path):
    """Past a plausible range, --allow-extrapolation reaches every check the value meets: the run
    ends with the value as typed, not with a refusal from inside the package."""
    line = refusal(["run", flag, f"{value}{unit}", *CHEAP])
    assert line.string.rstrip().endswith("--allow-extrapolation goes beyond it"), line.string
    beyond = float(line["bound"]) * (1.5 if line["op"].startswith("<") else 1 / 1.5)
    status, out, err = run_main(["run", flag, f"{beyond!r}{unit}", "--allow-extrapolation", *CHEAP])
    assert status == 0, err
    assert shown_in_json(out, path) == pytest.approx(beyond * SI[unit], rel=1e-12)
    result = json.loads(out)
    assert all(math.isfinite(x) for x in result["settled_positions_m"]), result


def test_an_extrapolating_drive_is_trusted_by_its_contacts_waveform_and_simulation():
    """Beyond the plausible preload, friction and frequency (each lifted by the drive's
    ``allow_extrapolation``), nothing the drive reaches refuses it again."""
    with pytest.raises(ValueError, match=r"^preload = 150\.0 is out of range: must be <= 100 N"):
        passmd.Drive(contacts=1, actuator_model="rigid", preload=150.0)
    drive = passmd.Drive(contacts=1, actuator_model="rigid", preload=150.0, friction_coefficient=1.5,
                         allow_extrapolation=True)
    contact = MDRContact.for_drive(drive)
    assert contact.normal_force == pytest.approx(150.0, rel=1e-12)
    wave = passmd.sawtooth(100e-9, 0.5, drive, periods=1)  # 0.5 Hz: below the plausible 1 Hz
    result = passmd.simulate(drive, wave, max_points=10)
    assert np.isfinite(result.runner_position).all() and result.settled_positions[-1] > 0.0


def test_a_drives_contact_is_the_one_the_public_constructor_builds():
    """The contact of a drive is the contact its checked numbers describe, bit for bit."""
    drive = passmd.Drive()
    contact = MDRContact.for_drive(drive, side=1)
    same = MDRContact(contact.normal_force, drive.hemisphere_radius, contact.E_star, contact.G_star,
                      drive.friction_coefficient)
    assert (same.params == contact.params).all()


@pytest.mark.parametrize(("position", "name"), list(enumerate(["normal_force", "radius", "E_star",
                                                                "G_star", "mu"])))
def test_the_public_contact_constructor_checks_each_bare_number(position, name):
    contact = MDRContact.for_drive(passmd.Drive())
    numbers = [contact.normal_force, contact.hemisphere_radius, contact.E_star, contact.G_star,
               contact.friction_coefficient]
    numbers[position] = -1.0
    with pytest.raises(ValueError, match=rf"^{name} = -1\.0 is out of range"):
        MDRContact(*numbers)
