"""The steady step of a running drive (``velocity.settled_step``): a run counts as settled when it
repeats itself from one period to the next, and its step then agrees with a long run's."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from passmd.model import contact, waveforms
from passmd.model.contact_kernels import STATE_HEADER
from passmd.model.parameters import Drive
from passmd.protocols import velocity
from passmd.solver import periodicity, simulation


def _drive(contacts, model, preload, mu, runner_mass, stiffness, mass, zeta):
    base = Drive()
    viscosity = 2 * zeta * math.sqrt(stiffness * mass)
    act = replace(base.actuator, stiffness=stiffness, mass=mass, viscosity=viscosity)
    return replace(base, contacts=contacts, actuator_model=model, preload=preload, friction_coefficient=mu,
                   runner_mass=runner_mass, actuator=act, allow_extrapolation=True)


#: Drives whose runs from rest settle slowly or ring (random drives of a settling study).
#: The first: one flexible contact at 854 Hz, ζ = 0.012; a state tolerance 25 times the default
#: takes its step 0.12 nm away from the long run's.
RINGING = (_drive(1, "flexible", 0.1445, 0.2722, 2.643e-3, 3.060e6, 3.274e-8, 0.01247), 120.36e-9, 853.93)
SLOW = (_drive(6, "flexible", 0.7608, 0.3095, 5.098e-3, 5.651e6, 3.046e-8, 0.02482), 77.56e-9, 32.657)
RIGID = (_drive(1, "rigid", 0.7917, 0.3433, 1.240e-3, 1.514e7, 1.342e-8, 0.06246), 100.94e-9, 165.69)
PAPER = (Drive(), 150e-9, 100.0)
#: One flexible contact at 432 Hz and 68 nm whose memory keeps a changing stack of micro-reversals.
STUCK = (_drive(1, "flexible", 0.7901, 0.3113, 7.165e-3, 3.266e6, 1.066e-8, 0.1753), 68.50e-9, 432.08)


def _long_run_step(drive, amplitude, frequency, periods=40):
    """The last step of a long run, and whether its last ten steps agree to 0.001 nm."""
    wave = waveforms.sawtooth(amplitude, frequency, drive, periods=periods)
    steps = np.diff(simulation.simulate(drive, wave, max_points=2).settled_positions)
    tail = steps[-10:]
    return float(steps[-1]), float(tail.max() - tail.min()) <= 1e-12


@pytest.mark.parametrize("case", [PAPER, RINGING, SLOW, RIGID], ids=["paper", "ringing", "slow", "rigid"])
def test_the_settled_step_is_the_long_runs_to_its_accuracy(case):
    drive, amplitude, frequency = case
    out = velocity.settled_step(drive, amplitude, frequency)
    truth, converged = _long_run_step(drive, amplitude, frequency)
    assert converged
    assert out["settled"] and out["mismatch_m"] <= velocity.STATE_SHARE * velocity.STEP_ACCURACY
    assert abs(out["step_m"] - truth) <= velocity.STEP_ACCURACY


def test_a_loose_state_tolerance_misses_the_step(monkeypatch):
    """The check above can fail: with 25 times the tolerance the ringing drive stops too early."""
    drive, amplitude, frequency = RINGING
    truth, _ = _long_run_step(drive, amplitude, frequency)
    monkeypatch.setattr(velocity, "STATE_SHARE", 25 * velocity.STATE_SHARE)
    out = velocity.settled_step(drive, amplitude, frequency)
    assert out["settled"]
    assert abs(out["step_m"] - truth) > velocity.STEP_ACCURACY


def test_a_memory_that_changes_its_structure_settles_by_its_steps():
    drive, amplitude, frequency = STUCK
    out = velocity.settled_step(drive, amplitude, frequency)
    truth, converged = _long_run_step(drive, amplitude, frequency)
    assert math.isinf(out["mismatch_m"])  # the states cannot be compared
    assert out["settled"] and out["spread_m"] <= velocity.STEP_ACCURACY
    assert converged and abs(out["step_m"] - truth) <= velocity.STEP_ACCURACY


def _memory(model, path):
    params, state = contact.contact_arrays(model, 0.2, 1e-3, 2.0e11, 8.0e10, 0.2, springs=200)
    for u in path:
        contact.contact_update(params, state, u)
    return params, state


@pytest.mark.parametrize("model", ["exact", "discrete"])
def test_a_memory_moved_on_matches_its_copy(model):
    """Full sliding, then the same reversals, along paths a shift apart: the memories are alike but
    for the shift, which memory_mismatch finds; another history is far, or not comparable."""
    path = np.array([3e-6, 2.0e-6, 2.6e-6, 2.2e-6, 2.4e-6])
    shift = 7e-8
    params, earlier = _memory(model, path)
    _, later = _memory(model, path - shift)
    assert contact.memory_mismatch(params, earlier, later, shift) < 1e-18
    assert contact.memory_mismatch(params, earlier, later, 0.0) == pytest.approx(shift, rel=1e-9)
    _, other = _memory(model, np.append(path, 2.3e-6) - shift)
    assert contact.memory_mismatch(params, earlier, other, shift) > 1e-9


def test_a_drive_against_a_load_cell_repeats_itself_only_in_place():
    drive = replace(Drive(contacts=1), load_cell=True)
    run = simulation.Simulation(drive, waveforms.sawtooth(150e-9, 100.0, drive, periods=2), max_points=2)
    run.run_to(1)
    earlier = run.boundary_state()
    moved = replace(earlier, y=earlier.y + np.r_[1e-9, np.zeros(earlier.y.size - 1)],
                    memory=earlier.memory.copy())
    moved.memory[:, contact.S_U] -= 1e-9
    moved.memory[:, STATE_HEADER::2] -= 1e-9  # reversal points (exact model; the padding is not read)
    assert not moved.translates
    mismatch, shift = periodicity.mismatch(earlier, moved)
    assert shift == pytest.approx(1e-9) and mismatch == pytest.approx(1e-9)
    free = replace(moved, translates=True)
    assert periodicity.mismatch(replace(earlier, translates=True), free)[0] < 1e-15


def test_the_fit_help_states_the_state_tolerance():
    from passmd.cli.commands import fit

    tolerance_nm = velocity.STATE_SHARE * velocity.STEP_ACCURACY * 1e9
    assert f"to {tolerance_nm:g} nm" in " ".join(fit._EPILOG.split())
