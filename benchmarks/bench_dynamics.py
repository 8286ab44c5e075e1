"""Speed of the hybrid simulator: ns per integrator step and wall time per 100 Hz period.

Runs each configuration (one/six contacts × rigid/flexible × exact/discrete N = 200) with
each integration scheme (:data:`passmd.solver.steps.SCHEMES`): the default error-controlled
step ("controlled"), the fixed fine step ("fixed", the reference) and, for flexible
actuators, the explicit adaptive step ("adaptive") and the quasi-static actuator at a fixed
runner step ("quasi-static"). Each run is three 100 Hz saw-tooth periods (150 nm,
0.4 N, R = 1 mm: the first from rest, two after a slip), repeated; the medians of the wall
time give ms per period (wall / 3) and ns per integrator step (rejected error-controlled
steps included). numba compilation happens in an untimed warm-up run. Each row also gives
the largest difference of the settled positions of the three periods from the fixed fine
step's.

Kernel comparison: the kernel of :data:`OLD_KERNEL_COMMIT` (one numba function before its
split into inline helpers, loaded from ``git show`` at the path it had then, its imports of
modules moved since renamed, into a module of its own) and the current one run the same
configurations in alternation in this one process, each first in every other pair; the
medians of their wall times, their ratio (current / old), and whether the two runs agree to
the last bit. Without that commit in the checkout's history (a shallow clone, an unpacked
sdist) the comparison is skipped with a line saying so.

Start-up: the median time from launching ``passmd run --periods 1`` to its first
integrator step (warm: bytecode and numba caches written by an untimed first launch),
the modules that command imports, and ``python -X importtime`` of the package's
command-line and dynamics modules. The machine's load average is recorded with the numbers.

Usage::

    python benchmarks/bench_dynamics.py [--repeats 5] [--out passmd/data/benchmarks/dynamics.json]
    python benchmarks/bench_dynamics.py --smoke   # seconds: every part once, to a temporary file

``--smoke`` runs every part on its smallest input (one rigid contact with the fixed and the
controlled step, one repeat, one old/new kernel pair on one configuration when the history
holds the old commit, one launch) and writes to a temporary file: it checks that the script
and its defaults work, its times mean nothing.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from passmd.model import waveforms
from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import Drive
from passmd.runtime.scripts import child_json
from passmd.solver import kernels, simulation

CONFIGS = [
    (contacts, model, contact, control)
    for contacts in (1, 6)
    for model in ("rigid", "flexible")
    for contact in ("exact", "discrete")
    # the fixed fine step first: it is the reference of the others' error
    for control in (("fixed", "controlled", "adaptive", "quasi-static") if model == "flexible"
                    else ("fixed", "controlled"))
]
#: 100 Hz periods of each timed run (the first from rest, the others after a slip).
PERIODS = 3


#: The commit whose kernel the current one is timed against (the last with ``_integrate`` as
#: one function).
OLD_KERNEL_COMMIT = "37f6f0a9a427d3fbfea40a9de15b88372af24c65"
#: Configurations of the kernel comparison: (contacts, actuators, contact model, scheme).
KERNEL_CONFIGS = [(6, "flexible", "exact", "controlled"), (6, "rigid", "exact", "controlled"),
                  (6, "flexible", "exact", "adaptive"), (6, "flexible", "discrete", "controlled"),
                  (1, "flexible", "exact", "quasi-static")]
ROOT = Path(__file__).resolve().parents[1]
#: The current kernel's path; at an older commit it may have lived elsewhere (:func:`moved_since`).
KERNEL_PATH = "passmd/solver/kernels.py"


def _git(*args: str) -> str:
    return subprocess.run(["git", "-C", str(ROOT), *args], capture_output=True, text=True, check=True).stdout


def in_history(commit: str) -> bool:
    """Whether this checkout's git history holds ``commit`` (not in a shallow clone, an sdist or a wheel)."""
    try:
        _git("cat-file", "-e", f"{commit}^{{commit}}")
    except (OSError, subprocess.CalledProcessError):
        return False
    return True


