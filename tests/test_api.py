"""The package's public names (``passmd.__all__``): each is the object of the module it comes
from, and ``import passmd`` loads none of them until used, so the command line's start-up and
``passmd --version`` stay free of the simulator (numba), pandas and matplotlib."""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest

import passmd


@pytest.mark.parametrize("name", sorted(passmd._API))
def test_every_public_name_is_its_modules_object(name):
    assert name in passmd.__all__
    assert getattr(passmd, name) is getattr(importlib.import_module(passmd._API[name]), name)


def test_import_passmd_loads_no_simulator():
    code = ("import sys, passmd; heavy = [m for m in ('numba', 'pandas', 'matplotlib', "
            "'passmd.solver.simulation') "
            "if m in sys.modules]; print(','.join(heavy))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == ""


def test_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'simulat'"):
        passmd.simulat  # noqa: B018


def test_drive_file_round_trip_through_the_public_names(tmp_path):
    drive = passmd.Drive(hemisphere_radius=0.5e-3, preload=0.6, friction_coefficient=0.25, contacts=1)
    path = tmp_path / "mine.toml"
    path.write_text(passmd.drive_toml(drive), encoding="utf-8")
    assert passmd.load_drive(path) == drive


def test_calibration_is_public():
    """``passmd.fit`` and ``passmd.read_measurements`` calibrate a drive without reaching into
    ``passmd.protocols``: the paper's own numbers read through the public name."""
    from passmd.ledger.reference import REFERENCE_DIR

    assert {"fit", "read_measurements"} <= set(passmd.__all__)
    data = passmd.read_measurements(REFERENCE_DIR / "paper_as_data.csv")
    assert data.kind == ("critical_amplitude", "position")
    with pytest.raises(ValueError, match="not a parameter the fit can free"):
        passmd.fit(passmd.Drive(), data, ["preload"], executor="serial", cache=False)
