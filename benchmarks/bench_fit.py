"""Cost of a calibration: three free parameters fitted to 30 measurements of a six-contact drive.

The measurements are steps of the Table 1–2 drive (R = 1 mm, six contacts, flexible actuators)
at three preloads (0.2, 0.4, 0.6 N) and ten saw-tooth amplitudes (110–200 nm, 100 Hz), simulated
at μ = 0.25, k_p = 5e6 N/m, ζ = 0.1 with 0.5 nm Gaussian noise (seed 0). The fit frees μ, k_p and
ζ from the drive's defaults (μ = 0.2, k_p = 6.5e6 N/m, ζ = 0.05) with the default bounds, on a
process pool over all cores and an empty result cache (a fresh temporary directory): its wall
time covers the global pass, the local searches, the scan of a parameter whose residuals
oscillate (k_p here) and the three profiles, i.e. everything ``passmd fit`` computes. The record
says whether the fit converged (no profile met a lower cost) and whether its intervals hold the
truth; the cost at the truth shows a fit stopped in a local minimum. Progress lines go to
stderr. The machine's load average before and after is recorded with the time (the 2-core
machine may be shared).

Usage::

    python benchmarks/bench_fit.py [--out passmd/data/benchmarks/fit.json]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from passmd.model.parameters import Drive
from passmd.protocols import fit as F
from passmd.runtime.config import RunConfig

TRUTH = {"friction_coefficient": 0.25, "actuator.stiffness": 5e6, "actuator.damping_ratio": 0.1}
PRELOADS = (0.2, 0.4, 0.6)
AMPLITUDES_NM = tuple(np.linspace(110.0, 200.0, 10))
NOISE_NM = 0.5


def measurements(base: Drive, cache) -> tuple[F.Measurements, Drive]:
    truth = base
    for name in ("friction_coefficient", "actuator.stiffness", "actuator.damping_ratio"):
        truth = F.FREE_PARAMETERS[name].set(truth, TRUTH[name], base)
    header = ["amplitude_nm", "preload_N", "frequency_Hz", "step_nm", "step_nm_sd"]
    rows = [[repr(float(a)), repr(p), "100", "0", repr(NOISE_NM)] for p in PRELOADS for a in AMPLITUDES_NM]
    data = F.measurements_from_rows(header, rows)
    exact = F.predict(truth, data, cache=cache)
    noise = np.random.default_rng(0).normal(0.0, NOISE_NM * 1e-9, exact.size)
    return replace(data, value=exact + noise), truth


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="passmd/data/benchmarks/fit.json")
    args = parser.parse_args()
    base = Drive()
    with tempfile.TemporaryDirectory() as data_cache, tempfile.TemporaryDirectory() as fit_cache:
        data, truth = measurements(base, data_cache)
        load_before = os.getloadavg()
        start = time.perf_counter()
        cpu = time.process_time()
        result = F.fit(base, data, list(TRUTH), config=RunConfig(cache_dir=Path(fit_cache)),
                       progress=lambda line: print(f"fit: {line} [{time.perf_counter() - start:.0f} s]",
                                                   file=sys.stderr, flush=True))
        wall = time.perf_counter() - start
        load_after = os.getloadavg()
        # the cost at the truth (its predictions are in the data's cache): a fit that ends above it
        # stopped in a local minimum
        truth_cost = float(np.sum(((data.value - F.predict(truth, data, cache=data_cache)) / data.sd) ** 2))
    record = {
        "benchmark": "fit: 3 free parameters, 30 step measurements, six contacts, flexible actuators",
        "wall_time_s": wall,
        "parent_cpu_time_s": time.process_time() - cpu,
        "target_s": 180.0,
        "simulations": result.simulations,
        "model_evaluations": result.evaluations,
        "truth": TRUTH,
        "estimates": result.estimates,
        "intervals_hold_truth": {n: bool(result.estimates[n]["interval"][0] <= TRUTH[n]
                                         <= result.estimates[n]["interval"][1]) for n in TRUTH},
        "cost_at_estimate": result.cost,
        "cost_at_truth": truth_cost,
        "jacobian_step": F.JACOBIAN_STEP,
        "scan": {"spacing": F.SCAN_SPACING, "half_width": F.SCAN_HALF_WIDTH, "rounds": F.SCAN_ROUNDS},
        "converged": result.converged,
        "identifiable": result.identifiable,
        "verdict": result.verdict,
        "correlation": result.correlation.tolist(),
        "cpus": os.cpu_count(),
        "load_average_before": list(load_before),
        "load_average_after": list(load_after),
        "python": platform.python_version(),
        "machine": platform.machine(),
    }
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(record, indent=2) + "\n")
    print(json.dumps({k: record[k] for k in ("wall_time_s", "simulations", "intervals_hold_truth",
                                              "cost_at_estimate", "cost_at_truth", "converged",
                                              "load_average_before", "load_average_after")}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
