"""Cost of a design map of a drive that is not the paper's: steady velocity over frequency × amplitude.

The drive: R = 0.5 mm, F_p = 0.6 N, k_p = 5e6 N/m, m_a = 1.5e-5 kg (outside Table 2's range:
extrapolated), c_p from ζ, m_r = 5 g, μ = 0.25, six contacts, flexible actuators; the
full stroke is Table 2's for R = 0.5 mm. The map: steady velocity
(:func:`passmd.protocols.maps.steady_point`) on a log grid of frequencies × a linear grid of
amplitudes up to the full stroke, through :func:`passmd.experiments.maps.compute_map` (process
pool over all cores), as ``passmd sweep velocity`` runs it.

Measured, each once, as wall time of this process and its workers:

* ``cold_s``: an empty result cache (numba kernels compiled beforehand, in an untimed warm-up);
* ``cached_s``: the same map again, every point from the cache.

The load average (1, 5, 15 min) before and after each measurement is recorded with it: on a
shared machine it says how many cores the map actually had.

Usage::

    python benchmarks/bench_sweep_map.py [--frequencies 24] [--amplitudes 24]
        [--out passmd/data/benchmarks/sweep_map.json]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from passmd.config import RunConfig
from passmd.experiments.maps import compute_map
from passmd.parameters import Drive, actuator_for_radius, actuator_viscosity
from passmd.protocols.maps import steady_point

#: Targets of the map on the 2-core machine (s).
COLD_TARGET_S = 60.0
CACHED_TARGET_S = 5.0


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
    amplitudes = np.linspace(40e-9, d.actuator.full_stroke_amplitude, n_amplitudes)
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frequencies", type=int, default=24)
    parser.add_argument("--amplitudes", type=int, default=24)
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--out", type=Path, default=Path("passmd/data/benchmarks/sweep_map.json"))
    args = parser.parse_args()
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
                "amplitude_range_m": [40e-9, d.actuator.full_stroke_amplitude], "workers": args.workers},
        "cold": {**cold, "target_s": COLD_TARGET_S},
        "cached": {**cached, "target_s": CACHED_TARGET_S},
    }
    for name in ("cold", "cached"):
        row = result[name]
        print(f"{name:6s} {row['wall_s']:8.2f} s (target {row['target_s']:g} s), "
              f"{row['computed_points']} computed, {row['cached_points']} cached, "
              f"load {row['load_average_before'][0]:.2f} -> {row['load_average_after'][0]:.2f}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(result, indent=2) + "\n")


if __name__ == "__main__":
    main()