def moved_since(commit: str) -> dict[str, str]:
    """Files of ``passmd/`` moved since ``commit``: {path then: path now}, each commit's renames in turn."""
    now: dict[str, str] = {}
    for line in _git("log", "--reverse", "-M", "--name-status", "--format=", f"{commit}..HEAD", "--",
                     "passmd").splitlines():
        status, *paths = line.split("\t")
        if status.startswith("R"):
            origin = next((then for then, path in now.items() if path == paths[0]), paths[0])
            now[origin] = paths[1]
    return now


def _module(path: str) -> str:
    return path.removesuffix(".py").removesuffix("/__init__").replace("/", ".")


def old_kernel_source(commit: str) -> str:
    """The kernel of ``commit`` (at its path then), its imports of moved passmd modules renamed to today's."""
    moved = moved_since(commit)
    then = next((old for old, new in moved.items() if new == KERNEL_PATH), KERNEL_PATH)
    modules = {_module(old): _module(new) for old, new in moved.items() if old.endswith(".py")}
    try:
        source = _git("show", f"{commit}:{then}")
    except subprocess.CalledProcessError:
        raise SystemExit(f"--old-kernel {commit}: that commit has no {then} (the kernel's path)") from None
    return re.sub(r"^(\s*(?:from|import)\s+)(passmd[\w.]*)", lambda m: m[1] + modules.get(m[2], m[2]),
                  source, flags=re.MULTILINE)


def old_kernel(commit: str):
    """The kernel of ``commit`` (:func:`old_kernel_source`) as a module of its own (in a temporary
    directory, so that its numba cache does not touch the package's)."""
    source = old_kernel_source(commit)
    path = Path(tempfile.mkdtemp(prefix="passmd-old-kernel-")) / "passmd_old_kernel.py"
    path.write_text(source)
    spec = importlib.util.spec_from_file_location("passmd_old_kernel", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@contextmanager
def running(module):
    """:mod:`passmd.solver.simulation` integrates with ``module``'s kernel (None: the current one); the
    argument records are rebuilt as that module's NamedTuples."""
    current = kernels.integrate
    if module is not None:
        def integrate(segments, mechanics, control, contacts, buffers, limit):
            return module.integrate(module.Segments(*segments), module.Mechanics(*mechanics),
                                    module.StepControl(*control), module.Contacts(*contacts),
                                    module.Buffers(*buffers), limit)
        kernels.integrate = integrate
    try:
        yield
    finally:
        kernels.integrate = current


def _outcome(res) -> tuple:
    return (res.steps, res.fine_steps, res.rejected_steps, res.settled_positions.tobytes(),
            res.final_state.tobytes(), res.runner_position.tobytes(), tuple(sorted(res.energy.items())))


def compare_kernels(commit: str, pairs: int, configs=KERNEL_CONFIGS, springs: int = 200) -> list:
    """Old and current kernel on ``configs``, timed in ``pairs`` alternating pairs (each kernel
    first in every other one): medians (ms per 100 Hz period), their ratio, and whether the
    results are identical to the last bit."""
    old = old_kernel(commit)
    rows = []
    for contacts, model, contact, scheme in configs:
        drive = Drive(contacts=contacts, actuator_model=model)
        kw = dict(contact_model=contact, springs=springs, scheme=scheme, max_points=2000)
        wf = waveforms.sawtooth(150e-9, PROTOCOL.drive_frequency, drive, periods=PERIODS)
        walls = {"old": [], "new": []}
        outcome = {}
        for i in range(pairs + 1):
            # the order alternates: the second run of a pair is slowed by the first (measured:
            # ≈ 20 % in either order), a fixed order would charge that to one kernel
            pair = (("old", old), ("new", None)) if i % 2 else (("new", None), ("old", old))
            for name, module in pair:
                with running(module):
                    res = simulation.simulate(drive, wf, **kw)
                if i:  # the first round compiles
                    walls[name].append(res.wall_time)
                outcome[name] = _outcome(res)
        old_ms, new_ms = (float(np.median(walls[n])) / PERIODS * 1e3 for n in ("old", "new"))
        rows.append({"contacts": contacts, "actuator": model, "contact_model": contact, "step": scheme,
                     "old_ms_per_100Hz_period": old_ms, "new_ms_per_100Hz_period": new_ms,
                     "new_over_old": new_ms / old_ms, "identical": outcome["old"] == outcome["new"],
                     "old_all_s": walls["old"], "new_all_s": walls["new"]})
    return rows


#: modules the ``run`` command should not need (imported only by other commands)
HEAVY_MODULES = ("pandas", "matplotlib", "pint", "dask", "distributed", "tqdm")

# launched as ``python -c``: reports (on stderr) the time and the heavy modules loaded when
# the CLI first enters the integrator (the checking wrapper ``_dynamics_kernel.integrate``,
# which passmd.solver.simulation looks up at call time), then finishes the command. The wrapper is
# put in when the command itself imports the kernel module (an import hook), so numba loads
# inside ``cli.main`` at the same point as in a real launch.
_FIRST_STEP = """
import importlib.machinery, json, sys, time
class Hook:
    @staticmethod
    def find_spec(name, path, target=None):
        if name != "passmd.solver.kernels":
            return None
        sys.meta_path.remove(Hook)
        spec = importlib.machinery.PathFinder.find_spec(name, path)
        load = spec.loader.exec_module
        def exec_module(kern):
            load(kern)
            integrate = kern.integrate
            def announced(*args, **kwargs):
                heavy = [m for m in json.loads(sys.argv[1]) if m in sys.modules]
                sys.stderr.write(json.dumps({"ready": time.time(), "heavy": heavy}) + "\\n")
                sys.stderr.flush()
                kern.integrate = integrate
                return integrate(*args, **kwargs)
            kern.integrate = announced
        spec.loader.exec_module = exec_module
        return spec
sys.meta_path.insert(0, Hook)
from passmd import cli
sys.exit(cli.main(sys.argv[2:]))
"""


def _warm_env() -> dict:
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)  # a warm machine has its bytecode cached
    return env


