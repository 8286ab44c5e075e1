"""Coverage of the fit's 95 % intervals over repeated noisy draws of synthetic measurements.

A cheap model keeps many fits affordable: one contact with rigid actuators (Table 1–2 at
R = 1 mm), steps of a 100 Hz saw-tooth at two preloads (0.2, 0.4 N) and four amplitudes
(60–180 nm), simulated at μ = 0.25 (and, with ``--free friction_coefficient,runner_mass``, a
runner of 6 g) plus Gaussian noise of 0.5 nm, a new seed for every draw. Each draw is fitted
from the drive's defaults with the noise's standard deviation given (σ known: χ²₁ profile
threshold); the share of draws whose profile interval, and whose Wald interval (estimate ±
1.96 standard errors, in log space as the fit works), holds the truth is the coverage, with
its binomial standard error. Nominal: 0.95.

Usage::

    python benchmarks/bench_fit_coverage.py [--draws 40] [--free friction_coefficient]
        [--out passmd/data/benchmarks/fit_coverage.json]
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import json
import math
import os
import sys
import tempfile
import time
from dataclasses import replace

import numpy as np

from passmd.model.parameters import Drive
from passmd.protocols import fit as F

BASE = Drive(contacts=1, actuator_model="rigid")
TRUTH = {"friction_coefficient": 0.25, "runner_mass": 6e-3, "contact_stiffness_scale": 1.5}
PRELOADS = (0.2, 0.4)
AMPLITUDES_NM = (60.0, 100.0, 140.0, 180.0)
NOISE_NM = 0.5


def _truth(free) -> Drive:
    drive = BASE
    for name in free:
        drive = F.FREE_PARAMETERS[name].set(drive, TRUTH[name], BASE)
    return drive


def _draw(seed: int, free: tuple[str, ...], cache: str) -> dict:
    header = ["amplitude_nm", "preload_N", "frequency_Hz", "step_nm", "step_nm_sd"]
    rows = [[repr(a), repr(p), "100", "0", repr(NOISE_NM)] for p in PRELOADS for a in AMPLITUDES_NM]
    data = F.measurements_from_rows(header, rows)
    exact = F.predict(_truth(free), data, executor="serial", cache=cache)
    noise = np.random.default_rng(seed).normal(0.0, NOISE_NM * 1e-9, exact.size)
    result = F.fit(BASE, replace(data, value=exact + noise), list(free), executor="serial", cache=cache,
                   starts=0)
    out = {"seed": seed}
    for name in free:
        est = result.estimates[name]
        low, high = est["interval"]
        half = 1.959964 * est["stderr"] / est["value"]  # standard error of log(value)
        out[name] = {"value": est["value"], "interval": [low, high],
                     "profile_holds": bool(low <= TRUTH[name] <= high),
                     "wald_holds": bool(abs(math.log(TRUTH[name] / est["value"])) <= half)}
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--draws", type=int, default=40)
    parser.add_argument("--free", default="friction_coefficient")
    parser.add_argument("--workers", type=int, default=os.cpu_count())
    parser.add_argument("--out", default="passmd/data/benchmarks/fit_coverage.json")
    args = parser.parse_args()
    free = tuple(args.free.split(","))
    start = time.perf_counter()
    load_before = os.getloadavg()
    draws = []
    with tempfile.TemporaryDirectory() as cache, cf.ProcessPoolExecutor(args.workers) as pool:
        futures = [pool.submit(_draw, seed, free, cache) for seed in range(args.draws)]
        for k, future in enumerate(cf.as_completed(futures)):
            draws.append(future.result())
            print(f"draw {k + 1}/{args.draws} [{time.perf_counter() - start:.0f} s]", file=sys.stderr,
                  flush=True)
    draws.sort(key=lambda d: d["seed"])
    coverage = {}
    n = len(draws)
    for name in free:
        for kind in ("profile", "wald"):
            share = sum(d[name][f"{kind}_holds"] for d in draws) / n
            coverage[f"{name}.{kind}"] = {"coverage": share,
                                          "binomial_stderr": math.sqrt(share * (1 - share) / n)}
    record = {"benchmark": "coverage of the fit's 95 % intervals", "model": "one contact, rigid actuators",
              "free": list(free), "truth": {k: TRUTH[k] for k in free}, "draws": n, "noise_nm": NOISE_NM,
              "preloads_N": PRELOADS, "amplitudes_nm": AMPLITUDES_NM, "nominal": 0.95, "coverage": coverage,
              "wall_time_s": time.perf_counter() - start, "load_average_before": list(load_before),
              "load_average_after": list(os.getloadavg()), "per_draw": draws}
    os.makedirs(os.path.dirname(args.out) or ".", exist_ok=True)
    with open(args.out, "w", encoding="utf-8") as handle:
        handle.write(json.dumps(record, indent=2) + "\n")
    print(json.dumps(coverage, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
