"""Cost of a cold book build: one ``nox -s book -- --cold --profile <p>``.

Runs the book session with empty simulation and numba caches (``--cold``: fresh temporary
folders, no previous build output; the bytecode of the installed modules is the environment's,
kept beside it as pip keeps it in site-packages) and records its wall time against the budget
:data:`BUDGET_S`, the time of its first part (``passmd ledger``, which computes every figure and
the whole assumption space), the machine's core count and its load average before and after (the
machine may be shared, which stretches the wall time). Each run is appended to ``--out`` (a JSON
list), which the book's execution statistics show beside the budget.

Usage (one command, from the repository root; nox installs the book's environment itself)::

    python3 benchmarks/bench_book.py            # paper profile: appended to passmd/data/benchmarks/book.json
    python3 benchmarks/bench_book.py --quick    # the quick profile, written to a temporary file
    python3 benchmarks/bench_book.py --smoke    # seconds: what a build needs, to a temporary file

``--smoke`` builds nothing (a build takes minutes): it resolves what a measurement needs before
it starts (nox, its ``book`` session, the book's table of contents, the folder of the default
``--out``, the profile's budget), times the build's first step, nox reading the noxfile
(``nox --list -s book``), and appends that record to a temporary file. ``bench_ledger.py
--smoke`` runs the build's first part, ``passmd ledger``.
"""

from __future__ import annotations

import argparse
import datetime
import importlib.util
import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_ledger import ROOT, append_run, git_commit, output  # noqa: E402  (a sibling script)

#: The wall time a cold build of each profile should stay within on a quiet 2-core machine (s): the
#: paper profile is the reader's build on a laptop; the quick profile is CI's.
BUDGET_S = {"paper": 180.0, "quick": 300.0}


def nox_command() -> list[str]:
    """How to run nox: this Python's module if it has it, else the ``nox`` on PATH."""
    if importlib.util.find_spec("nox") is not None:
        return [sys.executable, "-m", "nox"]
    if shutil.which("nox"):
        return [shutil.which("nox")]
    raise SystemExit("nox is not installed: python3 -m pip install nox uv")


def book_command(profile: str) -> list[str]:
    """The cold build of ``profile`` that :func:`measure` times."""
    return [*nox_command(), "-s", "book", "--", "--cold", "--profile", profile]


def measure(profile: str) -> dict:
    load_before = os.getloadavg()
    start = time.perf_counter()
    done = subprocess.run(book_command(profile), cwd=ROOT, capture_output=True, text=True)
    wall = time.perf_counter() - start
    load_after = os.getloadavg()
    if done.returncode != 0:
        sys.stderr.write(done.stdout[-4000:] + done.stderr[-4000:])
        raise SystemExit(f"the book build failed (exit status {done.returncode})")
    built = re.search(r"book built in (\d+) s wall time", done.stdout + done.stderr)
    prefetch_file = ROOT / "book" / "_build" / "passmd-prefetch-time.json"
    prefetch = json.loads(prefetch_file.read_text(encoding="utf-8"))
    return {
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "profile": profile, "git_commit": git_commit(),
        "build_s": float(built.group(1)) if built else None,
        "ledger_s": round(prefetch["wall_seconds"], 1),
        "session_wall_s": round(wall, 1), "budget_s": BUDGET_S[profile],
        "cores": os.cpu_count(), "load_average_before": [round(x, 2) for x in load_before],
        "load_average_after": [round(x, 2) for x in load_after],
    }


def smoke(profile: str) -> dict:
    """What :func:`measure` needs before the build starts, and the time of nox reading the noxfile."""
    command = book_command(profile)
    for needed in (ROOT / "book" / "_toc.yml", ROOT / "passmd" / "data" / "benchmarks"):
        if not needed.exists():
            raise SystemExit(f"{needed} is missing: a build cannot run or be recorded")
    start = time.perf_counter()
    listed = subprocess.run([*nox_command(), "--list", "--json", "-s", "book"], cwd=ROOT,
                            capture_output=True, text=True)
    wall = time.perf_counter() - start
    if listed.returncode != 0:
        raise SystemExit(f"nox has no book session: {' '.join(listed.stderr.split())}")
    return {
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "profile": profile, "smoke": True, "git_commit": git_commit(), "command": command,
        "nox_list_s": round(wall, 2), "budget_s": BUDGET_S[profile], "cores": os.cpu_count(),
        "load_average": [round(x, 2) for x in os.getloadavg()],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    size = parser.add_mutually_exclusive_group()
    size.add_argument("--quick", action="store_true", help="the quick profile, written to a temporary file")
    size.add_argument("--smoke", action="store_true",
                      help="resolve what a build needs and time nox reading the noxfile, to a temporary "
                           "file; builds nothing")
    parser.add_argument("--profile", default=None, choices=("quick", "paper"), help="default: paper")
    parser.add_argument("--out", default=None, help="JSON list the run is appended to")
    args = parser.parse_args()
    profile = args.profile or ("quick" if args.quick else "paper")
    append_run(output(args, "book"), smoke(profile) if args.smoke else measure(profile))


if __name__ == "__main__":
    try:  # one line on failure (the command line's contract), where passmd is installed
        from passmd.runtime.scripts import run_script
    except ImportError:  # pragma: no cover - run with a Python that has no passmd
        def run_script(main):
            return main() or 0
    sys.exit(run_script(main))
