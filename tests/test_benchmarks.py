"""Every benchmark script offers ``--smoke``, the mode ``nox -s benchmarks_smoke`` runs in CI.

A script without it would fail that session; this test says which script and why before CI
gets there. Each script is asked for ``--help`` in a process of its own (so an import that no
longer resolves fails here too), and its docstring must say what its smoke run checks.
"""

from __future__ import annotations

import argparse
import ast
import re
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPTS = sorted((Path(__file__).resolve().parents[1] / "benchmarks").glob("*.py"))


def test_benchmarks_are_found():
    assert SCRIPTS, "no benchmarks/*.py found"


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda script: script.stem)
def test_script_offers_smoke(script):
    done = subprocess.run([sys.executable, str(script), "--help"], capture_output=True, text=True,
                          cwd=script.parent, timeout=120)
    assert done.returncode == 0, done.stderr
    # the option's own line of the help, indented by two (other options' help may mention it)
    option = re.search(r"^  --smoke\b", done.stdout, re.MULTILINE)
    assert option, f"{script.name} has no --smoke:\n{done.stdout}"
    docstring = ast.get_docstring(ast.parse(script.read_text(encoding="utf-8"))) or ""
    assert "--smoke" in docstring, f"{script.name}'s docstring does not say what --smoke checks"


def test_quick_and_smoke_runs_never_write_over_the_committed_records():
    sys.path.insert(0, str(SCRIPTS[0].parent))
    from bench_ledger import ROOT, output

    committed = ROOT / "passmd" / "data" / "benchmarks"
    run = {"out": None, "quick": False, "smoke": False}
    assert output(argparse.Namespace(**run), "fit") == committed / "fit.json"
    for mode in ("quick", "smoke"):
        assert committed not in output(argparse.Namespace(**{**run, mode: True}), "fit").parents
    assert output(argparse.Namespace(**{**run, "quick": True, "out": "x.json"}), "fit") == Path("x.json")
