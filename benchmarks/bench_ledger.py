"""Cost of the replication ledger: one cold ``passmd ledger --profile <p> --json``.

Runs the command in a subprocess with an empty temporary simulation cache (numba's compiled
kernels stay warm: they are cached next to the package, not in the simulation cache), and records
its wall time against the budget :data:`BUDGET_S`, the CPU time of the command and its sweep
workers, the largest resident set of one of them (against :data:`MEMORY_BUDGET_MB`), how many
sweep points it computed, the machine's core count and its load average just before and after (the
machine may be shared: a load above the core count stretches the wall time), the size of the
assumption space it evaluated (points, covered, decided), the joint reading and the headline
counts. Each run is appended to ``--out`` (a JSON list), which the book's execution statistics
show.

Usage (one command, from the repository root)::

    python3 benchmarks/bench_ledger.py          # paper: appended to passmd/data/benchmarks/ledger.json
    python3 benchmarks/bench_ledger.py --quick  # quick profile, written to a temporary file
    python3 benchmarks/bench_ledger.py --smoke  # quick profile from the warm cache, temporary file

``--smoke`` runs the same command and record on the quick profile with the simulation cache it
would use anyway (``--cache-dir``, else ``$PASSMD_CACHE_DIR``, which nox points at the
repository's ``.passmd-cache/``, else the user cache folder), not an empty one: seconds once the
tests have filled that cache, the quick profile's minutes when they have not. It checks that the
script works; its times mean nothing.

``--python`` names the interpreter that runs ``passmd`` (default: this one if it imports passmd,
else the ``tests`` or ``book`` nox environment of the repository); ``--cache-dir`` an empty
directory to use as the cache and keep (e.g. to write a baseline from the same computation
afterwards); by default a temporary one is used and removed.
"""

from __future__ import annotations

import argparse
import datetime
import importlib.util
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from passmd.runtime.outputs import write_file

ROOT = Path(__file__).resolve().parents[1]
#: The wall time a cold ledger of each profile should stay within on a quiet 2-core machine (s).
BUDGET_S = {"paper": 120.0, "quick": 240.0}
#: The largest resident set one process of the paper ledger (the command or a sweep worker) should
#: reach (MB).
MEMORY_BUDGET_MB = 400.0


def git_commit() -> str:
    """The checked-out commit, with "(uncommitted changes)" for a dirty tree."""
    def git(*args):
        return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True).stdout.strip()

    commit = git("rev-parse", "HEAD") or "unknown"
    return commit + (" (uncommitted changes)" if git("status", "--porcelain", "--untracked-files=no") else "")


def passmd_python(given: str | None) -> str:
    """The interpreter that runs passmd: ``given``, this one if it imports passmd, else a nox
    environment's."""
    if given:
        return given
    if importlib.util.find_spec("passmd") is not None:
        return sys.executable
    for session in ("tests", "book"):
        candidate = ROOT / ".nox" / session / "bin" / "python"
        if candidate.is_file():
            return str(candidate)
    raise SystemExit("no Python that imports passmd: run `python3 -m nox -s tests --install-only` first, or "
                     "give one with --python")


