"""Cost of a cold book build: one ``nox -s book -- --cold --profile <p>``.

Runs the book session with empty simulation and numba caches (``--cold``: fresh temporary
folders, no previous build output) and records its wall time, the time of its first part
(``passmd ledger``, which computes every figure), the machine's core count and its load
average before and after (the machine may be shared, which stretches the wall time). Each run
is appended to ``--out`` (a JSON list), which the book's execution statistics show beside the
budget :data:`BUDGET_S`.

Usage::

    python benchmarks/bench_book.py [--profile paper] [--out passmd/data/benchmarks/book.json]

Needs ``nox`` on PATH and the book session's environment (run ``nox -s book`` once first:
``-R`` reuses it); run it with a Python that imports passmd (e.g. the book session's).
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

from bench_ledger import append_run  # a sibling script: the benchmarks folder is on the path

from passmd.runtime import provenance

#: The wall time a cold build of each profile should stay within (s): the paper profile is the
#: reader's build on a laptop; the quick profile is CI's.
BUDGET_S = {"paper": 360.0, "quick": 300.0}


def measure(profile: str) -> dict:
    load_before = os.getloadavg()
    start = time.perf_counter()
    nox = shutil.which("nox")
    if nox is None:
        raise SystemExit("nox is not on PATH: install it (python3 -m pip install nox uv)")
    command = [nox, "-R", "-s", "book", "--", "--cold", "--profile", profile]
    done = subprocess.run(command,
                          capture_output=True, text=True)
    wall = time.perf_counter() - start
    if done.returncode != 0:
        sys.stderr.write(done.stdout[-4000:] + done.stderr[-4000:])
        raise SystemExit(f"the book build failed (exit status {done.returncode})")
    built = re.search(r"book built in (\d+) s wall time", done.stdout + done.stderr)
    prefetch = json.loads(Path("book/_build/passmd-prefetch-time.json").read_text(encoding="utf-8"))
    return {
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "profile": profile, "git_commit": provenance.stamp(profile)["git_commit"],
        "build_s": float(built.group(1)) if built else None,
        "ledger_s": round(prefetch["wall_seconds"], 1),
        "session_wall_s": round(wall, 1), "budget_s": BUDGET_S[profile],
        "cores": os.cpu_count(), "load_average_before": [round(x, 2) for x in load_before],
        "load_average_after": [round(x, 2) for x in os.getloadavg()],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--profile", default="paper", choices=("quick", "paper"))
    parser.add_argument("--out", default="passmd/data/benchmarks/book.json")
    args = parser.parse_args()
    append_run(Path(args.out), measure(args.profile))


if __name__ == "__main__":
    main()
