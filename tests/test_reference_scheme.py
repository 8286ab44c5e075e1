"""The default integrator against the reference one, on the paper's drive and two others.

``scheme="reference"`` is the error-controlled step the default grew from (bracketed balance
solves, a fresh start at every breakpoint of x_p(t)); its finest setting is the fixed fine step
(``scheme="fixed"``: velocity Verlet at 96 steps per period of the ≈ 3 MHz actuator mode, the
reference of the convergence studies). The default's steps per period must lie within
:data:`STEP_AGREEMENT` of the fixed fine step's on

* the paper's drive (six contacts, flexible actuators, Tables 1–2) at 150 nm, 100 Hz;
* a drive with strong runner ringing: a 30 g runner (ten times the paper's) on R = 0.5 mm
  hemispheres at F_p = 0.8 N and 130 nm, whose micro-vibration is still ≈ 17 nm peak to peak in the settle
  window (the paper's: ≈ 3 nm), so the error-controlled steps cross a ringing runner all ramp long;
* a light runner (1 g) on R = 0.5 mm hemispheres at F_p = 0.2 N driven at 2 kHz, where the next
  fly-back comes 0.5 ms after the last one.

Three periods from rest each: the first step from rest and one steady step.
"""

import numpy as np
import pytest

from passmd.model import waveforms
from passmd.model.parameters import Drive
from passmd.solver import simulation
from passmd.solver.steps import SCHEMES

#: Largest difference of a step per period from the fixed fine step's (m).
STEP_AGREEMENT = 0.02e-9

DRIVES = {
    "paper": (Drive(contacts=6, actuator_model="flexible"), 150e-9, 100.0),
    "ringing runner": (Drive(contacts=6, actuator_model="flexible", runner_mass=30e-3, preload=0.8,
                             hemisphere_radius=0.5e-3, allow_extrapolation=True), 130e-9, 100.0),
    "light runner, 2 kHz": (Drive(contacts=6, actuator_model="flexible", runner_mass=1e-3, preload=0.2,
                                  hemisphere_radius=0.5e-3, allow_extrapolation=True), 100e-9, 2000.0),
}


def _run(name, scheme):
    drive, amplitude, frequency = DRIVES[name]
    wave = waveforms.sawtooth(amplitude, frequency, drive, periods=3)
    return simulation.simulate(drive, wave, scheme=scheme, max_points=2)


@pytest.fixture(scope="module")
def fixed():
    return {name: _run(name, "fixed") for name in DRIVES}


@pytest.mark.parametrize("name", list(DRIVES))
def test_default_steps_agree_with_the_reference_at_its_finest_step(fixed, name):
    default = _run(name, "controlled")
    reference = _run(name, "reference")
    np.testing.assert_allclose(default.step_sizes, fixed[name].step_sizes, rtol=0, atol=STEP_AGREEMENT)
    np.testing.assert_allclose(default.settled_positions, fixed[name].settled_positions, rtol=0,
                               atol=STEP_AGREEMENT)
    # the same error control and steps: the two schemes differ by the balance solve's tolerance only
    np.testing.assert_allclose(default.step_sizes, reference.step_sizes, rtol=0, atol=STEP_AGREEMENT / 10)
    assert default.steps < reference.steps


def test_the_agreement_check_fails_on_a_coarser_integrator(fixed):
    """The check can fail: the default with its tolerance 16 times looser (and the fine step
    twice as long) misses the fixed fine step's steps by more than STEP_AGREEMENT."""
    coarse = _run("paper", SCHEMES["controlled"].replace(refine=0.5))
    assert np.abs(coarse.step_sizes - fixed["paper"].step_sizes).max() > STEP_AGREEMENT


def test_reference_scheme_is_the_former_default():
    """The reference is the error-controlled step without the default's Newton balances and
    smooth breakpoints; everything else (tolerance, fine step) is the default's."""
    reference, default = SCHEMES["reference"], SCHEMES["controlled"]
    assert reference.error_control and reference.quiet_step == default.quiet_step
    assert not reference.newton_balance and not reference.smooth_breakpoints
    assert default.newton_balance and default.smooth_breakpoints


def test_command_line_names_every_scheme():
    """``passmd run --scheme`` offers exactly the schemes the library has (its parser loads no solver)."""
    from passmd.cli.commands.run import SCHEME_NAMES

    assert SCHEME_NAMES == tuple(SCHEMES)
