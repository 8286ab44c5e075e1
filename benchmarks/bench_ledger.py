"""Cost of the replication ledger: one cold ``passmd ledger --profile <p> --json``.

Runs the command in a subprocess with an empty temporary simulation cache (numba's compiled
kernels stay warm: they are cached next to the package, not in the simulation cache), and
records its wall time, the CPU time of the command and its sweep workers, the machine's core
count and its load average just before and after (the machine may be shared), the ledger's
joint reading and headline counts. Each run is appended to ``--out`` (a JSON list), which the
book's execution statistics show.

Usage::

    python benchmarks/bench_ledger.py [--profile paper] [--out passmd/data/benchmarks/ledger.json]
        [--cache-dir DIR]

``--cache-dir`` names an empty directory to use as the cache and keep (e.g. to write a baseline
from the same computation afterwards); by default a temporary one is used and removed.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from passmd.runtime import provenance


def measure(profile: str, cache_dir: str | None = None) -> dict:
    load_before = os.getloadavg()
    if cache_dir is not None and Path(cache_dir).exists() and any(Path(cache_dir).iterdir()):
        raise SystemExit(f"--cache-dir {cache_dir} is not empty: the measurement must start cold")
    with tempfile.TemporaryDirectory(prefix="passmd-bench-ledger-") as temporary:
        cache = temporary if cache_dir is None else cache_dir
        env = {**os.environ, "PASSMD_CACHE_DIR": cache}
        usage = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        done = subprocess.run([sys.executable, "-m", "passmd", "ledger", "--profile", profile, "--json"],
                              env=env, capture_output=True, text=True, check=True)
        wall = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    payload = json.loads(done.stdout)
    joint = payload["joint_reading"]
    return {
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "profile": profile, "git_commit": provenance.stamp(profile)["git_commit"],
        "wall_time_s": round(wall, 1),
        "cpu_time_s": round(after.ru_utime + after.ru_stime - usage.ru_utime - usage.ru_stime, 1),
        "cores": os.cpu_count(), "load_average_before": [round(x, 2) for x in load_before],
        "load_average_after": [round(x, 2) for x in os.getloadavg()],
        "joint_reading": joint["described"], "holding": joint["holding"], "claims": joint["claims"],
        "counts": payload["counts"],
    }


def append_run(out: Path, run: dict) -> None:
    """Append ``run`` to the JSON list in ``out`` (created if absent), replacing the file atomically,
    and print the run."""
    runs = json.loads(out.read_text(encoding="utf-8")) if out.exists() else []
    runs.append(run)
    tmp = out.with_name(f".{out.name}.tmp")
    tmp.write_text(json.dumps(runs, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    tmp.replace(out)
    print(json.dumps(run, indent=1, ensure_ascii=False))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--profile", default="paper", choices=("quick", "paper"))
    parser.add_argument("--out", default="passmd/data/benchmarks/ledger.json")
    parser.add_argument("--cache-dir", default=None)
    args = parser.parse_args()
    append_run(Path(args.out), measure(args.profile, args.cache_dir))


if __name__ == "__main__":
    main()
