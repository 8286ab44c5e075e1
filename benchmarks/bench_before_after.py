"""Before and after in one run: the fit, map, ledger and book benchmarks of an earlier revision and this tree.

Each benchmark named by ``--only`` is run twice in this one run, one after the other: first by the
earlier revision ``--before`` (its own script and its own ``passmd``, from a temporary ``git
worktree`` of this repository, imported through ``PYTHONPATH`` by the same interpreter and
dependencies), then by this tree. The record holds, per benchmark, both wall times with the
commit and the load average (1/5/15 min) around each, and their ratio before/after; a ratio is
only as good as the load it was measured under, which is why both loads are beside it.

The default earlier revision, :data:`BEFORE`, is main before the hybrid error-controlled step,
the Newton balances and the cheaper sweeps: the code the speed budgets of
:mod:`bench_dynamics`, :mod:`bench_fit`, :mod:`bench_sweep_map`, :mod:`bench_ledger` and
:mod:`bench_book` were set against. Each revision's script defines the workload it times; the
fit and the map are the same at both (15 steady steps of μ and k_p; a 24 × 24 velocity map),
the ledger and the book grew in between (more claims, held-out readings), so their records also
carry each side's points computed.

Before anything is timed, both trees run ``bench_fit.py --smoke`` once, untimed: it compiles the
numba kernels into each tree's own cache, so neither side's first benchmark pays for compiling.
``--only book`` also installs the worktree's ``book`` nox environment first, untimed.

Usage::

    python benchmarks/bench_before_after.py                       # fit, map, ledger; before = BEFORE
    python benchmarks/bench_before_after.py --only fit,map,ledger,book
    python benchmarks/bench_before_after.py --before <rev> --out before_after.json
    python benchmarks/bench_before_after.py --smoke               # HEAD against this tree, fit --smoke

``--smoke`` checks that the script works in seconds: the earlier revision is ``HEAD`` (unless
``--before`` is given), the benchmark ``bench_fit.py --smoke``, the record a temporary file; its
times and ratio mean nothing.
"""

from __future__ import annotations

import argparse
import contextlib
import datetime
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from passmd.runtime.outputs import write_file

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_book import nox_command  # noqa: E402  (a sibling script: this Python's nox, else nox on PATH)
from bench_ledger import ROOT, git_commit, output  # noqa: E402  (the commit with its dirty mark; --out or default)

#: The earlier revision of the default record: main before the speed work.
BEFORE = "ba95e30"
#: Each benchmark: its script, its arguments, and how to read the timed wall time (s) and the
#: points it computed (None where the record has none) from the JSON it writes.
BENCHMARKS = {
    "fit": ("bench_fit.py", [], lambda r: r["wall_time_s"], lambda r: r.get("simulations")),
    "map": ("bench_sweep_map.py", [], lambda r: r["cold"]["wall_s"], lambda r: r["map"]["points"]),
    "ledger": ("bench_ledger.py", [], lambda r: r[-1]["wall_time_s"], lambda r: r[-1].get("points_computed")),
    "book": ("bench_book.py", [], lambda r: r[-1]["session_wall_s"], lambda r: None),
}
SMOKE = {"fit": ("bench_fit.py", ["--smoke"], BENCHMARKS["fit"][2], BENCHMARKS["fit"][3])}


def git(*args: str) -> str:
    done = subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"git {' '.join(args)} failed: {' '.join(done.stderr.split()) or 'no message'}")
    return done.stdout.strip()


@contextlib.contextmanager
def worktree(revision: str):
    """A temporary detached worktree of ``revision`` (removed afterwards, with git's record of it)."""
    commit = git("rev-parse", "--verify", f"{revision}^{{commit}}")
    with tempfile.TemporaryDirectory(prefix="passmd-before-") as folder:
        tree = Path(folder) / "tree"
        git("worktree", "add", "--detach", "--quiet", str(tree), commit)
        try:
            yield tree, commit
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(tree)], cwd=ROOT, capture_output=True)
            subprocess.run(["git", "worktree", "prune"], cwd=ROOT, capture_output=True)


def environment(tree: Path) -> dict:
    """This process's environment with ``tree``'s package first on the import path."""
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(tree), os.environ.get("PYTHONPATH", "")]).rstrip(
        os.pathsep), "MPLBACKEND": "Agg"}