def measure(profile: str, python: str, cache_dir: str | None = None, cold: bool = True) -> dict:
    """One ``passmd ledger``: with an empty cache (``cache_dir``, else a temporary one) when ``cold``,
    else with ``cache_dir`` or the command's own default cache as it is."""
    if cold and cache_dir is not None and Path(cache_dir).exists() and any(Path(cache_dir).iterdir()):
        raise SystemExit(f"--cache-dir {cache_dir} is not empty: the measurement must start cold")
    with tempfile.TemporaryDirectory(prefix="passmd-bench-ledger-") as temporary:
        log = Path(temporary) / "sweeps.jsonl"
        env = {**os.environ, "PASSMD_SWEEP_LOG": str(log)}
        if cache_dir is not None or cold:
            env["PASSMD_CACHE_DIR"] = cache_dir or temporary
        load_before = os.getloadavg()
        usage = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        done = subprocess.run([python, "-m", "passmd", "ledger", "--profile", profile, "--json"], cwd=ROOT,
                              env=env, capture_output=True, text=True)
        wall = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        load_after = os.getloadavg()
        if done.returncode != 0:  # its own one-line error, as the last line of its stderr
            last = (done.stderr.strip().splitlines() or ["no message"])[-1]
            raise RuntimeError(f"passmd ledger failed (exit status {done.returncode}): {last}")
        lines = log.read_text(encoding="utf-8").splitlines() if log.exists() else []
        sweeps = [json.loads(line) for line in lines]
    payload = json.loads(done.stdout)
    joint = payload["joint_reading"]
    return {
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "profile": profile, "cold": cold, "git_commit": git_commit(),
        "wall_time_s": round(wall, 1), "budget_s": BUDGET_S[profile],
        "cpu_time_s": round(after.ru_utime + after.ru_stime - usage.ru_utime - usage.ru_stime, 1),
        # the largest resident set of the command or one of its sweep workers (Linux: kB)
        "peak_rss_mb": round(after.ru_maxrss / 1024, 1), "memory_budget_mb": MEMORY_BUDGET_MB,
        "points_computed": sum(int(s.get("computed", 0)) for s in sweeps),
        "cores": os.cpu_count(), "load_average_before": [round(x, 2) for x in load_before],
        "load_average_after": [round(x, 2) for x in load_after],
        "space_points": joint["points"], "covered_points": joint["covered_points"],
        "decided_points": joint["decided_points"],
        "joint_reading": joint["described"], "holding": joint["holding"], "claims": joint["claims"],
        "counts": payload["counts"],
    }


def append_run(out: Path, run: dict) -> None:
    """Append ``run`` to the JSON list in ``out`` (created if absent), replacing the file atomically,
    and print the run."""
    runs = json.loads(out.read_text(encoding="utf-8")) if out.exists() else []
    runs.append(run)
    text = json.dumps(runs, indent=1, ensure_ascii=False) + "\n"
    write_file(out, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"), overwrite=True)  # atomic
    print(json.dumps(run, indent=1, ensure_ascii=False))
    print(f"appended to {out}")


def output(args, name: str = "ledger") -> Path:
    """``--out``, else a temporary file for ``--quick`` and ``--smoke`` and the committed
    ``passmd/data/benchmarks/<name>.json`` otherwise."""
    if args.out:
        return Path(args.out)
    if getattr(args, "quick", False) or args.smoke:  # a script without --quick has only --smoke
        return Path(tempfile.mkdtemp(prefix="passmd-bench-")) / f"{name}.json"
    return ROOT / "passmd" / "data" / "benchmarks" / f"{name}.json"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    size = parser.add_mutually_exclusive_group()
    size.add_argument("--quick", action="store_true", help="the quick profile, written to a temporary file")
    size.add_argument("--smoke", action="store_true",
                      help="the quick profile from the warm cache, to a temporary file: checks the script "
                           "runs, measures nothing")
    parser.add_argument("--profile", default=None, choices=("quick", "paper"), help="default: paper")
    parser.add_argument("--out", default=None, help="JSON list the run is appended to")
    parser.add_argument("--cache-dir", default=None,
                        help="cache folder (must be empty, and is kept; --smoke: used as it is)")
    parser.add_argument("--python", default=None, help="interpreter that runs passmd")
    args = parser.parse_args()
    profile = "quick" if args.smoke else args.profile or ("quick" if args.quick else "paper")
    run = measure(profile, passmd_python(args.python), args.cache_dir, cold=not args.smoke)
    append_run(output(args), run)


if __name__ == "__main__":
    try:  # one line on failure (the command line's contract), where passmd is installed
        from passmd.runtime.scripts import run_script
    except ImportError:  # pragma: no cover - run with a Python that has no passmd
        def run_script(main):
            return main() or 0
    sys.exit(run_script(main))
