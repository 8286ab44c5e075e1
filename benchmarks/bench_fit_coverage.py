"""Coverage of the fit's 95 % regions where it is hard: μ and k_p of six flexible contacts from steady steps.

Each draw simulates the steady steps of the Table 1–2 drive (R = 1 mm, six contacts, flexible
actuators, ζ = 0.05) at 100 Hz, three preloads (0.2, 0.4, 0.6 N) and five amplitudes (110–190 nm),
with μ = 0.25 and an actuator stiffness spread over 3e6–1e7 N/m (log-evenly, one value per
draw), by other means than the fit's own forward model: the integrator refined twofold
(``scheme`` "controlled" with ``refine=2``) and the last step of a 16-period run from rest
(:func:`passmd.protocols.synthetic.independent_steps`). Gaussian noise of 0.5 nm (a new
seed per draw) is added and its sd stated. Each draw is fitted from the drive's defaults (μ = 0.2,
k_p = 6.5e6 N/m) with the default bounds, on a process pool over all cores and an empty result
cache. Counted: how often each parameter's reported 95 % region (all its pieces) holds the truth,
how often both do, how often the truth lies in the joint 95 % region (its cost within the level
of the minimum, ``truth_rise`` per draw), how often the verdict is identifiable / not uniquely
identified (several basins) / not identifiable / model rejected (χ² test, p < 0.01), and how often
a draw is called identifiable while a region misses the truth (which must never happen); the
median wall time.
Nominal coverage of a region: 0.95.

Usage::

    python benchmarks/bench_fit_coverage.py [--quick | --smoke] [--draws 40]
        [--out passmd/data/benchmarks/fit_coverage.json]

``--quick`` fits 4 draws (a small run) and writes to a temporary file unless ``--out`` is
given; the machine's load average is recorded beside the times (the 2-core machine may be
shared). ``--smoke`` fits one draw of a cut-down problem (μ alone of one rigid contact from
three steps, :data:`SETTINGS`) through the same steps (data, fit, the truth's rise, summary,
record) in seconds, to a temporary file: it checks that the script works, its coverage means
nothing. The draws run in a stratified order (the ends of the k_p range first, then the middles
of the gaps), and the JSON is rewritten after each: a run stopped early leaves a record of the
draws done (``draws_done`` of ``draws``) that still spreads over the whole range.
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

from passmd.model.parameters import Drive
from passmd.protocols import fit
from passmd.protocols.fit.prediction import drive_at
from passmd.protocols.synthetic import independent_steps
from passmd.runtime.config import RunConfig
from passmd.runtime.outputs import write_file

FREE = ("friction_coefficient", "actuator.stiffness")
MU = 0.25
STIFFNESS_RANGE = (3e6, 1e7)
PRELOADS = (0.2, 0.4, 0.6)
AMPLITUDES_NM = (110.0, 130.0, 150.0, 170.0, 190.0)
FREQUENCY = 100.0
NOISE_NM = 0.5
ROOT = Path(__file__).resolve().parents[1]
#: What each draw fits: the problem of the module docstring, and a cut-down one for ``--smoke``.
SETTINGS = {
    "full": {"drive": Drive(), "free": FREE, "preloads": PRELOADS, "amplitudes_nm": AMPLITUDES_NM,
             "model": "six contacts, flexible actuators, R = 1 mm, ζ = 0.05 (Tables 1-2)",
             "label": "μ and k_p of six flexible contacts, steady steps"},
    "smoke": {"drive": Drive(contacts=1, actuator_model="rigid"), "free": FREE[:1], "preloads": (0.4,),
              "amplitudes_nm": (120.0, 160.0, 200.0), "model": "one contact, rigid actuators, R = 1 mm",
              "label": "μ alone of one rigid contact, steady steps"},
}


def truths(draws: int) -> list[float]:
    """The actuator stiffness of each draw: log-evenly spread over STIFFNESS_RANGE (cell midpoints)."""
    low, high = STIFFNESS_RANGE
    return [float(low * (high / low) ** ((k + 0.5) / draws)) for k in range(draws)]


def stratified(count: int) -> list[int]:
    """0 … count-1 in an order whose every prefix spreads over the range: 0, count-1, then the
    middles of the largest gaps left."""
    order, seen = [], set()
    queue = [(0, count - 1)]
    for k in (0, count - 1):
        if k not in seen:
            order.append(k)
            seen.add(k)
    while queue:
        queue.sort(key=lambda gap: gap[0] - gap[1])  # widest gap first
        low, high = queue.pop(0)
        if high - low < 2:
            continue
        mid = (low + high) // 2
        order.append(mid)
        seen.add(mid)
        queue += [(low, mid), (mid, high)]
    return order


def draw(seed: int, stiffness: float, setting: dict = SETTINGS["full"]) -> dict:
    base, free = setting["drive"], list(setting["free"])
    truth_values = {n: {"friction_coefficient": MU, "actuator.stiffness": stiffness}[n] for n in free}
    # the drive the fit describes: k_p moved with the damping ratio held (ζ = 0.05, c_p follows)
    truth = drive_at(base, free, list(truth_values.values()), base.actuator.damping_ratio)
    conditions = [(p, a * 1e-9, FREQUENCY) for p in setting["preloads"] for a in setting["amplitudes_nm"]]
    steps = independent_steps(truth, conditions)
    values = steps + np.random.default_rng(seed).normal(0.0, NOISE_NM * 1e-9, steps.size)
    header = ["amplitude_nm", "preload_N", "frequency_Hz", "step_nm", "step_nm_sd"]
    rows = [[repr(float(a * 1e9)), repr(p), repr(f), repr(float(v * 1e9)), repr(NOISE_NM)]
            for (p, a, f), v in zip(conditions, values, strict=True)]
    data = fit.measurements_from_rows(header, rows, name=f"draw {seed}")
    with tempfile.TemporaryDirectory() as cache:
        start = time.perf_counter()
        config = RunConfig(cache_dir=Path(cache))
        result = fit.fit(base, data, free, config=config)
        wall = time.perf_counter() - start
        # the joint rise of the cost at the truth (the fit's forward model): inside the joint 95 %
        # region when at most the level; every parameter's region then holds its truth too
        at_truth = float(np.sum(((fit.predict(truth, data, config=config) - data.value) / data.sd) ** 2))
    holds = {n: any(a <= truth_values[n] <= b for a, b in result.estimates[n]["intervals"]) for n in free}
    pieces = {n: len(result.estimates[n]["intervals"]) for n in free}
    flat = any(result.estimates[n]["flat_profile"] for n in free)
    if result.model_rejected:
        verdict = "model rejected"
    elif result.identifiable:
        verdict = "identifiable"
    elif flat:
        verdict = "not identifiable"
    elif any(v > 1 for v in pieces.values()):
        verdict = "not uniquely identified"
    else:
        verdict = "other"
    return {"seed": seed, "truth": truth_values, "holds": holds, "pieces": pieces, "verdict": verdict,
            "estimates": {n: result.estimates[n]["value"] for n in free},
            "intervals": {n: result.estimates[n]["intervals"] for n in free},
            "p_value": result.goodness_of_fit["p_value"], "cost": result.cost, "cost_at_truth": at_truth,
            "truth_rise": at_truth - result.cost, "level": result.level, "wall_time_s": wall,
            "evaluations": result.evaluations, "simulations": result.simulations}


def summary(draws: list[dict]) -> dict:
    n = len(draws)

    def share(count: int) -> dict:
        p = count / n
        return {"count": count, "share": p, "binomial_stderr": math.sqrt(p * (1 - p) / n)}

    verdicts = ("identifiable", "not uniquely identified", "not identifiable", "model rejected", "other")
    return {
        "coverage": {name: share(sum(d["holds"][name] for d in draws)) for name in draws[0]["holds"]},
        "coverage_both": share(sum(all(d["holds"].values()) for d in draws)),
        "coverage_joint": share(sum(d["truth_rise"] <= d["level"] for d in draws)),
        "level": draws[0]["level"],
        "verdicts": {v: share(sum(d["verdict"] == v for d in draws)) for v in verdicts},
        "identifiable_but_missed": sum(d["verdict"] == "identifiable" and not all(d["holds"].values())
                                       for d in draws),
        "rejected_at_1_percent": share(sum(d["p_value"] < fit.REJECT_P for d in draws)),
        "median_wall_time_s": statistics.median(d["wall_time_s"] for d in draws),
        "median_evaluations": statistics.median(d["evaluations"] for d in draws),
    }


def record_of(draws: list[dict], count: int, args, setting: dict, start: float, load_before) -> dict:
    return {
        "benchmark": f"coverage of the fit's 95 % regions: {setting['label']}",
        "model": setting["model"],
        "data": "steady steps by the refined integrator (refine = 2), last step of 16 periods from rest",
        "free": list(setting["free"]), "mu": MU, "stiffness_range_N_per_m": list(STIFFNESS_RANGE),
        "draws": count, "draws_done": len(draws), "quick": bool(args.quick), "smoke": bool(args.smoke),
        "noise_nm": NOISE_NM, "preloads_N": list(setting["preloads"]),
        "amplitudes_nm": list(setting["amplitudes_nm"]), "frequency_Hz": FREQUENCY, "nominal": 0.95,
        **summary(draws), "wall_time_s": time.perf_counter() - start, "cpus": os.cpu_count(),
        "load_average_before": list(load_before), "load_average_after": list(os.getloadavg()),
        "python": platform.python_version(), "machine": platform.machine(), "per_draw": draws,
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--draws", type=int, default=40)
    size = parser.add_mutually_exclusive_group()
    size.add_argument("--quick", action="store_true", help="4 draws, to a temporary file")
    size.add_argument("--smoke", action="store_true",
                      help="one draw of μ alone, one rigid contact, three steps, to a temporary file: checks "
                           "the script runs, measures nothing")
    parser.add_argument("--out", default=None,
                        help="JSON record (default: passmd/data/benchmarks/fit_coverage.json; --quick, "
                             "--smoke: a temporary file)")
    args = parser.parse_args()
    count = 4 if args.quick else 1 if args.smoke else args.draws
    if count < 1:
        parser.error(f"--draws {count} is out of range: must be >= 1")
    setting = SETTINGS["smoke" if args.smoke else "full"]
    if args.out is None:
        args.out = (os.path.join(tempfile.mkdtemp(prefix="bench-fit-coverage-"), "fit_coverage.json")
                    if args.quick or args.smoke else ROOT / "passmd/data/benchmarks/fit_coverage.json")
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    load_before = os.getloadavg()
    stiffnesses = truths(count)
    draws = []
    for done, seed in enumerate(stratified(count), 1):
        load = os.getloadavg()
        draws.append({**draw(seed, stiffnesses[seed], setting), "load_average_before": list(load)})
        d = draws[-1]
        print(f"draw {done}/{count} (seed {seed}): k_p = {stiffnesses[seed]:.4g} N/m, {d['verdict']}, "
              f"holds {d['holds']}, p = {d['p_value']:.3g}, {d['wall_time_s']:.0f} s (load {load[0]:.1f})",
              file=sys.stderr, flush=True)
        record = record_of(draws, count, args, setting, start, load_before)
        text = json.dumps(record, indent=2) + "\n"
        # atomic: a reader never sees a half-written record
        write_file(out, lambda tmp, text=text: Path(tmp).write_text(text, encoding="utf-8"), overwrite=True)
    shown = ("coverage", "coverage_both", "verdicts", "identifiable_but_missed", "median_wall_time_s")
    print(json.dumps({k: record[k] for k in shown}, indent=2))
    print(f"written: {out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    from passmd.runtime.scripts import run_script

    sys.exit(run_script(main))  # one line on failure, never a traceback