def startup(repeats: int) -> dict:
    """Launch-to-first-step time of ``passmd run --periods 1`` (median), modules, importtime."""
    argv = [sys.executable, "-c", _FIRST_STEP, json.dumps(HEAVY_MODULES), "run", "--periods", "1", "--json"]
    times, heavy = [], []
    for i in range(repeats + 1):
        start = time.time()
        proc = subprocess.run(argv, capture_output=True, text=True, env=_warm_env())
        report = child_json(proc, "passmd run (the start-up probe)", stream="stderr", line=0)
        if i:  # the first launch writes the caches
            times.append(report["ready"] - start)
        heavy = report["heavy"]
    imp = subprocess.run(
        [sys.executable, "-X", "importtime", "-c", "import passmd.cli, passmd.solver.simulation"],
        capture_output=True, text=True, env=_warm_env(), check=True,
    ).stderr
    cumulative = {}
    for line in imp.splitlines():
        parts = [p.strip() for p in line.split("|")]
        if len(parts) == 3 and parts[2] in ("passmd.cli", "passmd.solver.simulation", "numpy", "numba"):
            cumulative[parts[2]] = int(parts[1]) / 1e6
    return {
        "command": "passmd run --periods 1",
        "launch_to_first_step_s": statistics.median(times),
        "launch_to_first_step_all_s": times,
        "heavy_modules_imported": heavy,
        "importtime_cumulative_s": cumulative,
    }


_REFERENCE: dict = {}


