"""Cost of a design map of a drive that is not the paper's: steady velocity over frequency × amplitude.

The drive: R = 0.5 mm, F_p = 0.6 N, k_p = 5e6 N/m, m_a = 1.5e-5 kg (outside Table 2's range:
extrapolated), c_p from ζ, m_r = 5 g, μ = 0.25, six contacts, flexible actuators; the
full stroke is Table 2's for R = 0.5 mm. The map: steady velocity
(:func:`passmd.protocols.maps.steady_point`) on a log grid of frequencies × a linear grid of
amplitudes up to the full stroke, through :func:`passmd.protocols.maps.compute_map` (process
pool over all cores), as ``passmd sweep velocity`` runs it.

Measured, each once, as wall time (the load average, 1/5/15 min, before and after each: on a
shared machine it says how many cores the map actually had):

* ``cold`` / ``cached``: :func:`~passmd.protocols.maps.compute_map` in this process with an
  empty result cache (numba kernels compiled beforehand, in an untimed warm-up), then the same
  map again, every point from the cache;
* ``cli_cold`` / ``cli_cached``: the same map as a user runs it, ``passmd sweep velocity
  --vary frequency=100Hz..110kHz:log:24 --vary amplitude=40nm..131nm:24 ... --out PREFIX`` in a
  subprocess (start-up, imports, CSV, JSON and the heat map included) with an empty cache of
  its own, then again from that cache; with the CPU time of the command and its workers.
  The command runs with Python's bytecode cache (an untimed small map first fills it, in a
  temporary ``PYTHONPYCACHEPREFIX``), as from an installed wheel: without it (e.g.
  ``PYTHONDONTWRITEBYTECODE`` and no ``__pycache__``) every start compiles about a thousand
  modules of the dependencies again, seconds that are not the command's.

Usage::

    python benchmarks/bench_sweep_map.py [--frequencies 24] [--amplitudes 24]
        [--out passmd/data/benchmarks/sweep_map.json]
    python benchmarks/bench_sweep_map.py --smoke   # seconds, to a temporary file

``--smoke`` is a 2 × 2 map (``--frequencies 2 --amplitudes 2``) through every part, written to a
temporary file: it checks that the script works, its times mean nothing.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from passmd.model.parameters import Drive
from passmd.model.tables import actuator_for_radius, actuator_viscosity
from passmd.protocols.maps import compute_map, steady_point
from passmd.runtime.config import RunConfig

#: Targets of the map on the 2-core machine (s).
COLD_TARGET_S = 10.0
CACHED_TARGET_S = 5.0
ROOT = Path(__file__).resolve().parents[1]


def drive() -> Drive:
    """The benchmark's drive (module docstring)."""
    stiffness, mass = 5e6, 1.5e-5
    actuator = replace(actuator_for_radius(0.5e-3), stiffness=stiffness, mass=mass,
                       viscosity=actuator_viscosity(stiffness, mass))
    return Drive(contacts=6, actuator_model="flexible", hemisphere_radius=0.5e-3, preload=0.6,
                 actuator=actuator, runner_mass=5e-3, friction_coefficient=0.25, allow_extrapolation=True)


def points(n_frequencies: int, n_amplitudes: int) -> list[dict]:
    d = drive()
    frequencies = np.geomspace(100.0, 110e3, n_frequencies)
    amplitudes = np.linspace(40e-9, 131e-9, n_amplitudes)
    return [{"drive": d, "frequency": float(f), "amplitude": float(a), "frequency_Hz": float(f),
             "amplitude_m": float(a)} for f in frequencies for a in amplitudes]


def _timed(grid, config) -> dict:
    load_before = os.getloadavg()
    start = time.perf_counter()
    table = compute_map("velocity", grid, config=config)
    wall = time.perf_counter() - start
    counts = table.attrs["sweep"]
    return {"wall_s": wall, "load_average_before": list(load_before),
            "load_average_after": list(os.getloadavg()),
            "cached_points": counts["cached"], "computed_points": counts["computed"]}


#: The drive of :func:`drive` as command-line options.
DRIVE_OPTIONS = ("--radius", "0.5mm", "--preload", "0.6N", "--actuator-stiffness", "5e6N/m",
                 "--actuator-mass", "1.5e-5kg", "--runner-mass", "5g", "--mu", "0.25", "--contacts", "6",
                 "--actuator", "flexible", "--allow-extrapolation")


