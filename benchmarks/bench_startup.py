"""Start-up tricks of the command line, each with and without, as whole processes side by side.

``passmd.cli.startup`` holds the tricks: pausing the cyclic garbage collector while a command
starts (``pause``/``resume``), freezing instead of collecting at the interpreter's exit
(``skip_exit_collection``) and loading numba's array-math registry with scipy's BLAS module
hidden (``load_numba_without_blas_probe``). Each variant launches the same command line,
``python -c`` calling :func:`passmd.cli.main`, with the named tricks replaced by no-ops in that
process; the variants run in turn in every round (the order rotated from round to round, after
one untimed warm-up launch of each, which also writes bytecode and numba caches), so a drift
of the machine's speed reaches all of them alike. For each command and variant: the median
wall and CPU (user + sys) seconds of a launch, and the median of the per-round ratios to the
shipped variant (all tricks on). The machine's load averages are recorded with the numbers.

Usage::

    python benchmarks/bench_startup.py [--rounds 15] [--out passmd/data/benchmarks/startup.json]
    python benchmarks/bench_startup.py --smoke   # seconds: every variant once on --help, to a temporary file

``--smoke`` runs one round of every variant on ``passmd --help`` only and writes to a
temporary file: it checks that the script and its patches work; its times mean nothing.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: variant name → the tricks of ``passmd.cli.startup`` replaced by no-ops in its process
VARIANTS = {
    "shipped": (),
    "no collector pause": ("pause",),
    "no exit freeze": ("skip_exit_collection",),
    "no BLAS hiding": ("load_numba_without_blas_probe",),
    "none": ("pause", "skip_exit_collection", "load_numba_without_blas_probe"),
}

#: command name → arguments of ``passmd`` (the default drive's run, warm caches)
COMMANDS = {"--help": ["--help"], "run": ["run"]}

_LAUNCH = """
import sys
from passmd.cli import startup
for name in sys.argv[1].split(",") if sys.argv[1] else ():
    setattr(startup, name, lambda *a, **k: None)
from passmd.cli import main
sys.exit(main(sys.argv[2:]))
"""


def launch(variant: str, argv: list[str]) -> tuple[float, float]:
    """(wall, CPU) seconds of one launch of ``passmd argv`` with ``variant``'s tricks off."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", _LAUNCH, ",".join(VARIANTS[variant]), *argv],
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def measure(argv: list[str], rounds: int) -> dict:
    """Every variant ``rounds`` times, interleaved; medians and per-round ratios to "shipped"."""
    names = list(VARIANTS)
    for name in names:
        launch(name, argv)  # untimed: bytecode, numba's cache, the result cache
    wall = {name: [] for name in names}
    cpu = {name: [] for name in names}
    for r in range(rounds):
        for name in names[r % len(names):] + names[:r % len(names)]:
            w, c = launch(name, argv)
            wall[name].append(w)
            cpu[name].append(c)
    rows = {}
    for name in names:
        ratios = [w / s for w, s in zip(wall[name], wall["shipped"], strict=True)]
        cpu_ratios = [c / s for c, s in zip(cpu[name], cpu["shipped"], strict=True)]
        rows[name] = {"wall_median_s": statistics.median(wall[name]), "wall_min_s": min(wall[name]),
                      "wall_max_s": max(wall[name]), "cpu_median_s": statistics.median(cpu[name]),
                      "wall_over_shipped_median": statistics.median(ratios),
                      "cpu_over_shipped_median": statistics.median(cpu_ratios)}
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=15, help="timed launches of each variant and command")
    ap.add_argument("--out", type=Path, default=None, help="JSON record (default "
                    "passmd/data/benchmarks/startup.json; --smoke: a temporary file)")
    ap.add_argument("--smoke", action="store_true", help="one round of every variant on --help, to a "
                    "temporary file (checks the script works)")
    args = ap.parse_args(argv)
    commands = COMMANDS
    if args.smoke:
        args.rounds, commands = 1, {"--help": COMMANDS["--help"]}
    if args.out is None:
        args.out = (Path(tempfile.mkdtemp(prefix="passmd-bench-")) / "startup.json" if args.smoke
                    else ROOT / "passmd/data/benchmarks/startup.json")
    load_before = os.getloadavg()
    results = {}
    for command, command_argv in commands.items():
        results[command] = measure(command_argv, args.rounds)
        for name, row in results[command].items():
            print(f"passmd {command:7} {name:19} wall {row['wall_median_s']:.3f} s "
                  f"(min {row['wall_min_s']:.3f}, max {row['wall_max_s']:.3f}), "
                  f"cpu {row['cpu_median_s']:.3f} s, /shipped: wall "
                  f"{row['wall_over_shipped_median']:.3f}, cpu {row['cpu_over_shipped_median']:.3f}")
    meta = {
        "machine": platform.processor() or platform.machine(),
        "python": platform.python_version(),
        "cpus": os.cpu_count(),
        "rounds": args.rounds,
        "date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()),
        # 1-, 5-, 15-minute load averages before and after: > 0.5 means the machine was not quiet
        "load_average_before": list(load_before),
        "load_average_after": list(os.getloadavg()),
    }
    print(f"load average before {load_before}, after {meta['load_average_after']} on {meta['cpus']} CPUs")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps({"meta": meta, "variants": {k: list(v) for k, v in VARIANTS.items()},
                                    "commands": results}, indent=2))
    print(f"written {args.out}")
    return 0


if __name__ == "__main__":
    from passmd.runtime.scripts import run_script

    sys.exit(run_script(main))  # one line on failure, never a traceback