def bench(contacts: int, model: str, contact: str, control: str, repeats: int, springs: int = 200) -> dict:
    drive = Drive(contacts=contacts, actuator_model=model)
    kw = dict(contact_model=contact, springs=springs, scheme=control)
    warm = waveforms.sawtooth(150e-9, 10e3, drive, periods=1)
    simulation.simulate(drive, warm, **kw)  # compile
    wf = waveforms.sawtooth(150e-9, PROTOCOL.drive_frequency, drive, periods=PERIODS)
    walls = []
    for _ in range(repeats):
        res = simulation.simulate(drive, wf, max_points=2000, **kw)
        walls.append(res.wall_time)
    if control == "fixed":
        _REFERENCE[(contacts, model, contact)] = res.settled_positions
    reference = _REFERENCE[(contacts, model, contact)]
    wall = statistics.median(walls)
    return {
        "contacts": contacts,
        "actuator": model,
        "step": control,
        "contact_model": contact if contact == "exact" else f"discrete N={springs}",
        "steps_per_period": res.steps / PERIODS,
        "rejected_per_period": res.rejected_steps / PERIODS,
        "fine_per_period": res.fine_steps / PERIODS,
        "fine_step_ns": res.fine_step * 1e9,
        "coarse_step_ns": res.coarse_step * 1e9,
        "ns_per_step": wall / res.steps * 1e9,
        "ms_per_100Hz_period": wall / PERIODS * 1e3,
        "error_vs_fixed_fine_nm": float(abs(res.settled_positions - reference).max()) * 1e9,
    }


# launched as ``python -c``: the median ms per 100 Hz period of the default scheme, six
# contacts, flexible actuators, exact contact, in a process of its own
_ONE_PROCESS = """
import json, statistics, sys
from passmd.solver import simulation
from passmd.model import waveforms
from passmd.model.parameters import Drive
d = Drive(contacts=6, actuator_model="flexible")
wf = waveforms.sawtooth(150e-9, float(sys.argv[1]), d, periods=int(sys.argv[2]))
simulation.simulate(d, wf, max_points=2000)
walls = [simulation.simulate(d, wf, max_points=2000).wall_time for _ in range(int(sys.argv[3]))]
print(json.dumps(statistics.median(walls) / int(sys.argv[2]) * 1e3))
"""


def across_processes(processes: int, repeats: int) -> dict:
    """ms per 100 Hz period of the headline configuration (six contacts, flexible, exact contact,
    default step), median of ``repeats`` runs in each of ``processes`` fresh processes: the
    2-core virtual machine's speed differs from one process to the next (by up to a third)."""
    per_process = []
    for _ in range(processes):
        argv = [sys.executable, "-c", _ONE_PROCESS, str(PROTOCOL.drive_frequency), str(PERIODS), str(repeats)]
        done = subprocess.run(argv, capture_output=True, text=True, env=_warm_env())
        per_process.append(child_json(done, "the timing process"))
    return {"configuration": "6 contacts, flexible, controlled, exact",
            "ms_per_100Hz_period_per_process": per_process,
            "median_ms_per_100Hz_period": statistics.median(per_process)}