def _timed_cli(argv: list[str], env: dict) -> dict:
    load_before = os.getloadavg()
    cpu_before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(argv, capture_output=True, text=True, check=False, env=env)
    wall = time.perf_counter() - start
    cpu_after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise RuntimeError(f"passmd sweep failed: {done.stderr.strip()}")
    cpu = (cpu_after.ru_utime - cpu_before.ru_utime) + (cpu_after.ru_stime - cpu_before.ru_stime)
    return {"wall_s": wall, "cpu_s": cpu, "load_average_before": list(load_before),
            "load_average_after": list(os.getloadavg()),
            "output": " ".join(done.stdout.splitlines()[2].split())}


def cli(n_frequencies: int, n_amplitudes: int, workers: int | None) -> dict:
    """The map through the command line, cold and from the cache (module docstring)."""
    with tempfile.TemporaryDirectory(prefix="bench-map-cli-") as folder:
        drop = ("PYTHONDONTWRITEBYTECODE", "PASSMD_CACHE_DIR")
        env = {k: v for k, v in os.environ.items() if k not in drop}
        env.update(PYTHONPYCACHEPREFIX=os.path.join(folder, "pycache"), MPLBACKEND="Agg")

        def command(frequencies: str, amplitudes: str, cache: str, out: str) -> list[str]:
            argv = [sys.executable, "-m", "passmd", "sweep", "velocity", "--vary", f"frequency={frequencies}",
                    "--vary", f"amplitude={amplitudes}", *DRIVE_OPTIONS,
                    "--cache-dir", os.path.join(folder, cache), "--out", os.path.join(folder, out)]
            return argv + (["--workers", str(workers)] if workers is not None else [])

        _timed_cli(command("1kHz,2kHz", "100nm", "warm-up", "warm-up"), env)  # fills the bytecode cache
        grid = (f"100Hz..110kHz:log:{n_frequencies}", f"40nm..131nm:{n_amplitudes}", "cache")
        argv = command(*grid, "map")  # each run's outputs new: a sweep never replaces a file
        return {"command": " ".join(argv[3:]).replace(folder, "TMP"), "cold": _timed_cli(argv, env),
                "cached": _timed_cli(command(*grid, "map-cached"), env)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frequencies", type=int, default=24)
    parser.add_argument("--amplitudes", type=int, default=24)
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--smoke", action="store_true",
                        help="a 2 x 2 map, to a temporary file: checks the script runs, measures nothing")
    parser.add_argument("--out", type=Path, default=None,
                        help="JSON written (default: passmd/data/benchmarks/sweep_map.json; --smoke: a "
                             "temporary file)")
    args = parser.parse_args()
    if args.smoke:
        args.frequencies = args.amplitudes = 2
    if args.out is None:
        args.out = (Path(tempfile.mkdtemp(prefix="passmd-bench-")) / "sweep_map.json" if args.smoke
                    else ROOT / "passmd/data/benchmarks/sweep_map.json")
    grid = points(args.frequencies, args.amplitudes)
    d = grid[0]["drive"]
    steady_point(d, grid[0]["amplitude"], 1e3)  # warm-up: numba kernels compiled or loaded
    with tempfile.TemporaryDirectory(prefix="bench-map-cache-") as cache:
        config = RunConfig(cache_dir=cache, workers=args.workers, progress=False)
        cold = _timed(grid, config)
        cached = _timed(grid, config)
    result = {
        "machine": {"python": platform.python_version(), "processor": platform.processor(),
                    "cpus": os.cpu_count()},
        "map": {"quantity": "velocity", "frequencies": args.frequencies, "amplitudes": args.amplitudes,
                "points": len(grid), "frequency_range_Hz": [100.0, 110e3],
                "amplitude_range_m": [40e-9, 131e-9], "workers": args.workers},
        "cold": {**cold, "target_s": COLD_TARGET_S},
        "cached": {**cached, "target_s": CACHED_TARGET_S},
    }
    line = cli(args.frequencies, args.amplitudes, args.workers)
    result["cli_command"] = line["command"]
    result["cli_cold"] = {**line["cold"], "target_s": COLD_TARGET_S}
    result["cli_cached"] = {**line["cached"], "target_s": CACHED_TARGET_S}
    for name in ("cold", "cached", "cli_cold", "cli_cached"):
        row = result[name]
        counts = (f"{row['computed_points']} computed, {row['cached_points']} cached" if "cpu_s" not in row
                  else f"cpu {row['cpu_s']:.2f} s, {row['output']}")
        print(f"{name:10s} {row['wall_s']:8.2f} s (target {row['target_s']:g} s), {counts}, "
              f"load {row['load_average_before'][0]:.2f} -> {row['load_average_after'][0]:.2f}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(result, indent=2) + "\n")
    print(f"written {args.out}")


if __name__ == "__main__":
    from passmd.runtime.scripts import run_script

    sys.exit(run_script(main))  # one line on failure, never a traceback
