"""Speed of the hybrid simulator: ns per integrator step and wall time per 100 Hz period.

Runs each configuration (one/six contacts × rigid/flexible × exact/discrete N = 200;
flexible both with the default adaptive step and with the fixed fine step) over one
100 Hz saw-tooth period (150 nm, 0.4 N, R = 1 mm) at the default, converged step,
repeats, and reports medians. numba compilation happens in an untimed warm-up run.

Usage::

    python benchmarks/bench_dynamics.py [--repeats 5] [--out passmd/data/benchmarks/dynamics.json]
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
from pathlib import Path

from passmd import dynamics, waveforms
from passmd.parameters import Drive

CONFIGS = [
    (contacts, model, contact, adaptive)
    for contacts in (1, 6)
    for model in ("rigid", "flexible")
    for contact in ("exact", "discrete")
    for adaptive in ((True, False) if model == "flexible" else (True,))
]


def bench(contacts: int, model: str, contact: str, adaptive: bool, repeats: int, springs: int = 200) -> dict:
    drive = Drive(contacts=contacts, actuator_model=model)
    kw = dict(contact_model=contact, springs=springs, adaptive=adaptive)
    warm = waveforms.sawtooth(150e-9, 10e3, drive, periods=1)
    dynamics.simulate(drive, warm, **kw)  # compile
    wf = waveforms.sawtooth(150e-9, 100.0, drive, periods=1)
    walls, steps = [], 0
    for _ in range(repeats):
        res = dynamics.simulate(drive, wf, max_points=2000, **kw)
        walls.append(res.wall_time)
        steps = res.steps
    wall = statistics.median(walls)
    return {
        "contacts": contacts,
        "actuator": model,
        "step": ("adaptive" if adaptive else "fixed") if model == "flexible" else "fixed",
        "contact_model": contact if contact == "exact" else f"discrete N={springs}",
        "steps_per_period": steps,
        "fine_step_ns": res.fine_step * 1e9,
        "coarse_step_ns": res.coarse_step * 1e9,
        "ns_per_step": wall / steps * 1e9,
        "ms_per_100Hz_period": wall * 1e3,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5, help="timed repeats per configuration (median)")
    ap.add_argument("--out", type=Path,
                    default=Path(__file__).resolve().parents[1] / "passmd/data/benchmarks/dynamics.json")
    args = ap.parse_args(argv)
    rows = [bench(c, m, k, a, args.repeats) for c, m, k, a in CONFIGS]
    header = (
        f"{'contacts':>8} {'actuator':>9} {'step':>9} {'contact':>16} {'steps':>9} "
        f"{'fine/ns':>7} {'coarse/ns':>9} {'ns/step':>8} {'ms/period':>10}"
    )
    print(header)
    for r in rows:
        print(
            f"{r['contacts']:>8} {r['actuator']:>9} {r['step']:>9} {r['contact_model']:>16} "
            f"{r['steps_per_period']:>9}"
            f"{r['fine_step_ns']:>7.2f} {r['coarse_step_ns']:>9.2f} {r['ns_per_step']:>8.1f} "
            f"{r['ms_per_100Hz_period']:>10.2f}"
        )
    args.out.parent.mkdir(parents=True, exist_ok=True)
    meta = {
        "machine": platform.processor() or platform.machine(),
        "python": platform.python_version(),
        "repeats": args.repeats,
    }
    args.out.write_text(json.dumps({"meta": meta, "rows": rows}, indent=2))
    print(f"written {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
