"""How the simulator's cost grows: with contacts, with the drive frequency, with the size of a sweep.

* **Contacts** (``contacts``): one 100 Hz period (three from rest, 150 nm, flexible actuators,
  exact contacts, default scheme) with 1, 6 and 24 contacts (24: eight on side 1 and sixteen on
  side 2 at 45°, the paper's arrangement scaled four times), each contact integrated with its own
  state (``share_side_state=False``: 1, 6 and 24 contact states) and with one state per side
  (the default: 1, 2 and 2). The integration loop's CPU time per period and per step, steps per
  period.
* **Frequency** (``frequency``): the paper's six-contact flexible drive at 150 nm over 100 Hz to
  110 kHz, each run as long as the steady-velocity protocol makes it
  (:func:`passmd.protocols.velocity.steady_periods`: ``max(20, f·5 ms)`` periods). CPU time per
  period and per simulated millisecond, steps per period and the share of fine steps (the
  actuators ring after every fly-back for a few µs, a whole period above ≈ 100 kHz).
* **Sweep size** (``sweep``): :func:`passmd.runtime.sweep.run` of the settled step
  (:func:`passmd.protocols.velocity.settled_step`, six contacts, 1 kHz) over 2 to 64 amplitudes
  with an empty cache on the process pool (all cores): wall time against points; the slope is
  the cost per point on this machine, the intercept the pool's start-up.
* **Dask** (``dask``): the per-task overhead of :func:`passmd.runtime.sweep.run` with
  ``executor="dask"`` (a local cluster of one single-threaded worker per core): a sweep of a
  function that returns at once, without the result cache, at two sizes; the slope is the
  scheduler's cost per task, the intercept the cluster's start-up. Then one task of a batch of
  settled steps (the batch a cluster task of ≥ 1 s would carry). :func:`dask_plan` turns these
  into the plan of a 10⁶-point sweep.

Timings are CPU times of this thread where the part runs in this process (contacts,
frequency), wall times where it runs on workers (sweep, dask); the load average is recorded
before and after each part (the machine may be shared).

Usage::

    python benchmarks/bench_scaling.py [--out passmd/data/benchmarks/scaling.json]
    python benchmarks/bench_scaling.py --smoke   # seconds, to a temporary file

``--smoke`` runs every part on its smallest input (one contact count, two frequencies, sweeps of
two and four points, dask with 2 and 3 tasks when dask is installed, no batch task) and writes
to a temporary file: it checks that the script works, its numbers mean nothing.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from passmd.model import waveforms
from passmd.model.arrangement import ContactGroup
from passmd.model.parameters import Drive
from passmd.protocols import velocity
from passmd.runtime import sweep
from passmd.runtime.config import RunConfig
from passmd.solver import simulation

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_dynamics import kernel_cpu_time  # noqa: E402  (a sibling script)

ROOT = Path(__file__).resolve().parents[1]
AMPLITUDE = 150e-9
#: Contacts per drive of the contact scaling (24: the paper's two sides scaled four times).
CONTACTS = (1, 6, 24)
FREQUENCIES = (100.0, 300.0, 1e3, 3e3, 10e3, 30e3, 110e3)
SWEEP_SIZES = (2, 8, 32, 64)
DASK_TASKS = (50, 200)
#: Points of the batch one dask task of a large sweep carries (about a second of settled steps).
DASK_BATCH = 300
#: The sweep the Dask plan is for.
PLAN_POINTS = 1_000_000
#: Shortest task worth sending to a cluster (s): its scheduler overhead then stays below 1 %.
PLAN_TASK_S = 1.0


def drive_with(contacts: int) -> Drive:
    """The paper's drive (flexible actuators) with 1, 6 or 24 contacts (24: 8 + 16 at 45°)."""
    if contacts == 24:
        groups = (ContactGroup(8, contact_angle=math.pi / 4, side=1),
                  ContactGroup(16, contact_angle=math.pi / 4, side=2))
        return Drive(actuator_model="flexible", contact_groups=groups)
    return Drive(contacts=contacts, actuator_model="flexible")


def _loop_cpu(drive, wave, repeats: int, **kw) -> tuple[float, object]:
    """Median CPU time of the integration loop over ``repeats`` runs (after one untimed), and the
    last result."""
    simulation.simulate(drive, wave, max_points=2, **kw)
    times = []
    for _ in range(repeats):
        with kernel_cpu_time() as spent:
            res = simulation.simulate(drive, wave, max_points=2, **kw)
        times.append(spent[0])
    return statistics.median(times), res


def contacts_part(repeats: int, counts=CONTACTS) -> list[dict]:
    rows = []
    for n in counts:
        drive = drive_with(n)
        wave = waveforms.sawtooth(AMPLITUDE, 100.0, drive, periods=3)
        for shared in (False, True):
            cpu, res = _loop_cpu(drive, wave, repeats, share_side_state=shared)
            rows.append({"contacts": n, "contact_states": int(res.multiplicity.size),
                         "shared_side_state": shared, "ms_per_100Hz_period": cpu / 3 * 1e3,
                         "steps_per_period": res.steps / 3, "ns_per_step": cpu / res.steps * 1e9})
    return rows


def frequency_part(repeats: int, frequencies=FREQUENCIES) -> list[dict]:
    drive = drive_with(6)
    rows = []
    for f in frequencies:
        periods = velocity.steady_periods(f)
        wave = waveforms.sawtooth(AMPLITUDE, f, drive, periods=periods)
        cpu, res = _loop_cpu(drive, wave, repeats)
        rows.append({"frequency_Hz": f, "periods": periods, "ms_per_period": cpu / periods * 1e3,
                     "ms_per_simulated_ms": cpu / (periods / f * 1e3) * 1e3, "run_ms": cpu * 1e3,
                     "steps_per_period": res.steps / periods, "fine_share": res.fine_steps / res.steps})
    return rows


