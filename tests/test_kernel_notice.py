"""The one-line stderr notice before the kernels compile (README: "The first simulation after
installing compiles the numerical kernels"), as a user sees it: said on the first simulation of a
fresh install and after the package's source changed, not once the kernels are compiled, never
on stdout (--json stays JSON). How numba names its cache files is its own business: the tests
only run commands and read what they print.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import passmd
from passmd.cli import kernels, main

PACKAGE = Path(passmd.__file__).resolve().parent

#: One cheap simulation (a saw-tooth period of a rigid one-contact drive), its result as JSON.
RUN = ["run", "--contacts", "1", "--actuator", "rigid", "--periods", "1", "--max-points", "10", "--json"]


def test_every_kernel_module_exists():
    """The notice checks the modules that hold the kernels: each is a source file of the package."""
    for module in kernels.KERNEL_MODULES:
        assert (PACKAGE / f"{module}.py").is_file(), module


def test_notice_goes_to_stderr_and_json_stays_clean(monkeypatch, capsys):
    monkeypatch.setattr(kernels, "kernels_cold", lambda package_dir=None: True)
    status = main(RUN)
    captured = capsys.readouterr()
    assert status == 0
    json.loads(captured.out)
    assert captured.err.count(kernels.NOTICE) == 1
    monkeypatch.setattr(kernels, "kernels_cold", lambda package_dir=None: False)
    assert main(["theory", "--json"]) == 0
    assert kernels.NOTICE not in capsys.readouterr().err


def test_no_notice_once_a_simulation_has_compiled_the_kernels(capsys):
    """After one simulation every kernel it needs is in numba's cache: the next run is quiet (a
    check waiting for a kernel no simulation compiles would print the notice on every run)."""
    assert main(RUN) == 0
    capsys.readouterr()
    assert main(RUN) == 0
    captured = capsys.readouterr()
    json.loads(captured.out)
    assert kernels.NOTICE not in captured.err, captured.err


@pytest.mark.slow
def test_notice_on_a_fresh_install_and_after_the_source_changed(tmp_path):
    """In a fresh copy of the package (no numba cache anywhere): the first run says it compiles,
    the second does not; after every source file of the package changed (an upgrade, an edit),
    the next run says it again, and the one after is quiet."""
    shutil.copytree(PACKAGE, tmp_path / "passmd", ignore=shutil.ignore_patterns("__pycache__"))
    env = {**os.environ, "PYTHONPATH": str(tmp_path), "HOME": str(tmp_path / "home"),
           "PASSMD_CACHE_DIR": str(tmp_path / "results"), "PYTHONDONTWRITEBYTECODE": "1"}
    env.pop("NUMBA_CACHE_DIR", None)  # numba's cache: next to the copied sources or under HOME

    def notices() -> int:
        done = subprocess.run([sys.executable, "-m", "passmd", *RUN], capture_output=True, text=True,
                              env=env, cwd=tmp_path, timeout=600)
        assert done.returncode == 0, done.stderr
        assert json.loads(done.stdout)["command"] == "run"  # stdout holds the JSON and nothing else
        return done.stderr.count(kernels.NOTICE)

    assert notices() == 1  # a fresh install compiles
    assert notices() == 0
    for source in (tmp_path / "passmd").rglob("*.py"):  # an edit or an upgrade: new text, new time
        with source.open("a", encoding="utf-8") as text:
            text.write("\n# changed after the kernels were compiled\n")
    assert notices() == 1
    assert notices() == 0
