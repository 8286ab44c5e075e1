"""Contact arrangements beyond the paper's one and six contacts (passmd.model.parameters.ContactGroup):
the simulator takes any arrangement, and its simulated critical amplitude agrees with the
generalised closed forms (passmd.model.theory: Eq. 10's first fly-back onset max_g u_x,max,g for any
number of groups, Eq. 11 for two groups of any counts, forces and radii)."""

from __future__ import annotations

import numpy as np
import pytest

from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import PAPER_SIX, ContactGroup, Drive
from passmd.model.theory import (
    drive_theory,
    first_flyback_critical_amplitude,
    friction_limit,
    runner_frequency,
)
from passmd.protocols import critical_amplitude as search

#: The search's final bracket, as in tests/test_critical_amplitude.py.
TOLERANCE = 0.5e-9

#: Four contacts, not the paper's: one at F_p on R = 1 mm, three at F_p/3 on R = 0.5 mm.
ONE_AND_THREE = (ContactGroup(1, load_share=1.0), ContactGroup(3, load_share=1 / 3, radius=0.5e-3))
#: Five contacts in three groups, one of them given by its normal force.
THREE_GROUPS = (ContactGroup(1, load_share=0.8), ContactGroup(2, load_share=0.4),
                ContactGroup(2, normal_force=0.1))


def _startup_vibration(drive, amplitude, frequency):
    """Amplitude of the runner vibration the ramp's velocity jump leaves: A f / ω_r (m)."""
    return amplitude * frequency / (2 * np.pi * runner_frequency(drive))


def test_paper_six_as_groups_is_the_paper_six():
    six, groups = Drive(), Drive(contact_groups=PAPER_SIX)
    assert groups.contacts == 6
    for key in ("normal_force_N", "presliding_m", "critical_amplitude_flexible_m"):
        np.testing.assert_allclose(drive_theory(groups)[key], drive_theory(six)[key], rtol=1e-15)
    assert friction_limit(groups) == pytest.approx(friction_limit(six), rel=1e-15)


def test_group_layout_follows_count_share_force_and_radius():
    drive = Drive(contact_groups=THREE_GROUPS)
    theory = drive_theory(drive)
    assert drive.contacts == 5
    assert theory["normal_force_N"] == pytest.approx([0.32, 0.16, 0.1], rel=1e-15)
    assert friction_limit(drive) == pytest.approx(0.2 * (0.32 + 2 * 0.16 + 2 * 0.1), rel=1e-14)
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
    out = search.critical_amplitude(drive, protocol="first", tolerance=TOLERANCE)
    allowed = TOLERANCE / 2 + _startup_vibration(drive, onset, PROTOCOL.drive_frequency) + 0.05e-9
    assert abs(out["critical_amplitude_m"] - onset) <= allowed


def test_steady_state_of_two_groups_follows_eq11():
    """As the six-contact test (Fig. 6a): within 10 % of Eq. 11, nearer it than either group's u_x,max."""
    drive = Drive(actuator_model="rigid", contact_groups=ONE_AND_THREE)
    theory = drive_theory(drive)
    found = search.critical_amplitude(drive, protocol="steady", tolerance=TOLERANCE)["critical_amplitude_m"]
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
    ({"count": 2}, "give exactly one"),
    ({"count": 2, "load_share": 0.5, "normal_force": 0.1}, "give exactly one"),
    ({"count": 2, "load_share": -0.5}, "load_share"),
    ({"count": 2, "normal_force": 0.1, "radius": 0.0}, "radius"),
])
def test_bad_group_is_refused(kwargs, fragment):
    with pytest.raises(ValueError, match=fragment):
        ContactGroup(**kwargs)
