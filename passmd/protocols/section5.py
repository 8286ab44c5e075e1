"""Section 5's runs: its drives, their Eq. 15 designs and the sweep's point functions.

The drive of Section 5 (:func:`section5_drive`), its Eq. 15 design (:func:`design_point`,
:func:`designs`), and the point functions the sweep sends to worker processes (so they are top
level): the steady velocity of one drive, waveform and frequency (:func:`velocity_point`, tabulated
over a grid by :func:`velocity_table`), the time series of one run from rest (:func:`trace_point`)
and Fig. 8b's run resolved inside the acceleration t_a (:func:`window_point`). Section 5 does not
state μ, so every function here takes it: Section 5's chapters supply the ledger's reading
(:func:`passmd.experiments.driving_waveform.figures.section5_fields`), and all three of them
(:mod:`passmd.experiments.driving_waveform.figures`, :mod:`passmd.experiments.waveform_velocity.figures`,
:mod:`passmd.experiments.waveform_optimum.figures`) tabulate these runs.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from passmd.model import optimized_waveform, theory, waveforms
from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import MOLYBDENUM, STEEL, Drive, paper_drive
from passmd.protocols import eq15
from passmd.protocols.velocity import (
    make_waveform,
    steady_run,
)
from passmd.runtime import sweep
from passmd.runtime.config import RunConfig
from passmd.runtime.validation import check_choice
from passmd.solver import simulation, steps
from passmd.solver.results import SimulationError

#: Driving frequency of Figs. 8 and 9a (Hz).
STEP_FREQUENCY = PROTOCOL.drive_frequency
#: Runner materials of Fig. 10c.
RUNNERS = {"steel": STEEL, "molybdenum": MOLYBDENUM}
#: Waveform variants of Figs. 9b and 10: (waveform, short_period rule). Where Eq. 15's settling time does
#: not fit the period, ``cut`` shortens it to the time left and ``skip`` drops it (t_s = 0): neither is
#: Eq. 15, so both are the ledger's readings of the Eq. 15 claims there (passmd.ledger.readings).
VARIANTS = (("sawtooth", ""), ("optimized", "cut"), ("optimized", "skip"))


def variant_name(waveform: str, short_period: str) -> str:
    """Label of a (waveform, short-period rule) pair of :data:`VARIANTS` in tables and plots."""
    if waveform == "sawtooth":
        return "sawtooth"
    return "optimized_skip" if short_period == "skip" else "optimized"


def section5_drive(hemisphere_radius: float, preload: float, runner: str, actuator_model: str,
                   friction_coefficient: float) -> Drive:
    """The drive of Section 5: six contacts, Table 1–2 parameters, free runner.

    ``runner`` names the runner material (``"steel"``, Table 1, or ``"molybdenum"``,
    Fig. 10c); ``actuator_model`` is ``"rigid"`` in the paper. ``friction_coefficient`` is
    Section 5's unstated μ (ledger axis ``friction_coefficient``, :mod:`passmd.ledger.readings`).
    """
    check_choice("runner", runner, tuple(RUNNERS))
    return paper_drive(hemisphere_radius, preload, actuator_model=actuator_model,
                       runner_material=RUNNERS[runner], friction_coefficient=friction_coefficient)


def make_design(settling_time: float, acceleration_time: float,
                acceleration_amplitude: float) -> optimized_waveform.OptimizedDesign:
    """An :class:`~passmd.model.optimized_waveform.OptimizedDesign` from plain sweep parameters."""
    return optimized_waveform.OptimizedDesign(settling_time, acceleration_time, acceleration_amplitude)


def design_point(hemisphere_radius: float, preload: float, runner: str, actuator_model: str,
                 friction_coefficient: float) -> dict:
    """Eq. 15 design of a drive at its full amplitude (:func:`passmd.protocols.eq15.optimized_design`).

    Returns the design's :meth:`~passmd.model.optimized_waveform.OptimizedDesign.as_dict` plus the amplitude
    and the linear runner-on-contacts frequency (:func:`passmd.model.theory.runner_frequency`).
    """
    drive = section5_drive(hemisphere_radius, preload, runner, actuator_model, friction_coefficient)
    amplitude = drive.actuator.full_stroke_amplitude
    out = eq15.optimized_design(amplitude, drive).as_dict()
    out["amplitude_m"] = amplitude
    out["linear_frequency_Hz"] = theory.runner_frequency(drive)
    return out


def velocity_point(hemisphere_radius: float, preload: float, runner: str, actuator_model: str,
                   frequency: float, waveform: str, short_period: str, settling_time: float,
                   acceleration_time: float, acceleration_amplitude: float,
                   friction_coefficient: float) -> dict:
    """Steady velocity of one Section 5 drive, waveform and frequency at the full amplitude.

    :func:`passmd.protocols.velocity.steady_run`; the design fields are ignored for the saw-tooth.
    """
    drive = section5_drive(hemisphere_radius, preload, runner, actuator_model, friction_coefficient)
    design = None if waveform != "optimized" else make_design(settling_time, acceleration_time,
                                                               acceleration_amplitude)
    return steady_run(drive, drive.actuator.full_stroke_amplitude, frequency, waveform, short_period, design)


def trace_point(hemisphere_radius: float, preload: float, runner: str, actuator_model: str,
                frequency: float, periods: int, waveform: str, settling_time: float,
                acceleration_time: float, acceleration_amplitude: float, zoom_start: float,
                zoom_end: float, full_samples: int, zoom_samples: int,
                friction_coefficient: float) -> dict:
    """Time series of one run from rest, for the time-domain figures (Figs. 8, 9a).

    The run is recorded at ≥ 200 samples per linear runner-vibration period and returned
    resampled on two uniform grids: the whole run (``full_*``) and ``[zoom_start,
    zoom_end]`` (``zoom_*``). Also returns the per-period measures, the micro-vibration
    frequency f_s after the first fly-back (saw-tooth) or after the first acceleration
    (optimized), measured as in the design (:func:`passmd.protocols.eq15.micro_vibration_frequency`),
    and the first three turning points of the runner after the first fly-back.
    """
    drive = section5_drive(hemisphere_radius, preload, runner, actuator_model, friction_coefficient)
    amplitude = drive.actuator.full_stroke_amplitude
    design = None if waveform == "sawtooth" else make_design(
        settling_time, acceleration_time, acceleration_amplitude)
    wave = make_waveform(drive, amplitude, frequency, periods, waveform, "cut", design)
    samples = int(math.ceil(wave.duration * theory.runner_frequency(drive) * 200)) + 1
    result = simulation.simulate(drive, wave, max_points=max(samples, 2000))
    t = result.time
    period = 1.0 / frequency
    v_p = wave.velocity(t)
    if waveform == "sawtooth":
        after = period
    else:
        timing = optimized_waveform.optimized_timing(design, amplitude, frequency, drive)
        after = period + timing["settling_time_s"] + timing["acceleration_time_s"]
    f_s, _ = eq15.micro_vibration_frequency(t, result.runner_velocity, v_p, after)
    _, turning = eq15.micro_vibration_frequency(t, result.runner_velocity, v_p, period)
    out = {
        "settled_positions_m": result.settled_positions,
        "back_steps_m": result.back_steps,
        "micro_vibration_frequency_Hz": f_s,
        "vibration_after_s": after,
        "flyback_start_s": period - waveforms.flyback_time(amplitude, drive),
        "turning_times_s": turning[:3],
        "wall_time_s": result.wall_time,
    }
    channels = {
        "piezo_position_m": result.piezo_position,
        "runner_position_m": result.runner_position,
        "runner_velocity_m_per_s": result.runner_velocity,
    }
    for g in range(result.multiplicity.size):
        channels[f"slip_share_{g + 1}"] = result.slip_share[g]
        channels[f"friction_force_{g + 1}_N"] = result.friction_force[g]
    for view, (t0, t1, n) in {"full": (0.0, wave.duration, full_samples),
                              "zoom": (zoom_start, zoom_end, zoom_samples)}.items():
        grid = np.linspace(t0, t1, int(n))
        out[f"{view}_time_s"] = grid
        for name, values in channels.items():
            out[f"{view}_{name}"] = np.interp(grid, t, values)
        out[f"{view}_piezo_position_m"] = wave.position(grid)  # exact, not resampled
    return out


def designs(drives: list[dict], config: RunConfig) -> pd.DataFrame:
    """Eq. 15 design of each drive (plain sweep parameters of :func:`section5_drive`; :func:`design_point`),
    one row each, cached."""
    return sweep.run(design_point, [dict(c) for c in drives], description="waveform design", config=config)


def design_fields(row) -> dict:
    """The design columns of a :func:`designs` row as the sweep parameters of the point functions."""
    return {"settling_time": float(row["settling_time_s"]),
            "acceleration_time": float(row["acceleration_time_s"]),
            "acceleration_amplitude": float(row["acceleration_amplitude_m"])}


def velocity_columns(table: pd.DataFrame) -> pd.DataFrame:
    """Add a velocity sweep's ``variant`` (:func:`variant_name` of its waveform and short-period rule),
    ``frequency_kHz`` and ``velocity_mm_per_s`` to ``table`` (in place, returned)."""
    table["variant"] = [variant_name(w, r)
                        for w, r in zip(table["waveform"], table["short_period"], strict=True)]
    table["frequency_kHz"] = table["frequency"] / 1e3
    table["velocity_mm_per_s"] = table["velocity_m_per_s"] * 1e3
    return table


def velocity_table(drives: list[dict], frequencies, config: RunConfig) -> pd.DataFrame:
    """Steady velocity of every configuration × waveform variant (:data:`VARIANTS`) × frequency.

    Each configuration's optimized waveform is its own Eq. 15 design. Adds display
    columns (``frequency_kHz``, ``velocity_mm_per_s``, ``step_nm``, ``back_step_nm``,
    ``radius_mm``) and ``variant`` (``sawtooth``, ``optimized``, ``optimized_skip``).
    """
    design_rows = designs(drives, config)
    points = []
    for c, (_, d) in zip(drives, design_rows.iterrows(), strict=True):
        fields = design_fields(d)
        for waveform, rule in VARIANTS:
            for f in frequencies:
                points.append({**c, "frequency": float(f), "waveform": waveform, "short_period": rule,
                               **fields})
    table = sweep.run(velocity_point, points, description="steady velocity", config=config)
    velocity_columns(table)
    table["step_nm"] = table["step_m"] * 1e9
    table["back_step_nm"] = table["back_step_m"] * 1e9
    table["radius_mm"] = table["hemisphere_radius"] * 1e3
    per_point = len(VARIANTS) * len(frequencies)
    table["micro_vibration_frequency_Hz"] = np.repeat(design_rows["micro_vibration_frequency_Hz"].to_numpy(),
                                                      per_point)
    # Eq. 15 is defined where its settling time, acceleration and fly-back fit into the period
    flyback = np.repeat([full_stroke_flyback(c) for c in drives], per_point)
    table["flyback_time_s"] = flyback
    table["eq15_time_s"] = np.repeat([float(d["settling_time_s"]) + float(d["acceleration_time_s"])
                                      for _, d in design_rows.iterrows()], per_point) + flyback
    table["eq15_fits"] = table["eq15_time_s"].to_numpy() < 1.0 / table["frequency"].to_numpy()
    return table


def full_stroke_flyback(fields: dict) -> float:
    """The fly-back at the full stroke of a Section 5 drive (s): both fly-back rules give the same."""
    drive = section5_drive(fields["hemisphere_radius"], fields["preload"], fields["runner"],
                           fields["actuator_model"], fields["friction_coefficient"])
    return waveforms.flyback_time(drive.actuator.full_stroke_amplitude, drive)


#: Integration refinement of the fly-back window run (``simulate``'s ``resolution``: the
#: error-controlled step's tolerance divided by its fourth power, so the step by about this):
#: t_a (about 0.2 µs) spans at least ``passmd.solver.steps.MIN_SEGMENT_STEPS`` steps like every piece,
#: and the refinement keeps the steps around it (the fly-back's slip and the settling t_s)
#: as fine as t_a's.
WINDOW_RESOLUTION = {"quick": 20.0, "paper": 40.0}
#: Record spacing of the fly-back window run: t_a / this (evenly spaced over the whole run).
WINDOW_SAMPLES_PER_ACCELERATION = 10
#: The window kept: from this long before the fly-back to this long after the end of t_a (s);
#: 30 µs after t_a covers more than a quarter of the runner's ~10 kHz micro-vibration.
WINDOW_BEFORE, WINDOW_AFTER = 2e-6, 30e-6


def window_point(hemisphere_radius: float, preload: float, runner: str, actuator_model: str,
                 settling_time: float, acceleration_time: float, acceleration_amplitude: float,
                 resolution: float, samples_per_acceleration: int,
                 friction_coefficient: float) -> dict:
    """Fig. 8b's run (100 Hz, period 1 saw-tooth, period 2 optimized) resolved inside t_a.

    The run is integrated with the step divided by ``resolution`` and recorded every
    t_a / ``samples_per_acceleration``; only the window from :data:`WINDOW_BEFORE` before the
    fly-back to :data:`WINDOW_AFTER` after the end of t_a is returned (time series ``time_s``,
    ``runner_velocity_m_per_s``, ``runner_position_m``, ``piezo_position_m``, ``slip_share_<g>``),
    with the fly-back start and end, the start and end of t_a (s) and the largest record
    spacing inside t_a (``record_spacing_s``).
    """
    drive = section5_drive(hemisphere_radius, preload, runner, actuator_model, friction_coefficient)
    amplitude = drive.actuator.full_stroke_amplitude
    design = make_design(settling_time, acceleration_time, acceleration_amplitude)
    wave = make_waveform(drive, amplitude, STEP_FREQUENCY, 2, "optimized", "cut", design)
    timing = optimized_waveform.optimized_timing(design, amplitude, STEP_FREQUENCY, drive)
    period = 1.0 / STEP_FREQUENCY
    flyback = waveforms.flyback_time(amplitude, drive)
    start_a = period + timing["settling_time_s"]
    end_a = start_a + timing["acceleration_time_s"]
    points = int(math.ceil(wave.duration * samples_per_acceleration / timing["acceleration_time_s"])) + 1
    refined = steps.SCHEMES["controlled"].replace(refine=resolution)
    result = simulation.simulate(drive, wave, scheme=refined, max_points=points)
    t = result.time
    keep = (t >= period - flyback - WINDOW_BEFORE) & (t <= end_a + WINDOW_AFTER)
    inside = t[(t >= start_a) & (t <= end_a)]
    if inside.size < 2:
        raise SimulationError("fewer than two recorded samples inside the acceleration t_a")
    out = {"time_s": t[keep], "runner_velocity_m_per_s": result.runner_velocity[keep],
           "runner_position_m": result.runner_position[keep], "piezo_position_m": result.piezo_position[keep],
           "flyback_start_s": period - flyback, "flyback_end_s": period, "acceleration_start_s": start_a,
           "acceleration_end_s": end_a, "record_spacing_s": float(np.max(np.diff(inside))),
           "wall_time_s": result.wall_time}
    for g in range(result.multiplicity.size):
        out[f"slip_share_{g + 1}"] = result.slip_share[g][keep]
    return out