def run_benchmark(tree: Path, script: str, args: list[str], out: Path) -> None:
    """``tree``'s ``benchmarks/<script> <args> --out <out>``, its output shown as it runs."""
    argv = [sys.executable, str(tree / "benchmarks" / script), *args, "--out", str(out)]
    done = subprocess.run(argv, cwd=tree, env=environment(tree))
    if done.returncode != 0:
        raise SystemExit(f"{script} of {tree} failed (exit status {done.returncode})")


def side(tree: Path, commit: str, name: str, spec, folder: Path) -> dict:
    """One side of one benchmark: its wall time (as its own record states it), points and loads."""
    script, args, wall, points = spec
    out = folder / f"{name}-{commit[:12]}.json"
    load_before = os.getloadavg()
    run_benchmark(tree, script, args, out)
    load_after = os.getloadavg()
    record = json.loads(out.read_text(encoding="utf-8"))
    return {"commit": commit, "wall_time_s": round(float(wall(record)), 2), "points_computed": points(record),
            "load_average_before": [round(x, 2) for x in load_before],
            "load_average_after": [round(x, 2) for x in load_after]}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", default=None,
                        help=f"earlier revision (default {BEFORE}; --smoke: HEAD)")
    parser.add_argument("--only", default="fit,map,ledger",
                        help=f"benchmarks, comma-separated, of {', '.join(BENCHMARKS)} "
                             "(default fit,map,ledger)")
    parser.add_argument("--smoke", action="store_true",
                        help="HEAD against this tree on bench_fit.py --smoke, to a temporary file: checks "
                             "the script runs, measures nothing")
    parser.add_argument("--out", default=None,
                        help="JSON written (default passmd/data/benchmarks/before_after.json; --smoke: a "
                             "temporary file)")
    args = parser.parse_args()
    chosen = SMOKE if args.smoke else {}
    if not args.smoke:
        for name in (n.strip() for n in args.only.split(",") if n.strip()):
            if name not in BENCHMARKS:
                raise SystemExit(f"--only {args.only}: {name!r} is not one of "
                                 f"{', '.join(BENCHMARKS)}")
            chosen[name] = BENCHMARKS[name]
        if not chosen:
            raise SystemExit(f"--only {args.only!r} names no benchmark: give some of "
                             f"{', '.join(BENCHMARKS)}")
    out = output(args, "before_after")
    here = git_commit()
    runs = {}
    with worktree(args.before or ("HEAD" if args.smoke else BEFORE)) as (tree, commit), \
            tempfile.TemporaryDirectory(prefix="passmd-before-after-") as scratch:
        folder = Path(scratch)
        for k, warm in enumerate((tree, ROOT)):  # each tree's kernels into its own numba cache, untimed
            run_benchmark(warm, "bench_fit.py", ["--smoke"], folder / f"warm-{k}.json")
        if "book" in chosen:  # the worktree's book environment, untimed
            done = subprocess.run([*nox_command(), "-s", "book", "--install-only"], cwd=tree,
                                  env=environment(tree), capture_output=True, text=True)
            if done.returncode != 0:
                last = (done.stderr.strip().splitlines() or ["no message"])[-1]
                raise SystemExit(f"installing the book environment of {commit[:12]} failed: {last}")
        for name, spec in chosen.items():
            start = time.perf_counter()
            before = side(tree, commit, name, spec, folder)
            after = side(ROOT, here, name, spec, folder)
            runs[name] = {"before": before, "after": after,
                          "ratio_before_over_after": round(before["wall_time_s"] / after["wall_time_s"], 2),
                          "pair_wall_s": round(time.perf_counter() - start, 1)}
            print(f"{name}: before {before['wall_time_s']:.1f} s, after {after['wall_time_s']:.1f} s, "
                  f"ratio {runs[name]['ratio_before_over_after']:.2f}", flush=True)
    record = {"date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
              "smoke": bool(args.smoke), "before": commit, "after": here, "cores": os.cpu_count(),
              "python": sys.version.split()[0], "benchmarks": runs}
    out.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps(record, indent=1) + "\n"
    write_file(out, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"), overwrite=True)  # atomic
    print(f"written {out}")
    return 0


if __name__ == "__main__":
    from passmd.runtime.scripts import run_script

    sys.exit(run_script(main))  # one line on failure, never a traceback
