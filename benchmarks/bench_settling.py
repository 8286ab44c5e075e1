"""When a run from rest has settled: the state rule of ``velocity.settled_step`` against three agreeing steps.

Random drives (one or six contacts, flexible or rigid actuators, k_p, m_a and m_r within a factor
e of the paper's, ζ 0.01–0.3, preload 0.1–0.8 N, μ 0.1–0.4, 20–900 Hz, 60–202 nm) each run
:data:`PERIODS` periods from rest under a saw-tooth. A drive whose last ten steps agree to
:data:`CONVERGED` has a true step, its last one; the others are counted and left out. On the
recorded run, each rule's stopping period and step are read off as ``settled_step`` would stop:

* ``steps``: the last three steps agree to ``STEP_ACCURACY`` (the step is the last one);
* ``state <share>``: the end-of-period states match, moved on by the runner's advance, to share ×
  ``STEP_ACCURACY`` (:func:`passmd.solver.periodicity.mismatch`; the step is the advance), or,
  where the contact memory changed its structure, the three steps agree.

Per rule: the mean number of periods and how many steps miss the true one by more than
``STEP_ACCURACY``, with the largest miss. Two samples: ``tuning`` (seed 2), on which
``velocity.STATE_SHARE`` was chosen, and ``held_out`` (seed 3), which it never saw. Every drive
also runs ``velocity.settled_step`` itself, which must stop at the period and step of ``state``
at ``STATE_SHARE`` (``cross_check_failures`` counts where it does not).

``--quick``: 200 drives per sample; ``--smoke``: 6, to a temporary file (checks that the script
works; its counts mean nothing).

Usage::

    python benchmarks/bench_settling.py [--quick | --smoke] [--out passmd/data/benchmarks/settling.json]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from passmd.model import waveforms
from passmd.model.parameters import Drive
from passmd.protocols import velocity
from passmd.runtime.outputs import write_file
from passmd.runtime.validation import InputError
from passmd.solver import periodicity, simulation

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_ledger import output  # noqa: E402  (a sibling script: --out, or a temporary file for --quick, --smoke)

PERIODS = 40
#: A drive's last ten steps must agree to this for its last step to count as the true one (m).
CONVERGED = 1e-12
SHARES = (0.1, 0.2, 0.3, 0.5, 1.0, 5.0)
SAMPLES = {"tuning": 2, "held_out": 3}
SIZES = {"full": 3000, "quick": 200, "smoke": 6}


def random_drives(seed: int, count: int):
    """``count`` (drive, amplitude, frequency) the simulator accepts, drawn as the docstring says."""
    rng = np.random.default_rng(seed)
    base = Drive()
    out = []
    while len(out) < count:
        contacts = int(rng.choice([1, 6]))
        model = str(rng.choice(["flexible", "flexible", "rigid"]))
        stiffness = base.actuator.stiffness * math.exp(rng.uniform(-1.0, 1.0))
        mass = base.actuator.mass * math.exp(rng.uniform(-1.0, 1.0))
        zeta = math.exp(rng.uniform(math.log(0.01), math.log(0.3)))
        act = replace(base.actuator, stiffness=stiffness, mass=mass,
                      viscosity=2 * zeta * math.sqrt(stiffness * mass))
        drive = replace(base, contacts=contacts, actuator_model=model, actuator=act, allow_extrapolation=True,
                        preload=float(rng.uniform(0.1, 0.8)),
                        friction_coefficient=float(rng.uniform(0.1, 0.4)),
                        runner_mass=float(base.runner_mass * math.exp(rng.uniform(-1.0, 1.0))))
        frequency = float(math.exp(rng.uniform(math.log(20.0), math.log(900.0))))
        amplitude = float(rng.uniform(60e-9, 300e-9))
        try:
            waveforms.sawtooth(amplitude, frequency, drive, periods=1)
        except InputError:  # beyond the stroke: drawn again
            continue
        out.append((drive, amplitude, frequency))
    return out


def record(drive, amplitude, frequency):
    """Steps and end-of-period (mismatch, advance) of a :data:`PERIODS`-period run."""
    run = simulation.Simulation(drive, waveforms.sawtooth(amplitude, frequency, drive, periods=PERIODS),
                                max_points=2)
    states = []
    for k in range(1, PERIODS + 1):
        run.run_to(k)
        states.append(run.boundary_state())
    pairs = [periodicity.mismatch(a, b) for a, b in zip(states[:-1], states[1:], strict=True)]
    return np.diff(run.settled_positions()), pairs


def stop(steps, pairs, share):
    """(periods, step) where a rule stops (share None: three agreeing steps, which is
    ``velocity.settled_value``'s rule where the states cannot be compared), or None."""
    for periods in range(2, PERIODS + 1):
        pair = (math.inf, 0.0) if share is None else pairs[periods - 2]
        step = velocity.settled_value(steps[:periods - 1], *pair, velocity.STEP_ACCURACY, share)
        if step is not None:
            return periods, step
    return None


def sample(seed: int, count: int) -> dict:
    rules = {"steps": None, **{f"state {share:g}": share for share in SHARES}}
    found = {name: [] for name in rules}
    unconverged, cross = 0, 0
    for drive, amplitude, frequency in random_drives(seed, count):
        steps, pairs = record(drive, amplitude, frequency)
        tail = steps[-10:]
        if tail.max() - tail.min() > CONVERGED:
            unconverged += 1
            continue
        truth = float(steps[-1])
        for name, share in rules.items():
            at = stop(steps, pairs, share)
            if at is not None:
                found[name].append((at[0], abs(at[1] - truth)))
        direct = velocity.settled_step(drive, amplitude, frequency, max_periods=PERIODS)
        expected = stop(steps, pairs, velocity.STATE_SHARE)
        if expected is None or direct["periods"] != expected[0] or direct["step_m"] != expected[1]:
            cross += 1
    out = {"seed": seed, "drives": count, "not_converged": unconverged, "cross_check_failures": cross,
           "rules": {}}
    for name, hits in found.items():
        periods = np.array([h[0] for h in hits], float)
        miss = np.array([h[1] for h in hits], float)
        out["rules"][name] = {
            "stopped": len(hits),
            "mean_periods": float(periods.mean()) if hits else math.nan,
            "misses_beyond_accuracy": int(np.sum(miss > velocity.STEP_ACCURACY)),
            "largest_miss_nm": float(miss.max() * 1e9) if hits else math.nan,
            "miss_p99_nm": float(np.quantile(miss, 0.99) * 1e9) if hits else math.nan,
        }
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    size = parser.add_mutually_exclusive_group()
    size.add_argument("--quick", action="store_true", help=f"{SIZES['quick']} drives per sample")
    size.add_argument("--smoke", action="store_true",
                      help=f"{SIZES['smoke']} drives per sample, to a temporary file: checks the script runs")
    parser.add_argument("--out", default=None, help="JSON file (default: the committed record)")
    args = parser.parse_args()
    mode = "smoke" if args.smoke else "quick" if args.quick else "full"
    t0 = time.perf_counter()
    result = {
        "benchmark": "settling of a run from rest: state rule against three agreeing steps",
        "mode": mode, "periods": PERIODS, "step_accuracy_nm": velocity.STEP_ACCURACY * 1e9,
        "state_share": velocity.STATE_SHARE,
        "samples": {name: sample(seed, SIZES[mode]) for name, seed in SAMPLES.items()},
    }
    result.update({"wall_time_s": time.perf_counter() - t0, "cpus": os.cpu_count(),
                   "load_average_after": list(os.getloadavg()), "python": platform.python_version()})
    path = output(args, "settling")
    text = json.dumps(result, indent=2) + "\n"
    write_file(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"), overwrite=True)  # atomic
    for name, part in result["samples"].items():
        print(f"{name} (seed {part['seed']}, {part['drives']} drives, {part['not_converged']} not converged, "
              f"{part['cross_check_failures']} cross-check failures)")
        for rule, r in part["rules"].items():
            print(f"  {rule:10s} periods {r['mean_periods']:.2f}  misses {r['misses_beyond_accuracy']:3d}  "
                  f"largest {r['largest_miss_nm']:.4f} nm")
    print(f"wrote {path}")
    return 0 if all(p["cross_check_failures"] == 0 for p in result["samples"].values()) else 1


if __name__ == "__main__":
    from passmd.runtime.scripts import run_script

    sys.exit(run_script(main))  # one line on failure, never a traceback
