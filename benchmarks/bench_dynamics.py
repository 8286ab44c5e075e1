"""Speed of the hybrid simulator: the default integrator against a plain fixed-step code and per scheme.

Headline (``headline``): one 100 Hz period of the paper's six-contact drive with flexible actuators
and the exact contact (150 nm saw-tooth, three periods from rest per run), integrated by the plain
fixed-step velocity-Verlet code of :mod:`verlet_baseline` (the yardstick), by the default scheme
("controlled") and by the scheme it replaced ("reference": the before of this record), the three in
turn within each of ``--headline-repeats`` rounds (the order rotating from round to round, so
that load on the shared machine falls on all three alike), numba compilation in an untimed first
round. The reference runs as the former default did, summing the energy terms. Recorded: the
medians in ms per period of the wall time, the CPU time and the CPU time of the integration loop
alone (the marginal cost of a period, what the budget is about), the ratios baseline/default and
reference/default (the before/after), each run's settled positions against the package's fixed
fine step, and the load average before and after.

Table (``rows``): each configuration (one/six contacts × rigid/flexible × exact/discrete N = 200)
with each integration scheme (:data:`passmd.solver.steps.SCHEMES`): the default error-controlled
step ("controlled"), the former one ("reference"), the fixed fine step ("fixed", the reference of
the errors) and, for flexible actuators, the explicit adaptive step ("adaptive") and the
quasi-static actuator at a fixed runner step ("quasi-static"); medians of the wall time of
three-period runs give ms per period and ns per integrator step (rejected error-controlled steps
included), and the largest difference of the settled positions from the fixed fine step's.

Start-up: the median time from launching ``passmd run --periods 1`` to its first integrator step
(warm: bytecode and numba caches written by an untimed first launch), the modules that command
imports, and ``python -X importtime`` of the package's command-line and dynamics modules. The
headline configuration is also timed in several fresh processes (the 2-core virtual machine's
speed differs from one process to the next).

Usage::

    python benchmarks/bench_dynamics.py [--repeats 5] [--headline-repeats 9]
        [--out passmd/data/benchmarks/dynamics.json]
    python benchmarks/bench_dynamics.py --smoke   # seconds: every part once, to a temporary file

``--smoke`` runs every part on its smallest input (the headline at 10 kHz with one round, one
rigid contact with the fixed and the default step, one repeat, one launch, one process) and writes
to a temporary file: it checks that the script and its defaults work, its times mean nothing.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
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

sys.path.insert(0, str(Path(__file__).resolve().parent))
import verlet_baseline  # noqa: E402  (a sibling script: the plain fixed-step code)

CONFIGS = [
    (contacts, model, contact, control)
    for contacts in (1, 6)
    for model in ("rigid", "flexible")
    for contact in ("exact", "discrete")
    # the fixed fine step first: it is the reference of the others' error
    for control in (("fixed", "controlled", "reference", "adaptive", "quasi-static") if model == "flexible"
                    else ("fixed", "controlled", "reference"))
]
#: 100 Hz periods of each timed run (the first from rest, the others after a slip).
PERIODS = 3
ROOT = Path(__file__).resolve().parents[1]


#: The headline: the paper's six contacts with flexible actuators and the exact contact.
HEADLINE_AMPLITUDE = 150e-9
#: Schemes of the headline besides the baseline: the default and the one it replaced.
HEADLINE_SCHEMES = ("controlled", "reference")


@contextmanager
def kernel_cpu_time():
    """Yields a one-item list that accumulates the CPU time spent in
    :func:`passmd.solver.kernels.integrate` (the integration itself: the marginal cost of the
    periods) while the block runs."""
    spent = [0.0]
    integrate = kernels.integrate

    def timed(*args, **kwargs):
        start = time.thread_time()
        try:
            return integrate(*args, **kwargs)
        finally:
            spent[0] += time.thread_time() - start

    kernels.integrate = timed
    try:
        yield spent
    finally:
        kernels.integrate = integrate


def _timed_run(drive, wf, name) -> tuple:
    """One headline run (``name``: "baseline" or a scheme): settled positions, steps, the wall and
    CPU time of the whole call (set-up and results included), and the CPU time of the integration
    loop alone (the marginal cost of the periods; the CPU time of this thread does not count the
    time other processes held the core)."""
    wall, cpu = time.perf_counter(), time.thread_time()
    if name == "baseline":
        settled, steps, _, loop = verlet_baseline.run(drive, wf, cpu=True)
    else:
        with kernel_cpu_time() as spent:  # (the former default always summed the energy terms)
            res = simulation.simulate(drive, wf, scheme=name, max_points=2, energy=name == "reference")
        settled, steps, loop = res.settled_positions, res.steps, spent[0]
    return settled, steps, time.perf_counter() - wall, time.thread_time() - cpu, loop


def headline(rounds: int, frequency: float = PROTOCOL.drive_frequency) -> dict:
    """Baseline, default and reference on the headline configuration, in turn within each of
    ``rounds`` timed rounds (module docstring): medians in ms per period of the wall time, of the
    CPU time and of the integration loop's CPU time (the marginal cost: what a period adds to a
    run), and their ratios. On a loaded machine the wall time of the long baseline runs stretches
    more than that of the short ones (the scheduler shares a core in slices of milliseconds): the
    CPU time ratios are the ones a quiet machine would show."""
    drive = Drive(contacts=6, actuator_model="flexible")
    wf = waveforms.sawtooth(HEADLINE_AMPLITUDE, frequency, drive, periods=PERIODS)
    fixed = simulation.simulate(drive, wf, scheme="fixed", max_points=2).settled_positions
    names = ("baseline",) + HEADLINE_SCHEMES
    times = {kind: {name: [] for name in names} for kind in ("wall", "cpu", "loop")}
    steps, errors = {}, {}
    load_before = os.getloadavg()
    for i in range(rounds + 1):
        for name in names[i % 3:] + names[:i % 3]:
            settled, n, *measured = _timed_run(drive, wf, name)
            if i:  # the first round compiles
                for kind, value in zip(("wall", "cpu", "loop"), measured, strict=True):
                    times[kind][name].append(value / PERIODS * 1e3)
            steps[name] = n / PERIODS
            errors[name] = float(np.abs(settled - fixed).max()) * 1e9
    median = {kind: {name: statistics.median(v) for name, v in by.items()} for kind, by in times.items()}
    ratios = {kind: {"baseline_over_default": m["baseline"] / m["controlled"],
                     "reference_over_default": m["reference"] / m["controlled"]}
              for kind, m in median.items()}
    return {
        "configuration": "6 contacts, flexible, exact contact, 150 nm saw-tooth",
        "frequency_Hz": frequency,
        "rounds": rounds,
        "ms_per_period": median,
        "all_ms_per_period": times,
        "ratios": ratios,
        "steps_per_period": steps,
        "error_vs_fixed_fine_nm": errors,
        "load_average_before": list(load_before),
        "load_average_after": list(os.getloadavg()),
    }


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
from passmd.solver import kernels, simulation
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
    ap.add_argument("--repeats", type=int, default=5,
                    help="timed repeats per configuration of the table (median)")
    ap.add_argument("--headline-repeats", type=int, default=9,
                    help="timed rounds of the headline (baseline, default and reference in turn; median)")
    ap.add_argument("--headline-only", action="store_true", help="only the headline (printed, not written)")
    ap.add_argument("--smoke", action="store_true",
                    help="every part on its smallest input (the headline at 10 kHz, one contact, one repeat, "
                         "one launch), written to a temporary file: checks the script runs, measures nothing")
    ap.add_argument("--out", type=Path, default=None,
                    help="JSON written (default: passmd/data/benchmarks/dynamics.json; --smoke: a "
                         "temporary file)")
    args = ap.parse_args(argv)
    configs, frequency = CONFIGS, PROTOCOL.drive_frequency
    if args.smoke:
        args.repeats, args.headline_repeats = 1, 1
        configs, frequency = CONFIGS[:2], 10e3  # one rigid contact: the fixed step first, the reference
    if args.out is None:
        args.out = (Path(tempfile.mkdtemp(prefix="passmd-bench-")) / "dynamics.json" if args.smoke
                    else ROOT / "passmd/data/benchmarks/dynamics.json")
    load_before = os.getloadavg()
    head = headline(args.headline_repeats, frequency)
    ms, ratios = head["ms_per_period"], head["ratios"]
    print(f"{head['configuration']}, {frequency:g} Hz, median of {head['rounds']} rounds (load "
          f"{head['load_average_before'][0]:.2f} -> {head['load_average_after'][0]:.2f}), ms per period:")
    for kind, label in (("loop", "integration loop, CPU"), ("cpu", "whole call, CPU"),
                        ("wall", "whole call, wall")):
        m, r = ms[kind], ratios[kind]
        print(f"  {label:22s}: plain Verlet {m['baseline']:8.3f}, reference {m['reference']:.3f}, default "
              f"{m['controlled']:.3f}; baseline/default {r['baseline_over_default']:.0f}x, reference/default "
              f"{r['reference_over_default']:.2f}x")
    if args.headline_only:
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
    args.out.write_text(json.dumps({"meta": meta, "headline": head, "rows": rows, "startup": start,
                                    "across_processes": spread}, indent=2))
    print(f"written {args.out}")
    return 0


if __name__ == "__main__":
    from passmd.runtime.scripts import run_script

    sys.exit(run_script(main))  # one line on failure, never a traceback
