"""One period at stall (Section 4.2): the time series and measures that show where the stall force
comes from — the runner's position, the load cell's force and, per contact side, the friction, the
actuators' deflection and the share of each contact that slides — from the fly-back that starts the
period. The stall itself is found by :func:`passmd.protocols.stall.generated_force`."""

from __future__ import annotations

import numpy as np

from passmd.model import waveforms
from passmd.model.parameters import Drive
from passmd.solver import simulation

__all__ = ["stall_cycle"]


def stall_cycle(
    drive: Drive, amplitude: float, frequency: float, periods: int, samples_per_period: int = 2000
) -> dict:
    """One period at stall, from the fly-back that starts it: time series and measures.

    Runs ``periods`` saw-tooth periods from rest (the count
    :func:`passmd.protocols.stall.generated_force` needed to stall) recording ``samples_per_period``
    samples per period, and keeps the window from the fly-back of period ``periods − 1`` to that of
    the last period.

    Returns
    -------
    dict
        Arrays (SI) ``time_s`` (since the fly-back), ``piezo_m``, ``runner_m`` (x_r − x̄_r),
        ``load_cell_N`` (k·x_r), ``friction_N`` (total on the runner), and per contact group
        (side 1: two contacts at F_N1, side 2: four at F_N2) ``friction_side{1,2}_N``,
        ``deflection_side{1,2}_m`` (x_p − x_a), ``slip_share_side{1,2}``; scalars
        ``generated_force_N``, ``sliding_capacity_N`` (Σ μF_N), ``back_slide_m`` (largest
        backward excursion of the runner after the fly-back, from every integrator step),
        ``deflection_before_flyback_side{1,2}_m`` (x_p − x_a at the last sample before it),
        ``full_slip_time_s`` (time every contact slides, to the sample spacing),
        ``mean_slip_share_side{1,2}`` (over the period), ``sample_spacing_s``. The first
        sample is the last one before the fly-back (negative time).
    """
    if not isinstance(drive, Drive) or drive.contacts != 6:
        raise ValueError(f"drive = {drive!r} is not allowed: must be a six-contact Drive")
    if isinstance(periods, bool) or int(periods) != periods or periods < 2:
        raise ValueError(f"periods = {periods!r} is out of range: must be an integer >= 2")
    if isinstance(samples_per_period, bool) or int(samples_per_period) != samples_per_period \
            or samples_per_period < 100:
        raise ValueError(
            f"samples_per_period = {samples_per_period!r} is out of range: must be an integer >= 100"
        )
    drive = drive if drive.load_cell else drive.replace(load_cell=True)
    wave = waveforms.sawtooth(amplitude, frequency, drive, periods=int(periods))
    result = simulation.simulate(drive, wave, max_points=int(periods) * int(samples_per_period) + 1)
    start, end = wave.slip_marks[-2], wave.slip_marks[-1]
    spacing = float(result.time[1] - result.time[0])
    first = int(np.searchsorted(result.time, start, side="right")) - 1  # last sample before the fly-back
    last = int(np.searchsorted(result.time, end, side="right"))
    sel = slice(first, last)
    t = result.time[sel] - start
    k = drive.load_cell_stiffness
    x_r = result.runner_position[sel]
    x_p = result.piezo_position[sel]
    n = result.multiplicity
    friction = result.friction_force[:, sel] * n[:, None]
    deflection = x_p[None, :] - result.actuator_position[:, sel]
    slip = result.slip_share[:, sel]
    forces = drive.contact_layout.normal_forces  # Eq. 1, as the simulation's groups
    capacity = float(drive.friction_coefficient * np.sum(n * forces))
    out = {
        "time_s": t,
        "piezo_m": x_p,
        "runner_m": x_r - float(np.mean(x_r[1:])),
        "load_cell_N": k * x_r,
        "friction_N": friction.sum(axis=0),
        "generated_force_N": float(result.generated_force),
        "sliding_capacity_N": capacity,
        "back_slide_m": float(result.back_steps[-2]),
        "full_slip_time_s": float(np.count_nonzero(np.all(slip[:, 1:] >= 1.0 - 1e-9, axis=0)) * spacing),
        "sample_spacing_s": spacing,
    }
    for g, side in enumerate(("side1", "side2")):
        out[f"friction_{side}_N"] = friction[g]
        out[f"deflection_{side}_m"] = deflection[g]
        out[f"slip_share_{side}"] = slip[g]
        out[f"deflection_before_flyback_{side}_m"] = float(deflection[g, 0])
        out[f"mean_slip_share_{side}"] = float(np.mean(slip[g, 1:]))
    return out
