"""Cost of a calibration: μ and k_p of six flexible contacts fitted to 15 steady steps, empty result cache.

First the cost of one model evaluation: the settled step of one row
(:func:`passmd.protocols.velocity.settled_step`, six contacts, flexible actuators, 100 Hz), timed in
this process over the rows of the data (median), and the cost of one parameter set (the 15 rows
through the sweep engine on the process pool). The
estimator's grids are sized against them: 180 s on two cores holds about
180 s × 2 / (15 × t_row) parameter sets, so the fit's stages are counted in parameter sets.

Then the fit: the steps of the Table 1–2 drive (R = 1 mm, six contacts, flexible actuators, ζ = 0.05)
at 100 Hz, three preloads (0.2, 0.4, 0.6 N) and five amplitudes (110–190 nm), made at μ = 0.25,
k_p = 5e6 N/m by the refined integrator (the last step of a 16-period run,
:func:`passmd.protocols.synthetic.independent_steps`) plus 0.5 nm Gaussian noise (seed 0,
sd stated); μ and k_p are fitted from the drive's defaults (μ = 0.2, k_p = 6.5e6 N/m) with the default
bounds, on a process pool over all cores and an empty result cache (a fresh temporary directory;
the compiled kernels are cached by numba). Its wall time covers everything ``passmd fit`` computes,
and the record says whether it stayed within :data:`BUDGET_S`.
The record says whether the regions hold the truth, the verdict and the goodness of fit, the
parameter sets per stage, and the machine's load average before and after (the 2-core machine
may be shared: the times are not proof of speed when it is loaded).

Then the same fit once more in this process alone (``executor="serial"``, another empty result
cache), with the integrator's time of every settled step summed (``wall_time_s`` of
:func:`~passmd.protocols.velocity.settled_step`: the compiled loop and its call): the integrator's
share of the fit, and its floor, that time over the cores, the wall time the fit would take if
nothing but the integration were left and every core were busy with it. A budget below the floor
cannot hold without a faster integrator or fewer simulated periods. The serial fit must find the
same estimates and regions as the pooled one (the record says whether it did: a fit does not
depend on how its rows were shared out).

``--quick``: one flexible contact and six steps (a small run of the same machinery), written to a
temporary file unless ``--out`` is given.
``--smoke``: μ alone of one rigid contact from three steps, written to a temporary file: the
same steps (data, row timing, parameter sets, the whole fit, the record) in seconds; it checks
that the script works, its times and regions mean nothing.

Usage::

    python benchmarks/bench_fit.py [--quick | --smoke] [--out passmd/data/benchmarks/fit.json]
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

import numpy as np

from passmd.model.parameters import Drive
from passmd.protocols import fit, velocity
from passmd.protocols.fit.prediction import drive_at
from passmd.protocols.synthetic import independent_steps
from passmd.runtime.config import RunConfig
from passmd.runtime.outputs import write_file

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_ledger import output  # noqa: E402  (a sibling script: --out, or a temporary file for --quick, --smoke)

FREE = ("friction_coefficient", "actuator.stiffness")
TRUTH = {"friction_coefficient": 0.25, "actuator.stiffness": 5e6}
#: Where the fit starts: the drive's defaults.
START = {"friction_coefficient": 0.2, "actuator.stiffness": 6.5e6}
NOISE_NM = 0.5
TARGET_S = 180.0
#: The wall time the full fit (15 rows, two free parameters, empty result cache) should stay within
#: on a quiet 2-core machine (s).
BUDGET_S = 20.0
SETTINGS = {
    "full": {"drive": Drive(), "free": FREE, "preloads": (0.2, 0.4, 0.6),
             "amplitudes_nm": (110.0, 130.0, 150.0, 170.0, 190.0),
             "label": "μ and k_p, six contacts, flexible actuators, 15 steady steps"},
    "quick": {"drive": Drive(contacts=1), "free": FREE, "preloads": (0.3, 0.5),
              "amplitudes_nm": (120.0, 160.0, 200.0), "label": "μ and k_p, one flexible contact, 6 steps"},
    "smoke": {"drive": Drive(contacts=1, actuator_model="rigid"), "free": FREE[:1], "preloads": (0.4,),
              "amplitudes_nm": (120.0, 160.0, 200.0), "label": "μ alone, one rigid contact, 3 steps"},
}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    size = parser.add_mutually_exclusive_group()
    size.add_argument("--quick", action="store_true",
                      help="one flexible contact, six steps, to a temporary file")
    size.add_argument("--smoke", action="store_true",
                      help="μ alone, one rigid contact, three steps, to a temporary file: checks the script "
                           "runs, measures nothing")
    parser.add_argument("--out", default=None,
                        help="JSON written (default: passmd/data/benchmarks/fit.json; --quick, --smoke: a "
                             "temporary file)")
    args = parser.parse_args()
    setting = SETTINGS["smoke" if args.smoke else "quick" if args.quick else "full"]
    base, free = setting["drive"], setting["free"]
    truth = drive_at(base, list(free), [TRUTH[n] for n in free], base.actuator.damping_ratio)
    conditions = [(p, a * 1e-9, 100.0) for p in setting["preloads"] for a in setting["amplitudes_nm"]]
    steps = independent_steps(truth, conditions)
    noisy = steps + np.random.default_rng(0).normal(0.0, NOISE_NM * 1e-9, steps.size)
    header = ["amplitude_nm", "preload_N", "frequency_Hz", "step_nm", "step_nm_sd"]
    rows = [[repr(float(a * 1e9)), repr(p), repr(f), repr(float(v * 1e9)), repr(NOISE_NM)]
            for (p, a, f), v in zip(conditions, noisy, strict=True)]
    data = fit.measurements_from_rows(header, rows, name="bench_fit data")

    load_row = os.getloadavg()
    row_times = []
    for p, a, f in conditions:  # one model evaluation per row, in this process (kernels warm)
        start = time.perf_counter()
        velocity.settled_step(base.replace(preload=p), a, f)
        row_times.append(time.perf_counter() - start)
    with tempfile.TemporaryDirectory() as cache:
        config = RunConfig(cache_dir=Path(cache))
        from passmd.protocols.fit.prediction import _Model

        model = _Model(base, data, list(free), "steady", executor=None, cache=cache, config=config)
        x_start = np.log([START[n] for n in free])
        start = time.perf_counter()
        model.evaluate([x_start + 0.005 * k * np.eye(len(free))[0] for k in range(8)])  # eight μ
        set_s = (time.perf_counter() - start) / 8

    stages: list[tuple[float, str]] = []
    with tempfile.TemporaryDirectory() as cache:
        load_before = os.getloadavg()
        start = time.perf_counter()

        def progress(line: str) -> None:
            stages.append((time.perf_counter() - start, line))
            print(f"fit: {line} [{time.perf_counter() - start:.0f} s]", file=sys.stderr, flush=True)

        result = fit.fit(base, data, list(free), config=RunConfig(cache_dir=Path(cache)), progress=progress)
        wall = time.perf_counter() - start
        load_after = os.getloadavg()
    serial = serial_fit(base, data, free)
    row_s = statistics.median(row_times)
    record = {
        "benchmark": f"fit: {setting['label']}",
        "quick": bool(args.quick),
        "smoke": bool(args.smoke),
        "wall_time_s": wall,
        "target_s": TARGET_S,
        "budget_s": BUDGET_S,
        "within_budget": wall <= BUDGET_S,
        "row_evaluation_s": row_s,
        "row_evaluation_times_s": row_times,
        "parameter_set_s": set_s,
        "budget_parameter_sets": TARGET_S * (os.cpu_count() or 1) / (len(data) * row_s),
        "model_evaluations": result.evaluations,
        "simulations": result.simulations,
        "stages": [{"t_s": t, "line": line} for t, line in stages],
        "truth": {n: TRUTH[n] for n in free},
        "estimates": {n: result.estimates[n]["value"] for n in free},
        "intervals": {n: result.estimates[n]["intervals"] for n in free},
        "regions_hold_truth": {n: any(a <= TRUTH[n] <= b for a, b in result.estimates[n]["intervals"])
                               for n in free},
        "identifiable": result.identifiable,
        "goodness_of_fit": result.goodness_of_fit,
        "verdict": result.verdict,
        "serial_wall_time_s": serial["wall_s"],
        "integrator_s": serial["integrator_s"],
        "integrator_floor_s": serial["integrator_s"] / (os.cpu_count() or 1),
        "simulated_periods": serial["periods"],
        "serial_same_result": same_result(result, serial["result"], free),
        "load_average_serial": serial["load_before"],
        "cpus": os.cpu_count(),
        "load_average_row_timing": list(load_row),
        "load_average_before": list(load_before),
        "load_average_after": list(load_after),
        "python": platform.python_version(),
        "machine": platform.machine(),
    }
    out = output(args, "fit")
    text = json.dumps(record, indent=2) + "\n"
    out.parent.mkdir(parents=True, exist_ok=True)
    write_file(out, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"), overwrite=True)  # atomic
    shown = ("wall_time_s", "budget_s", "within_budget", "row_evaluation_s", "parameter_set_s",
             "budget_parameter_sets", "model_evaluations", "regions_hold_truth", "integrator_floor_s",
             "serial_same_result", "load_average_before", "load_average_after")
    print(json.dumps({k: record[k] for k in shown}, indent=2))
    print(f"written {out}")
    return 0


def serial_fit(base, data, free) -> dict:
    """The fit again in this process (empty result cache), with the integrator's time of its settled
    steps summed: ``wall_s``, ``integrator_s``, ``periods``, ``result``, ``load_before``."""
    spent = {"integrator_s": 0.0, "periods": 0}
    settled_step = velocity.settled_step

    def timed(*args, **kwargs):  # every step of the data (100 Hz) is a settled step
        out = settled_step(*args, **kwargs)
        spent["integrator_s"] += out["wall_time_s"]
        spent["periods"] += out["periods"]
        return out

    velocity.settled_step = timed  # (read by passmd.protocols.fit.prediction.predict_point at each call)
    try:
        with tempfile.TemporaryDirectory() as cache:
            load_before = os.getloadavg()
            start = time.perf_counter()
            result = fit.fit(base, data, list(free), executor="serial",
                             config=RunConfig(cache_dir=Path(cache)))
            wall = time.perf_counter() - start
    finally:
        velocity.settled_step = settled_step
    return {"wall_s": wall, "result": result, "load_before": list(load_before), **spent}


def same_result(first, second, free) -> bool:
    """Whether two fits found the same estimates and the same regions (exactly)."""
    return all(first.estimates[n]["value"] == second.estimates[n]["value"]
               and first.estimates[n]["intervals"] == second.estimates[n]["intervals"] for n in free)


if __name__ == "__main__":
    from passmd.runtime.scripts import run_script

    sys.exit(run_script(main))  # one line on failure, never a traceback
