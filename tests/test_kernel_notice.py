"""The one-line stderr notice before the kernels compile (passmd.cli.kernels): said when numba's
cache holds no index as new as a kernel module's source, never on stdout (--json stays JSON)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from passmd.cli import kernels, main

PACKAGE = Path(kernels.__file__).resolve().parents[1]


def _copy(tmp_path, monkeypatch) -> Path:
    monkeypatch.setenv("HOME", str(tmp_path / "home"))  # no user-wide numba cache
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    package = tmp_path / "pkg"
    package.mkdir()
    for module in kernels.KERNEL_MODULES:
        (package / module).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(PACKAGE / f"{module}.py", package / f"{module}.py")
    return package


def test_every_kernel_module_exists():
    """The notice checks the modules that hold the kernels: each is a source file of the package."""
    for module in kernels.KERNEL_MODULES:
        assert (PACKAGE / f"{module}.py").is_file(), module


def _index(package: Path, module: str, mtime: float) -> None:
    cache = (package / module).parent / "__pycache__"
    cache.mkdir(exist_ok=True)
    name = cache / f"{Path(module).name}.kernel-10.py{sys.version_info.major}{sys.version_info.minor}.nbi"
    name.write_bytes(b"")
    os.utime(name, (mtime, mtime))


def test_cold_without_index_warm_with_fresh_ones_cold_again_when_a_source_is_newer(tmp_path, monkeypatch):
    package = _copy(tmp_path, monkeypatch)
    assert kernels.kernels_cold(package)
    stamp = max((package / f"{m}.py").stat().st_mtime for m in kernels.KERNEL_MODULES)
    for module in kernels.KERNEL_MODULES[:-1]:
        _index(package, module, stamp + 10)
    assert kernels.kernels_cold(package)  # one module still without an index
    _index(package, kernels.KERNEL_MODULES[-1], stamp + 10)
    assert not kernels.kernels_cold(package)
    source = package / f"{kernels.KERNEL_MODULES[0]}.py"
    os.utime(source, (stamp + 20, stamp + 20))  # the source changed after it was compiled
    assert kernels.kernels_cold(package)


def test_notice_goes_to_stderr_and_json_stays_clean(monkeypatch, capsys):
    monkeypatch.setattr(kernels, "kernels_cold", lambda package_dir=None: True)
    status = main(["run", "--contacts", "1", "--actuator", "rigid", "--periods", "1", "--max-points", "10",
                   "--json"])
    captured = capsys.readouterr()
    assert status == 0
    json.loads(captured.out)
    assert captured.err.count(kernels.NOTICE) == 1
    monkeypatch.setattr(kernels, "kernels_cold", lambda package_dir=None: False)
    assert main(["theory", "--json"]) == 0
    assert kernels.NOTICE not in capsys.readouterr().err


# in a fresh copy of the package: cold before, then one short simulation, then warm
_COLD_START = """
from passmd.solver import simulation as dynamics
from passmd.model import waveforms
from passmd.cli import kernels
from passmd.model.parameters import Drive
cold_before = kernels.kernels_cold()
drive = Drive(contacts=1, actuator_model="rigid")
dynamics.simulate(drive, waveforms.sawtooth(150e-9, 100.0, drive, periods=1), max_points=10)
print(cold_before, kernels.kernels_cold())
"""


@pytest.mark.slow
def test_one_simulation_warms_every_kernel_module(tmp_path):
    """The notice stops after the first simulation: every module the check waits for gets an
    index from a simulation (a module whose kernels no simulation compiles would keep the
    notice up on every later run)."""
    shutil.copytree(PACKAGE, tmp_path / "passmd", ignore=shutil.ignore_patterns("__pycache__"))
    env = {**os.environ, "PYTHONPATH": str(tmp_path), "HOME": str(tmp_path / "home"),
           "PYTHONDONTWRITEBYTECODE": "1"}
    env.pop("NUMBA_CACHE_DIR", None)
    done = subprocess.run([sys.executable, "-c", _COLD_START], capture_output=True, text=True, env=env,
                          cwd=tmp_path, check=True)
    assert done.stdout.split() == ["True", "False"], done.stderr
