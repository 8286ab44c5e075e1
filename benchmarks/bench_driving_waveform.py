"""Cost of Section 5's chapters (driving waveform, velocity, beyond the paper): their building
blocks (medians of repeated runs) and one cold computation of every Fig. 8–10 panel and study at a profile.

Timed blocks (each repeated, median and fastest reported; numba compiles in an untimed warm-up):

* ``design``: :func:`passmd.protocols.eq15.optimized_design` of the Section 5 drive (two 100 Hz
  saw-tooth periods recorded densely, f_s and V_r measured, Eq. 15);
* ``steady_sawtooth_<f>`` / ``steady_optimized_<f>``: one steady-velocity point
  (:func:`passmd.protocols.section5.velocity_point`) at 1 kHz and 110 kHz;
* ``step_100hz``: one Fig. 9a protocol run (three 100 Hz periods, rigid actuators).

Then, once, with an empty temporary simulation cache: every panel (``figure_data``) and the
studies beyond the paper (:mod:`passmd.experiments.waveform_optimum.figures`) at ``--profile``,
as wall time of this process plus its sweep workers.

Usage::

    python benchmarks/bench_driving_waveform.py [--repeats 5] [--profile paper]
        [--out passmd/data/benchmarks/driving_waveform.json]
    python benchmarks/bench_driving_waveform.py --smoke   # seconds, to a temporary file

``--smoke`` is ``--repeats 1 --profile quick`` written to a temporary file: every block and
every panel and study, on the quick grids; it checks that the script works, its times mean
nothing.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

from passmd.experiments.figure_table import figure_data
from passmd.experiments.waveform_optimum.figures import flexible_study, numerical_optimum, settling_scan
from passmd.experiments.waveform_velocity.figures import startup_transient
from passmd.model.defaults import PROTOCOL
from passmd.runtime.config import RunConfig

PANELS = ("fig8a", "fig8b", "fig9a", "fig9b", "fig10a", "fig10b", "fig10c")
ROOT = Path(__file__).resolve().parents[1]


def _timed(func, repeats: int) -> dict:
    func()  # warm-up: numba compilation and caches
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        func()
        times.append(time.perf_counter() - start)
    return {"median_s": statistics.median(times), "fastest_s": min(times), "repeats": repeats}


def blocks(repeats: int) -> dict:
    from passmd.experiments.driving_waveform.figures import section5_fields
    from passmd.model import optimized_waveform
    from passmd.protocols import eq15
    from passmd.protocols.section5 import section5_drive, velocity_point
    from passmd.solver import simulation

    drive = section5_drive(**section5_fields())
    amplitude = drive.actuator.full_stroke_amplitude
    design = eq15.optimized_design(amplitude, drive)
    fields = {"settling_time": design.settling_time, "acceleration_time": design.acceleration_time,
              "acceleration_amplitude": design.acceleration_amplitude}
    out = {"design": _timed(lambda: eq15.optimized_design(amplitude, drive), repeats)}
    for f in (1e3, 110e3):
        for waveform, rule in (("sawtooth", ""), ("optimized", "cut")):
            out[f"steady_{waveform}_{f / 1e3:g}kHz"] = _timed(
                lambda f=f, w=waveform, r=rule: velocity_point(
                    **section5_fields(), frequency=f, waveform=w, short_period=r, **fields),
                repeats)
    wave = optimized_waveform.optimized(amplitude, PROTOCOL.drive_frequency, drive, periods=3, design=design)
    out["step_100hz"] = _timed(lambda: simulation.simulate(drive, wave, max_points=2), repeats)
    return out


def cold_profile(profile: str) -> dict:
    """Every panel and study at ``profile`` with an empty simulation cache (one run each)."""
    with tempfile.TemporaryDirectory(prefix="bench-dw-cache-") as cache:
        config = RunConfig(profile=profile, cache_dir=cache)
        out = {}
        for name in PANELS:
            start = time.perf_counter()
            figure_data(name, config)
            out[name] = time.perf_counter() - start
        for name, call in (("settling_scan", lambda: settling_scan(config)),
                           ("numerical_optimum", lambda: numerical_optimum(config)),
                           ("flexible_study", lambda: flexible_study(config)),
                           ("startup_transient", lambda: startup_transient(config, 110e3))):
            start = time.perf_counter()
            call()
            out[name] = time.perf_counter() - start
        out["total"] = sum(out.values())
        return {"profile": profile, "wall_s": out}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--profile", choices=("quick", "paper"), default="paper")
    parser.add_argument("--smoke", action="store_true",
                        help="--repeats 1 --profile quick, to a temporary file: checks the script runs, "
                             "measures nothing")
    parser.add_argument("--out", type=Path, default=None,
                        help="JSON written (default: passmd/data/benchmarks/driving_waveform.json; --smoke: "
                             "a temporary file)")
    args = parser.parse_args()
    if args.smoke:
        args.repeats, args.profile = 1, "quick"
    if args.out is None:
        args.out = (Path(tempfile.mkdtemp(prefix="passmd-bench-")) / "driving_waveform.json" if args.smoke
                    else ROOT / "passmd/data/benchmarks/driving_waveform.json")
    result = {
        "machine": {"python": platform.python_version(), "processor": platform.processor(),
                    "cpus": os.cpu_count()},
        "blocks": blocks(args.repeats),
        "cold": cold_profile(args.profile),
    }
    for name, row in result["blocks"].items():
        print(f"{name:28s} median {row['median_s'] * 1e3:9.2f} ms   fastest {row['fastest_s'] * 1e3:9.2f} ms")
    for name, wall in result["cold"]["wall_s"].items():
        print(f"cold {args.profile:5s} {name:20s} {wall:8.2f} s")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(result, indent=2) + "\n")
    print(f"written {args.out}")


if __name__ == "__main__":
    from passmd.runtime.scripts import run_script

    sys.exit(run_script(main))  # one line on failure, never a traceback
