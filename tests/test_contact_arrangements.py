"""Contact arrangements beyond the paper's one and six contacts (passmd.model.arrangement.ContactGroup):
the normal forces follow from the preload and the contact angles (Eq. 1) and must balance the preload
on each side; the simulator takes any arrangement, and its simulated critical amplitude agrees with the
generalised closed forms (passmd.model.theory: Eq. 10's first fly-back onset max_g u_x,max,g for any
number of groups, Eq. 11 for two groups of any counts, forces and radii)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from passmd.model.arrangement import ONE_CONTACT, side_loads
from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import PAPER_SIX, ContactGroup, Drive
from passmd.model.theory import (
    _six_contact_forces,
    contact_arrangement,
    drive_theory,
    first_flyback_critical_amplitude,
    friction_limit,
    runner_frequency,
)
from passmd.protocols import critical_amplitude

#: The search's final bracket, as in tests/test_critical_amplitude.py.
TOLERANCE = 0.5e-9

#: Four contacts, not the paper's: one at F_p on R = 1 mm, three at F_p/3 on R = 0.5 mm.
ONE_AND_THREE = (ContactGroup(1, load_share=1.0), ContactGroup(3, load_share=1 / 3, radius=0.5e-3))
#: Five contacts in three groups on two sides, one of them given by its normal force: side 1 carries
#: F_p = 0.4 N on one contact, side 2 on 2 × 0.12 N + 2 × 0.08 N.
THREE_GROUPS = (ContactGroup(1, load_share=1.0, side=1), ContactGroup(2, load_share=0.3, side=2),
                ContactGroup(2, normal_force=0.08, side=2))


def _startup_vibration(drive, amplitude, frequency):
    """Amplitude of the runner vibration the ramp's velocity jump leaves: A f / ω_r (m)."""
    return amplitude * frequency / (2 * np.pi * runner_frequency(drive))


def test_paper_six_as_groups_is_the_paper_six():
    six, groups = Drive(), Drive(contact_groups=PAPER_SIX)
    assert groups.contacts == 6
    for key in ("normal_force_N", "presliding_m", "critical_amplitude_flexible_m"):
        np.testing.assert_allclose(drive_theory(groups)[key], drive_theory(six)[key], rtol=1e-15)
    assert friction_limit(groups) == pytest.approx(friction_limit(six), rel=1e-15)


@pytest.mark.parametrize("preload", [1e-3, 0.1, 0.3, 0.4, 0.9, 1.0, 7.3])
def test_paper_six_groups_give_eq1_to_the_last_bit(preload):
    """Two contacts at 45° on one side, four on the other: F_p/(2 sin 45°), F_p/(4 sin 45°) exactly."""
    eq1 = [float(f) for f in _six_contact_forces(np.asarray(preload))]
    for drive in (Drive(preload=preload), Drive(preload=preload, contact_groups=PAPER_SIX)):
        assert drive.contact_layout.normal_forces.tolist() == eq1
    assert Drive(preload=preload, contacts=1).contact_layout.normal_forces.tolist() == [preload]
    assert ONE_CONTACT[0].contact_angle == math.pi / 2


def test_contact_angle_sets_the_normal_force():
    """A V-groove at α carries F_p/(n sin α) per contact; a flat guide (90°) F_p/n; Eq. 1's balance."""
    for degrees in (30.0, 45.0, 60.0, 90.0):
        alpha = math.radians(degrees)
        groups = (ContactGroup(2, contact_angle=alpha), ContactGroup(3, contact_angle=math.pi / 2))
        rows = contact_arrangement(Drive(preload=0.5, contact_groups=groups))
        assert rows[0]["normal_force_N"] == pytest.approx(0.5 / (2 * math.sin(alpha)), rel=1e-15)
        assert rows[1]["normal_force_N"] == pytest.approx(0.5 / 3, rel=1e-15)
        assert [r["side"] for r in rows] == [1, 2] and [r["force_from"] for r in rows] == ["Eq. 1"] * 2
    # a side of a given group and a group taking the rest at its own angle
    mixed = (ContactGroup(1), ContactGroup(2, load_share=0.3, side=2),
             ContactGroup(2, contact_angle=math.pi / 3, side=2))
    with pytest.raises(ValueError, match=r"contact_groups\[0\]: side is not given"):
        Drive(contact_groups=mixed)
    mixed = (ContactGroup(1, side=1), *mixed[1:])
    forces = Drive(contact_groups=mixed).contact_layout.normal_forces
    assert forces[2] == pytest.approx((0.4 - 2 * 0.12) / (2 * math.sin(math.pi / 3)), rel=1e-14)
    assert side_loads(0.4, mixed) == pytest.approx({1: 0.4, 2: 0.4}, rel=1e-14)


