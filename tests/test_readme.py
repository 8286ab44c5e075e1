"""The README's quickstart runs as written (README contract: "a quickstart that a test runs").

Each line of the command-line block runs as ``python -m passmd …`` in a subprocess and must
exit 0 with output; the Python block runs in a fresh interpreter and must exit 0. A
command that no longer exists, an option that was renamed or an API that moved fails here.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"


def _block(heading: str, language: str) -> str:
    text = README.read_text(encoding="utf-8")
    start = text.index(heading)
    section = text[start:text.index("\n## ", start + len(heading))]
    match = re.search(rf"```{language}\n(.*?)```", section, re.S)
    assert match, f"no {language} block under {heading!r}"
    return match.group(1)


def _cli_lines() -> list[str]:
    lines = [line for line in _block("## Quickstart: command line", "bash").splitlines() if line.strip()]
    assert lines and all(line.startswith("passmd ") for line in lines), lines
    return lines


def _env(tmp_path: Path) -> dict:
    return {**os.environ, "MPLBACKEND": "Agg", "PASSMD_CACHE_DIR": str(tmp_path / "cache")}


@pytest.mark.parametrize("line", _cli_lines())
def test_readme_command_line_quickstart_runs(line, tmp_path):
    argv = [sys.executable, "-m", "passmd", *shlex.split(line)[1:]]
    done = subprocess.run(argv, capture_output=True, text=True, cwd=tmp_path, env=_env(tmp_path), timeout=600)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip()


def test_readme_python_quickstart_runs(tmp_path):
    code = _block("## Quickstart: Python", "python")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path,
                          env=_env(tmp_path), timeout=600)
    assert done.returncode == 0, done.stderr
    printed = done.stdout.split("\n")
    assert len([line for line in printed if line.strip()]) == 2, done.stdout


def test_reliability_counts_are_the_suites_own():
    """The Reliability section's counts are those of the suites it lists: "`tests/X.py` (N named
    tests)" their module-level test functions, the named command lines of the bad-input suite and
    the generated examples per run; and the input-file limits it states are the readers' own."""
    import ast

    from passmd.runtime.inputs import LIMITS, format_size

    text = README.read_text(encoding="utf-8")
    start = text.index("## Reliability")
    section = text[start:text.index("\n## ", start + 3)]
    stated = re.findall(r"`(tests/test_\w+\.py)` \((\d+) named tests\)", section)
    assert len(stated) >= 7, section
    for path, count in stated:
        tree = ast.parse((README.parent / path).read_text(encoding="utf-8"))
        tests = [node for node in tree.body
                 if isinstance(node, ast.FunctionDef) and node.name.startswith("test_")]
        assert len(tests) == int(count), f"{path}: the README says {count}, the file has {len(tests)}"
    sys.path.insert(0, str(README.parent / "tests"))
    import test_bad_inputs

    assert f"{len(test_bad_inputs.NAMED_CASES)} named command lines" in section
    examples = os.environ.get("PASSMD_FUZZ_EXAMPLES", "250")
    assert f"hypothesis suites: {examples} command lines per run" in section
    assert f"hypothesis suites of {examples} generated drive" in section
    flat = " ".join(section.split())
    for kind in ("drive file", "measurement file", "reference table", "benchmark record", "cache entry"):
        assert f"a {kind} up to {format_size(LIMITS[kind])}" in flat, kind
