"""A plain fixed-step velocity-Verlet simulator of the same model: the yardstick of ``bench_dynamics``.

Eqs. 2–3 with the exact MDR contacts of :mod:`passmd.model.contact` (one contact row per
group, as the package shares one state per side), written the way one would first write
it: one numba loop, every linear piece of x_p(t) cut into equal steps no longer than the
fine step of :func:`passmd.solver.steps.step_plan` (96 steps per period of the ≈ 3 MHz
actuator mode), kick–drift–kick on the runner and the actuators with the damping
trapezoidal in the velocity, the contact memory committed once per step, and the settled
position of each period (the mean of x_r − x_p over its settle window plus x_p at the
window's end, :mod:`passmd.model.waveforms`) accumulated on the way. No step adaptation, no
event handling, no energy terms, no recording: the cost of the physics alone at the step
the stiff mode needs everywhere.

``bench_dynamics`` times :func:`run` against the package's default integrator in the same
process, interleaved, and reports the ratio of their costs per 100 Hz period.

Usage::

    python benchmarks/verlet_baseline.py [--periods 3] [--amplitude-nm 150]
    python benchmarks/verlet_baseline.py --smoke   # one short period: checks the loop runs

``--smoke`` runs one 10 kHz period of six flexible contacts and checks its settled position
against the package's fixed fine step (the same equations at the same step) to 0.05 nm; its
time means nothing.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from numba import njit

from passmd.model.contact import contact_update_row
from passmd.model.contact_kernels import P_STIFFNESS
from passmd.model.parameters import Drive
from passmd.model.waveforms import Waveform
from passmd.solver.setup import contact_rows
from passmd.solver.steps import step_plan

#: numba options: the loop allocates nothing (its work arrays come from :func:`run`), so it runs
#: without reference counting, as the package's kernels do (a contact call then costs a plain call)
OPTIONS = {"cache": True, "error_model": "numpy", "_nrt": False}


@njit(**OPTIONS)
def _verlet(times, positions, dt_max, window_start, window_end, runner_mass, load_stiffness, multiplicity,
            actuator_mass, actuator_stiffness, actuator_viscosity, params, state, work, settled):
    """Fixed-step velocity Verlet over the pieces of x_p(t); settled positions into ``settled``
    (``work``: zeros of shape (4, groups)). Returns the number of steps."""
    G = multiplicity.shape[0]
    x_a, v_a, a_a, T = work[0], work[1], work[2], work[3]
    x_r = 0.0
    v_r = 0.0
    a_r = 0.0
    gam = actuator_viscosity / actuator_mass
    inv_ma = 1.0 / actuator_mass
    inv_mr = 1.0 / runner_mass
    steps = 0
    period = 0
    integral = 0.0
    length = 0.0
    for s in range(times.shape[0] - 1):
        t0, t1 = times[s], times[s + 1]
        x0, x1 = positions[s], positions[s + 1]
        n = int(np.ceil((t1 - t0) / dt_max))
        dt = (t1 - t0) / n
        vp = (x1 - x0) / (t1 - t0)
        in_window = t0 >= window_start[period] and t1 <= window_end[period]
        damp = 1.0 / (1.0 + 0.5 * dt * gam)
        for i in range(n):
            x_p = x0 + vp * i * dt
            xp_new = x1 if i == n - 1 else x0 + vp * (i + 1) * dt
            xr_old = x_r
            x_r += dt * v_r + 0.5 * dt * dt * a_r
            F = 0.0
            for g in range(G):
                x_a[g] += dt * v_a[g] + 0.5 * dt * dt * (a_a[g] - gam * v_a[g])
                T[g] = contact_update_row(params, state, g, x_a[g] - x_r)
                F += multiplicity[g] * T[g]
            a_new = (F - load_stiffness * x_r) * inv_mr
            v_r += 0.5 * dt * (a_r + a_new)
            if in_window:
                integral += 0.5 * dt * ((xr_old - x_p) + (x_r - xp_new))
                length += dt
            a_r = a_new
            for g in range(G):
                a_g = (actuator_stiffness * (xp_new - x_a[g]) - T[g]) * inv_ma
                v_a[g] = (v_a[g] + 0.5 * dt * (a_a[g] - gam * v_a[g] + a_g)) * damp
                a_a[g] = a_g
            steps += 1
        if in_window and t1 >= window_end[period]:
            settled[period] = integral / length + x1
            integral = 0.0
            length = 0.0
        if period + 1 < window_start.shape[0] and t1 >= window_end[period]:
            period += 1
    return steps


def fine_step(drive: Drive) -> float:
    """The package's fine step of ``drive`` (96 steps per period of the stiffest mode)."""
    params, _, multiplicity = contact_rows(drive, "exact", 2, True)
    k = params[:, P_STIFFNESS]  # largest tangent stiffness 2aG* of each group
    return step_plan(drive, float(k.max()), float(np.sum(multiplicity * k))).fine_step


def run(drive: Drive, waveform: Waveform, cpu: bool = False) -> tuple:
    """Settled positions (m), steps and wall time (s) of the plain Verlet run (from rest, virgin
    contacts); with ``cpu`` also the CPU time of its loop (s)."""
    if drive.actuator_model != "flexible":
        raise ValueError("the baseline integrates flexible actuators only")
    params, state, multiplicity = contact_rows(drive, "exact", 2, True)
    settled = np.zeros(waveform.periods)
    act = drive.actuator
    start, start_cpu = time.perf_counter(), time.thread_time()
    windows = waveform.settle_windows
    steps = _verlet(waveform.times, waveform.positions, fine_step(drive), windows[:, 0].copy(),
                    windows[:, 1].copy(), drive.runner_mass, drive.effective_load_cell_stiffness,
                    multiplicity.astype(float), act.mass, act.stiffness,
                    act.viscosity, params, state, np.zeros((4, multiplicity.size)), settled)
    wall, loop = time.perf_counter() - start, time.thread_time() - start_cpu
    return (settled, int(steps), wall, loop) if cpu else (settled, int(steps), wall)


def main(argv=None) -> int:
    from passmd.model import waveforms
    from passmd.solver import simulation

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--periods", type=int, default=3, help="100 Hz periods")
    ap.add_argument("--amplitude-nm", type=float, default=150.0, help="saw-tooth amplitude (nm)")
    ap.add_argument("--smoke", action="store_true",
                    help="one 10 kHz period, checked against the package's fixed fine step: checks the loop "
                         "runs")
    args = ap.parse_args(argv)
    drive = Drive(contacts=6, actuator_model="flexible")
    frequency, periods = (10e3, 1) if args.smoke else (100.0, args.periods)
    wf = waveforms.sawtooth(args.amplitude_nm * 1e-9, frequency, drive, periods=periods)
    run(drive, wf)  # compile
    settled, steps, wall = run(drive, wf)
    print(f"plain Verlet: {steps / periods:.0f} steps and {wall / periods * 1e3:.2f} ms per period, "
          f"{wall / steps * 1e9:.1f} ns per step; settled positions {np.round(settled * 1e9, 4)} nm")
    if args.smoke:
        reference = simulation.simulate(drive, wf, scheme="fixed", max_points=2).settled_positions
        error = float(np.abs(settled - reference).max())
        print(f"against the package's fixed fine step: {error * 1e9:.4f} nm")
        if error > 0.05e-9:
            raise SystemExit("the baseline disagrees with the package's fixed fine step")
    return 0


if __name__ == "__main__":
    from passmd.runtime.scripts import run_script

    raise SystemExit(run_script(main))  # one line on failure, never a traceback
