"""The runner's ringing after a fly-back (passmd.protocols.ringing): measured on a simulated record,
checked against the linear runner-on-contacts frequency and against a record made by other means."""

from __future__ import annotations

import math

import numpy as np
import pytest

from passmd.model import theory
from passmd.model.parameters import Drive
from passmd.protocols import ringing


@pytest.fixture(scope="module")
def drive():
    return Drive(contacts=1, actuator_model="rigid")


def test_swings_of_a_decaying_sine_made_by_other_means():
    """_swings on a damped cosine (no simulator): frequency, first swing and 1/e time to < 1 %."""
    f, a0, tau = 5e3, 40e-9, 3e-3
    t = np.linspace(0.0, 20e-3, 200_001)
    x = a0 * np.exp(-t / tau) * np.cos(2 * np.pi * f * t)
    v = np.gradient(x, t)
    turns, times, swings = ringing._swings(t, x, v, after=0.0)
    assert 1.0 / (turns[2] - turns[0]) == pytest.approx(f, rel=1e-3)
    # a swing is half the change between turning points: a0 e^(-t/τ) at its midpoint, to O((1/(fτ))²)
    expected = a0 * np.exp(-times / tau) * np.cosh(0.25 / (f * tau))
    np.testing.assert_allclose(swings[:50], expected[:50], rtol=1e-3)
    probe = {"swing_times_s": times, "swing_amplitudes_m": swings, "flyback_time_s": 0.0,
             "ringing_frequency_Hz": f, "ringing_amplitude_m": swings[0], "ringing_decay_time_s": tau}
    left = ringing.at_frequency(probe, 100.0)  # the next fly-back 10 ms later
    assert left["ringing_at_next_flyback_m"] == pytest.approx(a0 * math.exp(-10e-3 / tau), rel=2e-3)
    assert left["ringing_affects_steps"]  # 1.4 nm > 0.5 nm
    small = ringing.at_frequency({**probe, "swing_amplitudes_m": swings * 1e-2}, 100.0)
    assert not small["ringing_affects_steps"]


def test_ringing_of_a_drive_is_near_its_linear_frequency_and_decays(drive):
    """The swing after a fly-back runs on the contacts' tangential stiffness: between √(2/3) and 1 times
    √(Σ 2aG*/m_r)/2π (the Masing secant, as Eq. 15's f_s), and it only decays."""
    probe = ringing.stick_ringing(drive, drive.actuator.full_stroke_amplitude)
    ratio = probe["ringing_frequency_Hz"] / theory.runner_frequency(drive)
    assert math.sqrt(2 / 3) <= ratio <= 1.01
    swings = probe["swing_amplitudes_m"]
    assert swings.size > 20 and np.all(np.diff(swings[::2]) <= 1e-3 * swings[0])
    assert 0 < probe["ringing_decay_time_s"] < probe["ringing_hold_s"]
    assert ringing.left_after(probe, 0.0) == swings[0] and ringing.left_after(probe, 1.0) == swings[-1]


def test_turns_ignore_changes_below_the_resolution():
    assert ringing.turns([1.0, 2.0, 3.0, 2.0, 4.0], [0.5] * 5) == [2, 3]
    assert ringing.turns([1.0, 1.2, 1.1, 1.3, 2.0], [0.5] * 5) == []  # wiggles below 0.5: monotone
    assert ringing.turns([1.0, None, 3.0, float("nan"), 2.0], [0.1] * 5) == [2]
