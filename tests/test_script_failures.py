"""A benchmark that fails ends in one line, as the command line does: never a traceback.

Contract (README, "Reliability"; CONTRIBUTING, "Numerics and performance"): every script of
``benchmarks/`` runs its ``main`` through :func:`passmd.runtime.scripts.run_script`, and reads what
its child processes print through :func:`passmd.runtime.scripts.child_json`, so a full disk, a
failing child or a child that printed nothing is one line naming what failed, exit status 1.
"""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest

from passmd.runtime.scripts import ScriptError, child_json, run_script

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


def test_a_full_disk_under_a_benchmark_is_one_line(tmp_path):
    """``bench_fit.py --smoke --out /dev/full``: its smoke fit runs, then the write fails."""
    if not os.path.exists("/dev/full"):
        pytest.skip("needs /dev/full")
    env = {**os.environ, "MPLBACKEND": "Agg", "CI": "true"}
    done = subprocess.run([sys.executable, str(BENCHMARKS / "bench_fit.py"), "--smoke", "--out", "/dev/full"],
                          capture_output=True, text=True, env=env, timeout=600)
    assert done.returncode == 1, done.stderr
    last = done.stderr.splitlines()[-1]
    assert last == "bench_fit.py: error: No space left on device (/dev/full)", done.stderr
    assert "Traceback" not in done.stderr


@pytest.mark.parametrize("script", sorted(BENCHMARKS.glob("*.py")), ids=lambda p: p.name)
def test_every_benchmark_runs_its_main_through_the_one_line_runner(script):
    tree = ast.parse(script.read_text(encoding="utf-8"))
    guard = [node for node in tree.body if isinstance(node, ast.If) and "__main__" in ast.unparse(node.test)]
    assert guard and "run_script(main)" in ast.unparse(guard[0]), f"{script.name}: main not run by run_script"


def test_a_child_that_failed_or_printed_nothing_is_one_line():
    failed = subprocess.CompletedProcess([], 1, stdout="", stderr="Traceback...\nValueError: broken\n")
    with pytest.raises(ScriptError, match=r"^the probe failed \(exit status 1\): ValueError: broken$"):
        child_json(failed, "the probe")
    silent = subprocess.CompletedProcess([], 0, stdout="", stderr="")
    with pytest.raises(ScriptError, match="^the probe printed 'nothing' on its stdout"):
        child_json(silent, "the probe")
    assert child_json(subprocess.CompletedProcess([], 0, stdout="[1, 2]\n", stderr=""), "x") == [1, 2]
    assert child_json(subprocess.CompletedProcess([], 0, stdout="", stderr='{"a": 1}\nmore\n'), "x",
                      stream="stderr", line=0) == {"a": 1}


def test_run_script_turns_any_failure_into_one_line(capsys, monkeypatch):
    monkeypatch.delenv("PASSMD_DEBUG", raising=False)

    def broken():
        raise ValueError("a value\nover two lines")

    assert run_script(broken, "bench_x.py") == 1
    assert capsys.readouterr().err == "bench_x.py: error: ValueError: a value over two lines\n"

    def interrupted():
        raise KeyboardInterrupt

    assert run_script(interrupted, "bench_x.py") == 130
    assert capsys.readouterr().err == "bench_x.py: interrupted\n"
    assert run_script(lambda: 0, "bench_x.py") == 0
