"""Cost per call of the MDR contact kernels: exact (reversal stack) and discrete (N springs).

A realistic path for the integrator: u(t) sampled at a fixed step, a large oscillation that
drives the contact into full sliding and back (amplitude 1.2 u_max) with a superimposed,
decaying micro-vibration (a thousand reversals), as the runner makes after each slip; and
for the exact model also a ring-down whose 600 reversals all nest (the deepest stack).
Each timed run is a numba loop calling the kernel once per sample; the table reports the
median (and the fastest) of repeated runs in ns per call. numba compilation happens in an
untimed warm-up.

Usage::

    python benchmarks/bench_contact.py [--repeats 7] [--out passmd/data/benchmarks/contact.json]
    python benchmarks/bench_contact.py --smoke   # seconds, to a temporary file

``--smoke`` runs every case once on paths of :data:`SMOKE_POINTS` samples and the smallest
discrete model, written to a temporary file: it checks that the script works, its times mean
nothing.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np
from numba import njit

from passmd.model.contact import (
    contact_arrays,
    contact_force,
    contact_reset,
    contact_update,
    contact_update_row,
    stack_contacts,
)
from passmd.model.mdr_contact import MDRContact
from passmd.model.parameters import Drive
from passmd.model.theory import contact_moduli, normal_forces
from passmd.runtime.outputs import write_file

SPRINGS = (100, 200, 1000, 10000)
PATH_POINTS = 1_000_000  # samples of the exact model's path
SPRING_UPDATES = 200_000_000  # N × calls per discrete run (≈ 0.1–0.3 s each)
SMOKE_POINTS = 20_000  # samples of each path with --smoke
ROOT = Path(__file__).resolve().parents[1]


@njit(cache=True)
def _run_update(params, state, us):
    total = 0.0
    for i in range(us.size):
        total += contact_update(params, state, us[i])
    return total


@njit(cache=True)
def _run_update_row(P, S, us):
    total = 0.0
    for i in range(us.size):
        total += contact_update_row(P, S, 0, us[i])
    return total


@njit(cache=True)
def _run_force(params, state, us):
    total = 0.0
    for i in range(us.size):
        total += contact_force(params, state, us[i])
    return total


def oscillating_path(u_max: float, points: int = PATH_POINTS) -> np.ndarray:
    """Full-sliding oscillation (20 cycles) plus a decaying micro-vibration restarted each half-cycle."""
    t = np.linspace(0.0, 20.0, points, endpoint=False)  # in units of the big cycle
    phase = (2.0 * t) % 1.0  # time since the last half-cycle began
    micro = 0.25 * np.exp(-4.0 * phase) * np.sin(2 * np.pi * 37.0 * t)
    return u_max * (1.2 * np.sin(2 * np.pi * t) + micro)


def ring_down_path(u_max: float, points: int = PATH_POINTS) -> np.ndarray:
    """A runner ringing down on its contacts: every reversal nests inside the previous one."""
    t = np.linspace(0.0, 1.0, points, endpoint=False)
    return u_max * 0.9 * np.exp(-5.0 * t) * np.cos(2 * np.pi * 300.0 * t)


def _time(run, args, state, repeats):
    times = []
    for _ in range(repeats):
        state[:] = 0.0
        t0 = time.perf_counter()
        run(*args)
        times.append(time.perf_counter() - t0)
    return times


def bench(repeats: int, points: int = PATH_POINTS, springs=SPRINGS,
          spring_updates: int = SPRING_UPDATES) -> list[dict]:
    drive = Drive()
    E_star, G_star = contact_moduli(drive)
    F_N = float(normal_forces(drive.preload, drive.contacts)[0])
    args = (F_N, drive.hemisphere_radius, E_star, G_star, drive.friction_coefficient)
    u_max = MDRContact(*args).presliding
    path = oscillating_path(u_max, points)
    rows = []

    ring = ring_down_path(u_max, points)
    params, state = contact_arrays("exact", *args, capacity=1024)
    P, S = stack_contacts([(params, state)])
    cases = [
        ("oscillation", "contact_update", _run_update, (params, state), state, path),
        ("oscillation", "contact_force", _run_force, (params, state), state, path),
        ("oscillation", "contact_update_row", _run_update_row, (P, S), S, path),
        ("ring-down", "contact_update", _run_update, (params, state), state, ring),
    ]
    for name, kernel, run, run_args, st, us in cases:
        run(*run_args, us[:10])  # compile
        contact_reset(params, state)
        probe = MDRContact(*args, capacity=1024)
        probe.path(us)
        times = _time(run, (*run_args, us), st, repeats)
        rows.append(_row("exact", None, kernel, us.size, times, path=name, reversals=probe.reversal_count,
                         max_depth=probe.max_depth, overflows=probe.overflow_count))

    for n in springs:
        params, state = contact_arrays("discrete", *args, springs=n)
        calls = min(path.size, spring_updates // n)
        stride = max(1, path.size // calls)
        us = np.ascontiguousarray(path[::stride][:calls])
        _run_update(params, state, us[:10])
        times = _time(_run_update, (params, state, us), state, repeats)
        rows.append(_row("discrete", n, "contact_update", us.size, times, path="oscillation"))
    return rows


def _row(model, springs, kernel, calls, times, **extra) -> dict:
    return {
        "model": model,
        "springs": springs,
        "kernel": kernel,
        "calls": int(calls),
        "ns_per_call_median": statistics.median(times) / calls * 1e9,
        "ns_per_call_min": min(times) / calls * 1e9,
        **extra,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7, help="timed repeats per case (median reported)")
    ap.add_argument("--smoke", action="store_true",
                    help="every case once on short paths, to a temporary file: checks the script runs, "
                         "measures nothing")
    ap.add_argument("--out", type=Path, default=None,
                    help="JSON written (default: passmd/data/benchmarks/contact.json; --smoke: a "
                         "temporary file)")
    args = ap.parse_args(argv)
    if args.smoke:
        args.repeats = 1
        rows = bench(1, SMOKE_POINTS, SPRINGS[:1], SMOKE_POINTS * SPRINGS[0])
    else:
        rows = bench(args.repeats)
    if args.out is None:
        args.out = (Path(tempfile.mkdtemp(prefix="passmd-bench-")) / "contact.json" if args.smoke
                    else ROOT / "passmd/data/benchmarks/contact.json")
    print(f"{'model':>9} {'N':>6} {'kernel':>19} {'path':>12} {'calls':>9} {'ns/call median':>15} "
          f"{'ns/call min':>12} {'reversals':>10} {'max depth':>10}")
    for r in rows:
        n = "∞" if r["springs"] is None else r["springs"]
        print(f"{r['model']:>9} {n:>6} {r['kernel']:>19} {r['path']:>12} {r['calls']:>9} "
              f"{r['ns_per_call_median']:>15.1f} {r['ns_per_call_min']:>12.1f} "
              f"{r.get('reversals', ''):>10} {r.get('max_depth', ''):>10}")
    meta = {
        "machine": platform.processor() or platform.machine(),
        "python": platform.python_version(),
        "numba": numba.__version__,
        "repeats": args.repeats,
        "paths": {
            "oscillation": "1.2 u_max full-sliding oscillation + decaying micro-vibration (oscillating_path)",
            "ring-down": "0.9 u_max decaying oscillation, nested reversals (ring_down_path)",
        },
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps({"meta": meta, "rows": rows}, indent=2)
    write_file(args.out, lambda tmp: Path(tmp).write_text(text), overwrite=True)  # atomic
    print(f"written {args.out}")
    return 0


if __name__ == "__main__":
    from passmd.runtime.scripts import run_script

    sys.exit(run_script(main))  # one line on failure, never a traceback
