"""The one-line stderr notice before the kernels compile (README: "The first simulation after
installing compiles the numerical kernels"), as a user sees it: said when a simulating command
compiles, on the first simulation of a fresh install and after the package's source changed, not
once the kernels are compiled nor after a mere change of the files' times, never on stdout
(--json stays JSON). The tests only run commands and read what they print.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numba
import pytest

import passmd
from passmd.cli import kernels, main
from passmd.solver import simulation

PACKAGE = Path(passmd.__file__).resolve().parent

#: One cheap simulation (a saw-tooth period of a rigid one-contact drive), its result as JSON.
RUN = ["run", "--contacts", "1", "--actuator", "rigid", "--periods", "1", "--max-points", "10", "--json"]


def test_notice_goes_to_stderr_once_and_json_stays_clean(monkeypatch, capsys):
    """A command during which numba compiles (here: a function of the test's own, then the
    simulation) says so once, on stderr; a command that compiles nothing says nothing."""
    original = simulation.simulate

    def compiling_simulate(*args, **kwargs):
        numba.njit(lambda x, y: x + y)(1, 2)  # a fresh function: numba compiles it now
        numba.njit(lambda x: -x)(1.5)
        return original(*args, **kwargs)

    monkeypatch.setattr(simulation, "simulate", compiling_simulate)
    assert main(RUN) == 0
    captured = capsys.readouterr()
    json.loads(captured.out)
    assert captured.err.count(kernels.NOTICE) == 1, captured.err
    monkeypatch.setattr(simulation, "simulate", original)
    assert main(RUN) == 0
    assert kernels.NOTICE not in capsys.readouterr().err
    assert main(["theory", "--json"]) == 0
    assert kernels.NOTICE not in capsys.readouterr().err


def test_a_finished_command_leaves_no_stream_to_a_later_compile(monkeypatch):
    """A command armed with a stderr that is closed once it returns (a caller running commands
    in-process, a test's captured stream): a numba compile after it neither writes there nor
    fails."""
    import io

    stderr = io.StringIO()
    monkeypatch.setattr(sys, "stderr", stderr)
    assert main([a for a in RUN if a != "--json"]) == 0
    monkeypatch.undo()
    stderr.close()
    assert numba.njit(lambda x: x * 3.0)(2.0) == 6.0  # a fresh function: numba compiles it now


def test_no_notice_once_a_simulation_has_compiled_the_kernels(capsys):
    """After one simulation every kernel it needs is compiled: the next run is quiet."""
    assert main(RUN) == 0
    capsys.readouterr()
    assert main(RUN) == 0
    captured = capsys.readouterr()
    json.loads(captured.out)
    assert kernels.NOTICE not in captured.err, captured.err


@pytest.mark.slow
def test_notice_on_a_fresh_install_and_after_the_source_changed(tmp_path):
    """In a fresh copy of the package (no numba cache anywhere): the first run says it compiles,
    the second does not; new times on every file (a reinstall of the same version) change nothing;
    after every source file of the package changed (an upgrade, an edit), the next run says it
    again, and the one after is quiet."""
    shutil.copytree(PACKAGE, tmp_path / "passmd", ignore=shutil.ignore_patterns("__pycache__"))
    env = {**os.environ, "PYTHONPATH": str(tmp_path), "HOME": str(tmp_path / "home"),
           "PASSMD_CACHE_DIR": str(tmp_path / "results"), "PYTHONDONTWRITEBYTECODE": "1"}
    env.pop("NUMBA_CACHE_DIR", None)  # numba's cache: next to the copied sources or under HOME
    sources = list((tmp_path / "passmd").rglob("*.py"))

    def notices() -> int:
        done = subprocess.run([sys.executable, "-m", "passmd", *RUN], capture_output=True, text=True,
                              env=env, cwd=tmp_path, timeout=600)
        assert done.returncode == 0, done.stderr
        assert json.loads(done.stdout)["command"] == "run"  # stdout holds the JSON and nothing else
        return done.stderr.count(kernels.NOTICE)

    assert notices() == 1  # a fresh install compiles
    assert notices() == 0
    for source in sources:  # the same text, new times: nothing to compile
        source.touch()
    assert notices() == 0
    for source in sources:  # an edit or an upgrade: new text
        with source.open("a", encoding="utf-8") as text:
            text.write("\n# changed after the kernels were compiled\n")
    assert notices() == 1
    assert notices() == 0