@pytest.mark.parametrize(("groups", "fragment"), [
    # shares of 0.9 on 2 + 4 contacts: 5.4 × the preload
    ((ContactGroup(2, load_share=0.9), ContactGroup(4, load_share=0.9)),
     r"contact_groups\[0\]: the normal forces on side 1 do not balance the preload: .* = 0.72 N, "
     r"must be F_p = 0.4 N"),
    ((ContactGroup(2, load_share=0.5), ContactGroup(4, load_share=0.3)),
     r"contact_groups\[1\]: the normal forces on side 2 .* = 0.48 N"),
    ((ContactGroup(1, normal_force=0.5, side=2), ContactGroup(2, side=2), ContactGroup(1, side=1)),
     r"contact_groups\[0\]: their normal forces carry all of the preload on side 2 .* "
     r"nothing for contact_groups\[1\]"),
    # the paper's geometry with the flat guide's shares: side 1 carries 0.707 F_p
    ((ContactGroup(2, load_share=0.5, contact_angle=math.pi / 4), ContactGroup(4, load_share=0.25)),
     r"side 1 do not balance .* 2 × 0.2 N × sin 45°"),
])
def test_unbalanced_groups_are_refused(groups, fragment):
    with pytest.raises(ValueError, match=fragment):
        Drive(contact_groups=groups)


def test_balance_accepts_shares_typed_to_three_digits():
    Drive(contact_groups=(ContactGroup(3, load_share=0.333), ContactGroup(1, load_share=1.0)))
    with pytest.raises(ValueError, match="within 0.5%"):
        Drive(contact_groups=(ContactGroup(3, load_share=0.33), ContactGroup(1, load_share=1.0)))


def test_group_layout_follows_count_share_force_and_radius():
    drive = Drive(contact_groups=THREE_GROUPS)
    theory = drive_theory(drive)
    assert drive.contacts == 5
    assert theory["normal_force_N"] == pytest.approx([0.4, 0.12, 0.08], rel=1e-15)
    assert friction_limit(drive) == pytest.approx(0.2 * (0.4 + 2 * 0.12 + 2 * 0.08), rel=1e-14)
    a = theory["contact_radius_m"]
    one_three = drive_theory(Drive(contact_groups=ONE_AND_THREE))
    # Hertz: a ∝ (F R)^(1/3): the second group has F/3 and R/2
    assert one_three["contact_radius_m"][1] / one_three["contact_radius_m"][0] == pytest.approx(6 ** (-1 / 3))
    assert a[0] > a[1] > a[2]


@pytest.mark.parametrize("groups", [ONE_AND_THREE, THREE_GROUPS], ids=["1+3, two radii", "1+2+2"])
def test_first_flyback_onset_is_the_largest_presliding(groups):
    """As the six-contact test: all contacts slide only when the one with the largest u_x,max does."""
    drive = Drive(actuator_model="rigid", contact_groups=groups)
    onset = first_flyback_critical_amplitude(drive)
    out = critical_amplitude.critical_amplitude(drive, protocol="first", tolerance=TOLERANCE)
    allowed = TOLERANCE / 2 + _startup_vibration(drive, onset, PROTOCOL.drive_frequency) + 0.05e-9
    assert abs(out["critical_amplitude_m"] - onset) <= allowed


def test_steady_state_of_two_groups_follows_eq11():
    """As the six-contact test (Fig. 6a): within 10 % of Eq. 11, nearer it than either group's u_x,max."""
    drive = Drive(actuator_model="rigid", contact_groups=ONE_AND_THREE)
    theory = drive_theory(drive)
    found = critical_amplitude.critical_amplitude(drive, protocol="steady",
                                                  tolerance=TOLERANCE)["critical_amplitude_m"]
    dev = abs(found / theory["critical_amplitude_rigid_m"] - 1)
    assert dev < 0.1
    assert dev < min(abs(found / u - 1) for u in theory["presliding_m"])


@pytest.mark.parametrize(("groups", "fragment"), [
    ((ContactGroup(2, load_share=0.5), "x"), "must be a tuple of ContactGroup"),
])
def test_bad_groups_are_refused(groups, fragment):
    with pytest.raises(ValueError, match=fragment):
        Drive(contact_groups=groups)


@pytest.mark.parametrize(("kwargs", "fragment"), [
    ({"count": 0, "load_share": 0.5}, "count = 0"),
    ({"count": 2, "load_share": 0.5, "normal_force": 0.1}, "give at most one"),
    ({"count": 2, "load_share": -0.5}, "load_share"),
    ({"count": 2, "normal_force": 0.1, "radius": 0.0}, "radius"),
    ({"count": 2, "contact_angle": 0.0}, "contact_angle = 0.0 is out of range"),
    ({"count": 2, "contact_angle": 2.0}, "contact_angle = 2.0 is out of range"),
    ({"count": 2, "side": 3}, "side = 3 is not allowed: must be 1 or 2"),
    ({"count": 2, "side": True}, "side = True"),
])
def test_bad_group_is_refused(kwargs, fragment):
    with pytest.raises(ValueError, match=fragment):
        ContactGroup(**kwargs)