def markdown(rows: list) -> str:
    """The rows as a Markdown table."""
    lines = ["| contacts | actuators | step control | contact model | steps per period (fine; rejected) "
             "| ns per step | ms per 100 Hz period | error vs fixed fine step (nm) |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['contacts']} | {r['actuator']} | {r['step']} | {r['contact_model']} "
                     f"| {r['steps_per_period']:.0f} "
                     f"({r['fine_per_period']:.0f}; {r['rejected_per_period']:.0f}) "
                     f"| {r['ns_per_step']:.1f} | {r['ms_per_100Hz_period']:.2f} "
                     f"| {r['error_vs_fixed_fine_nm']:.4f} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5, help="timed repeats per configuration (median)")
    ap.add_argument("--old-kernel", default=None,
                    help="commit whose kernel the current one is timed against (default: OLD_KERNEL_COMMIT, "
                         "skipped when this checkout's history lacks it)")
    ap.add_argument("--kernel-pairs", type=int, default=40,
                    help="timed old/new pairs per configuration of the kernel comparison (even: each "
                         "kernel first in half of them)")
    ap.add_argument("--kernel-only", action="store_true", help="only the kernel comparison (not written)")
    ap.add_argument("--smoke", action="store_true",
                    help="every part on its smallest input (one contact, one repeat, one kernel pair, one "
                         "launch), written to a temporary file: checks the script runs, measures nothing")
    ap.add_argument("--out", type=Path, default=None,
                    help="JSON written (default: passmd/data/benchmarks/dynamics.json; --smoke: a "
                         "temporary file)")
    args = ap.parse_args(argv)
    if args.kernel_pairs < 2 or args.kernel_pairs % 2:
        ap.error(f"--kernel-pairs {args.kernel_pairs} is out of range: must be an even number >= 2")
    configs, kernel_configs = CONFIGS, KERNEL_CONFIGS
    if args.smoke:
        args.repeats, args.kernel_pairs = 1, 2
        # one rigid contact (the fixed step first: the reference); the cheapest kernel comparison
        configs, kernel_configs = CONFIGS[:2], KERNEL_CONFIGS[-1:]
    if args.out is None:
        args.out = (Path(tempfile.mkdtemp(prefix="passmd-bench-")) / "dynamics.json" if args.smoke
                    else ROOT / "passmd/data/benchmarks/dynamics.json")
    load_before = os.getloadavg()
    commit = args.old_kernel or OLD_KERNEL_COMMIT
    if in_history(commit):
        kernel_rows = compare_kernels(commit, args.kernel_pairs, kernel_configs)
    elif args.old_kernel:
        ap.error(f"--old-kernel {commit} is not a commit of this checkout's git history")
    else:
        print(f"kernel comparison skipped: --old-kernel {commit[:12]} is not in this checkout's git history "
              "(a shallow clone or no repository); fetch it (git fetch --unshallow) to compare")
        kernel_rows = None
    for r in kernel_rows or []:
        print(f"kernel {r['contacts']} {r['actuator']} {r['contact_model']} {r['step']}: old "
              f"{r['old_ms_per_100Hz_period']:.3f} ms, new {r['new_ms_per_100Hz_period']:.3f} ms per period, "
              f"new/old {r['new_over_old']:.3f}, identical: {r['identical']}")
    if args.kernel_only:
        return 0
    rows = [bench(c, m, k, control, args.repeats) for c, m, k, control in configs]
    start = startup(args.repeats)
    spread = across_processes(args.repeats, args.repeats)
    print(markdown(rows))
    print(f"start-up ({start['command']}): {start['launch_to_first_step_s']:.3f} s to the first step; "
          f"heavy modules imported: {start['heavy_modules_imported'] or 'none'}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    meta = {
        "machine": platform.processor() or platform.machine(),
        "python": platform.python_version(),
        "repeats": args.repeats,
        "kernel_pairs": args.kernel_pairs,
        "periods_per_run": PERIODS,
        "cpus": os.cpu_count(),
        "date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()),
        # 1-, 5-, 15-minute load averages before and after: > 0.5 means the machine was not quiet
        "load_average_before": list(load_before),
        "load_average_after": list(os.getloadavg()),
    }
    print(f"load average before {load_before}, after {meta['load_average_after']} on {meta['cpus']} CPUs")
    print(f"{spread['configuration']}: {spread['median_ms_per_100Hz_period']:.3f} ms per period, median of "
          f"{len(spread['ms_per_100Hz_period_per_process'])} processes "
          f"({', '.join(f'{v:.2f}' for v in spread['ms_per_100Hz_period_per_process'])})")
    comparison = {"old_commit": commit, "rows": kernel_rows} if kernel_rows is not None else None
    args.out.write_text(json.dumps({"meta": meta, "rows": rows, "startup": start, "across_processes": spread,
                                    "kernel_comparison": comparison}, indent=2))
    print(f"written {args.out}")
    return 0


if __name__ == "__main__":
    from passmd.runtime.scripts import run_script

    sys.exit(run_script(main))  # one line on failure, never a traceback
