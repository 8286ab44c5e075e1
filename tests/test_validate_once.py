"""Inputs are validated once, at the boundary (the standards: records validate on construction,
public functions check their arguments, internal code trusts them).

The walk of ``passmd run --preload 0.4N`` from the option to the simulation kernel checks the
preload's range exactly twice: the option, in the user's unit (``passmd.cli.options``), and the
:class:`~passmd.model.parameters.Drive` record it becomes. --frequency and --amplitude are checked by
the option and then by the public :func:`~passmd.model.waveforms.sawtooth` (and the amplitude by the
:class:`~passmd.model.waveforms.Waveform` record), not again by the command. The checks are counted by
tracing calls of the check helpers of :mod:`passmd.runtime.validation` and of
:meth:`~passmd.model.parameters.PlausibleRange.check` (outermost calls only: a helper calling another
counts once).
"""

from __future__ import annotations

import contextlib
import io
import sys

import pytest

import passmd.runtime.validation as validation
from passmd import cli
from passmd.model.mdr_contact import MDRContact
from passmd.model.parameters import Drive, PlausibleRange
from passmd.solver import simulation as dynamics

#: The check helpers whose calls are counted, by code object.
CHECKS = {function.__code__: label for label, function in (
    ("check_range", validation.check_range), ("check_positive", validation.check_positive),
    ("check_array", validation.check_array), ("check_count", validation.check_count),
    ("check_choice", validation.check_choice), ("PlausibleRange.check", PlausibleRange.check))}


@contextlib.contextmanager
def traced_checks():
    """Record ``(helper, name, caller)`` of every outermost check helper call in the block."""
    calls = []

    def profile(frame, event, arg):
        if event == "call" and frame.f_code in CHECKS and frame.f_back.f_code not in CHECKS:
            caller = frame.f_back.f_code
            calls.append((CHECKS[frame.f_code], str(frame.f_locals.get("name")), caller.co_qualname))

    previous = sys.getprofile()
    sys.setprofile(profile)
    try:
        yield calls
    finally:
        sys.setprofile(previous)


class _KernelReached(BaseException):
    """The simulation was set up (its contacts built) and about to run the kernel."""


def _stop_before_the_kernel(self, periods):
    raise _KernelReached


@pytest.fixture(scope="module")
def run_walk():
    """Every check of ``passmd run --preload 0.4N --frequency 2kHz --amplitude 150nm``, the run
    stopped where the kernel would start (after the simulation's contacts are built)."""
    argv = ["run", "--preload", "0.4N", "--frequency", "2kHz", "--amplitude", "150nm", "--periods", "1"]
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(dynamics.Simulation, "run_to", _stop_before_the_kernel)
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()) as err:
            with traced_checks() as calls, pytest.raises(_KernelReached):
                cli.main(argv)
    assert "error" not in err.getvalue(), err.getvalue()
    return calls


def test_the_preload_is_range_checked_at_the_option_and_in_the_drive_only(run_walk):
    preload = [(helper, caller) for helper, name, caller in run_walk if "preload" in name]
    assert preload == [("PlausibleRange.check", "Quantity.parse"),  # --preload, in N, as typed
                       ("PlausibleRange.check", "Drive.__post_init__")], preload
    # what the simulation derives from the checked drive (each contact's force, radius, moduli)
    # is not checked again on its way to the kernel
    derived = [(name, caller) for _, name, caller in run_walk
               if name in ("normal_force", "radius", "E_star", "G_star", "mu")]
    assert derived == [], derived


def test_frequency_and_amplitude_are_checked_at_the_option_and_by_the_waveform_only(run_walk):
    frequency = [(name, caller) for _, name, caller in run_walk if name in ("--frequency", "frequency")]
    assert frequency == [("--frequency", "Quantity.parse"), ("frequency", "sawtooth")], frequency
    amplitude = [(name, caller) for _, name, caller in run_walk if name in ("--amplitude", "amplitude")]
    assert amplitude == [("--amplitude", "Quantity.parse"), ("amplitude", "sawtooth"),
                         ("amplitude", "Waveform.__post_init__")], amplitude


def test_a_drives_contact_is_built_from_the_drive_without_checking_it_again():
    """MDRContact.for_drive trusts the drive's checked force, radius and moduli; the public
    constructor with bare floats checks them."""
    drive = Drive()
    with traced_checks() as calls:
        contact = MDRContact.for_drive(drive, side=1)
    rechecked = [call for call in calls if call[1] in ("normal_force", "radius", "E_star", "G_star", "mu")]
    assert rechecked == [], rechecked
    with traced_checks() as calls:
        same = MDRContact(contact.normal_force, drive.hemisphere_radius, contact.E_star, contact.G_star,
                          drive.friction_coefficient)
    assert {name for _, name, _ in calls} >= {"normal_force", "radius", "E_star", "G_star", "mu"}
    assert (same.params == contact.params).all()  # the same contact either way, bit for bit