def _settled_point(amplitude: float) -> dict:
    """One sweep point: the settled step of the six-contact flexible drive at 1 kHz (picklable)."""
    out = velocity.settled_step(drive_with(6), amplitude, 1e3)
    return {"step_m": out["step_m"], "periods": out["periods"]}


def _timed_sweep(func, points, cached: bool = True, **kw) -> float:
    """Wall time of :func:`passmd.runtime.sweep.run` over ``points`` (``cached``: with an empty result
    cache, as a user's first sweep; else without one)."""
    with tempfile.TemporaryDirectory(prefix="bench-scaling-") as cache:
        start = time.perf_counter()
        sweep.run(func, points, cache=cache if cached else None,
                  config=RunConfig(cache_dir=cache if cached else None, progress=False), **kw)
        return time.perf_counter() - start


def _fit_line(x, y) -> tuple[float, float]:
    slope, intercept = np.polyfit(np.asarray(x, float), np.asarray(y, float), 1)
    return float(slope), float(intercept)


def sweep_part(sizes=SWEEP_SIZES) -> dict:
    amplitudes = np.linspace(90e-9, 200e-9, max(sizes))
    _settled_point(150e-9)  # numba loaded in this process (the pool's workers load it on their own)
    walls = [_timed_sweep(_settled_point, [{"amplitude": float(a)} for a in amplitudes[:n]]) for n in sizes]
    slope, intercept = _fit_line(sizes, walls)
    return {"function": "settled_step, 6 contacts, flexible, 1 kHz", "points": list(sizes), "wall_s": walls,
            "s_per_point": slope, "start_s": intercept, "workers": os.cpu_count()}


def _nothing(index: int) -> dict:
    return {"value": index}


def _batch(amplitudes: tuple) -> dict:
    """One task of a large sweep: a batch of settled steps (picklable)."""
    start = time.perf_counter()
    for a in amplitudes:
        _settled_point(a)
    return {"seconds": time.perf_counter() - start}


def dask_part(sizes=DASK_TASKS, batch: int = DASK_BATCH) -> dict | None:
    try:
        import distributed  # noqa: F401  (the executor's dependency)
    except ImportError:
        return None
    walls = [_timed_sweep(_nothing, [{"index": i} for i in range(n)], cached=False, executor="dask")
             for n in sizes]
    slope, intercept = _fit_line(sizes, walls)
    amplitudes = tuple(float(a) for a in np.linspace(90e-9, 200e-9, batch))
    wall = _timed_sweep(_batch, [{"amplitudes": amplitudes}], executor="dask", workers=1) if batch else None
    return {"tasks": list(sizes), "wall_s": walls, "s_per_task": slope, "start_s": intercept,
            "batch_points": batch, "batch_task_wall_s": wall}


def dask_plan(dask: dict, sweep_rows: dict, points: int = PLAN_POINTS, task_s: float = PLAN_TASK_S) -> dict:
    """A sweep of ``points`` points on a Dask cluster: points per task so that a task lasts at least
    ``task_s`` (at the measured cost per point of the settled step, one core per worker), the tasks,
    the scheduler's share of the work (measured cost per task over the task's length), and the
    core-hours."""
    per_point = sweep_rows["s_per_point"] * sweep_rows["workers"]  # one core's seconds per point
    batch = max(1, math.ceil(task_s / per_point))
    tasks = math.ceil(points / batch)
    return {"points": points, "s_per_point_one_core": per_point, "points_per_task": batch, "tasks": tasks,
            "scheduler_share": dask["s_per_task"] / (batch * per_point),
            "unbatched_scheduler_share": dask["s_per_task"] / per_point,
            "core_hours": points * per_point / 3600}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3, help="timed runs per configuration (median)")
    ap.add_argument("--smoke", action="store_true",
                    help="every part on its smallest input, to a temporary file: checks the script runs")
    ap.add_argument("--out", type=Path, default=None,
                    help="JSON written (default: passmd/data/benchmarks/scaling.json; --smoke: a temporary "
                         "file)")
    args = ap.parse_args(argv)
    counts, frequencies, sizes, tasks, batch = CONTACTS, FREQUENCIES, SWEEP_SIZES, DASK_TASKS, DASK_BATCH
    if args.smoke:
        args.repeats, counts, frequencies, sizes, tasks, batch = 1, (1,), (1e3, 30e3), (2, 4), (2, 3), 0
    if args.out is None:
        args.out = (Path(tempfile.mkdtemp(prefix="passmd-bench-")) / "scaling.json" if args.smoke
                    else ROOT / "passmd/data/benchmarks/scaling.json")
    record = {"meta": {"python": platform.python_version(), "machine": platform.machine(),
                       "cpus": os.cpu_count(), "repeats": args.repeats,
                       "date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime())}}
    for name, part in (("contacts", lambda: contacts_part(args.repeats, counts)),
                       ("frequency", lambda: frequency_part(args.repeats, frequencies)),
                       ("sweep", lambda: sweep_part(sizes)), ("dask", lambda: dask_part(tasks, batch))):
        before = os.getloadavg()
        value = part()
        record[name] = value
        record["meta"][f"load_average_{name}"] = [list(before), list(os.getloadavg())]
        print(f"{name}: {json.dumps(value)[:400]}")
    if record["dask"] is not None:
        record["dask_plan"] = dask_plan(record["dask"], record["sweep"])
        print(f"dask plan: {record['dask_plan']}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(record, indent=2) + "\n")
    print(f"written {args.out}")
    return 0


if __name__ == "__main__":
    from passmd.runtime.scripts import run_script

    raise SystemExit(run_script(main))  # one line on failure, never a traceback
