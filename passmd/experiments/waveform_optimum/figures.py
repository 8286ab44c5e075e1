"""Beyond the paper: the settling time, a numerical optimum of (t_s, V_a, Δ_a), flexible actuators.

Section 6's outlook asks how the actuators' dynamics affect the new waveform; a replication
also has to say how much Eq. 15's heuristic leaves on the table. Built on the runs of
:mod:`passmd.protocols.section5` at the Section 5 drive of :mod:`passmd.experiments.driving_waveform.figures`
(same drives, designs, protocols and cache):

* :func:`settling_scan` — the 100 Hz step against the settling time t_s (:func:`settling_scans`: with
  Eq. 15's acceleration and with the optimum's);
* :func:`numerical_optimum` — scipy's differential evolution over (t_s, V_a, Δ_a) against
  the Eq. 15 design and the saw-tooth, at a few frequencies;
* :func:`flexible_study` — the same comparison with flexible actuators.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd.experiments import FigureSpec
from passmd.experiments.driving_waveform.figures import section5_fields
from passmd.model import optimized_waveform
from passmd.model.tables import Assumption
from passmd.protocols.section5 import (
    STEP_FREQUENCY,
    VARIANTS,
    design_fields,
    designs,
    make_design,
    section5_drive,
    velocity_columns,
)
from passmd.protocols.velocity import (
    STEP_PERIODS,
    STEP_PROTOCOL_BELOW,
    step_run,
    waveform_velocity,
)
from passmd.runtime import sweep
from passmd.runtime.config import RunConfig


def step_point(hemisphere_radius: float, preload: float, runner: str, actuator_model: str,
               frequency: float, waveform: str, settling_time: float, acceleration_time: float,
               acceleration_amplitude: float, friction_coefficient: float,
               periods: int = STEP_PERIODS) -> dict:
    """Fig. 9a protocol (:func:`passmd.protocols.velocity.step_run`), Section 5 drive, full amplitude."""
    drive = section5_drive(hemisphere_radius, preload, runner, actuator_model, friction_coefficient)
    design = None if waveform == "sawtooth" else make_design(
        settling_time, acceleration_time, acceleration_amplitude)
    return step_run(drive, drive.actuator.full_stroke_amplitude, frequency, waveform, design, periods)


#: Differential-evolution budgets (population size factor, generations) per profile.
OPTIMIZER_BUDGET = {"paper": (10, 30), "quick": (5, 4)}

#: Frequencies of the numerical optimisation per profile (Hz), rigid and flexible actuators.
OPTIMUM_FREQUENCIES = {
    "paper": {"rigid": (STEP_FREQUENCY, 1e3, 10e3, 50e3, 110e3), "flexible": (STEP_FREQUENCY,)},
    "quick": {"rigid": (STEP_FREQUENCY, 110e3), "flexible": ()},
}


#: Frequencies of the flexible-actuator study per profile (Hz).
FLEXIBLE_FREQUENCIES = {"paper": (STEP_FREQUENCY, 1e3, 10e3, 50e3, 110e3), "quick": (STEP_FREQUENCY, 110e3)}

#: Points of the settling-time scan over [0, 2/f_s] per profile.
SCAN_POINTS = {"paper": 41, "quick": 9}

ASSUMPTIONS: tuple[Assumption, ...] = (
    Assumption(
        key="waveform_optimizer",
        symbol="t_s, V_a, Δ_a",
        value=(
            "scipy differential evolution (seed 0) over t_s ∈ [0, min(1.5/f_s, T/2)], "
            "V_a ∈ [0.01, 1]·V_max (log), Δ_a ∈ [0.02, 0.95]·A; objective the velocity of the "
            f"chapter's protocol (< {STEP_PROTOCOL_BELOW / 1e3:g} kHz: 3 periods, mean step × f; "
            "above: steady)"
        ),
        unit="–",
        rationale=(
            "The paper's outlook: how much does Eq. 15's heuristic leave on the table? The three "
            "numbers of Fig. 8b are kept, only chosen by the optimiser instead of Eq. 15; the "
            "amplifier's slew-rate limit bounds V_a, the period bounds t_s."
        ),
        sensitivity="Chapter Beyond Eq. (15): the optimum's parameters per frequency.",
    ),
)


def optimum_point(hemisphere_radius: float, preload: float, runner: str, actuator_model: str,
                  frequency: float, settling_time: float, acceleration_time: float,
                  acceleration_amplitude: float, micro_vibration_frequency: float, popsize: int,
                  maxiter: int, friction_coefficient: float, seed: int = 0) -> dict:
    """Best (t_s, V_a, Δ_a) for the velocity at one frequency, by differential evolution.

    The given design (Eq. 15, with its measured f_s) is evaluated by the same protocol for
    comparison, and so is the saw-tooth (assumption ``waveform_optimizer``).

    Returns
    -------
    dict
        ``velocity_sawtooth_m_per_s``, ``velocity_eq15_m_per_s``, ``velocity_optimum_m_per_s``,
        the optimum's ``optimum_settling_time_s``, ``optimum_acceleration_velocity_m_per_s``,
        ``optimum_acceleration_amplitude_m``, ``optimum_acceleration_time_s``, ``evaluations``.
    """
    from scipy.optimize import differential_evolution

    drive = section5_drive(hemisphere_radius, preload, runner, actuator_model, friction_coefficient)
    amplitude = drive.actuator.full_stroke_amplitude
    v_max = optimized_waveform.max_piezo_velocity(drive)
    period = 1.0 / frequency
    t_s_max = min(1.5 / micro_vibration_frequency, 0.5 * period)

    def unpack(x):
        t_s, log_va, share = x
        v_a = v_max * 10.0**log_va
        d_a = share * amplitude
        return optimized_waveform.OptimizedDesign(t_s * t_s_max, d_a / v_a, d_a)

    count = [0]

    def objective(x):
        count[0] += 1
        return -waveform_velocity(drive, amplitude, frequency, "optimized", unpack(x)) * 1e3

    found = differential_evolution(objective, bounds=[(0.0, 1.0), (-2.0, 0.0), (0.02, 0.95)], seed=seed,
                                   popsize=int(popsize), maxiter=int(maxiter), polish=False, tol=1e-3)
    best = unpack(found.x)
    heuristic = make_design(settling_time, acceleration_time, acceleration_amplitude)
    return {
        "velocity_sawtooth_m_per_s": waveform_velocity(drive, amplitude, frequency, "sawtooth"),
        "velocity_eq15_m_per_s": waveform_velocity(drive, amplitude, frequency, "optimized", heuristic),
        "velocity_optimum_m_per_s": -float(found.fun) / 1e3,
        "optimum_settling_time_s": best.settling_time,
        "optimum_acceleration_velocity_m_per_s": best.acceleration_velocity,
        "optimum_acceleration_amplitude_m": best.acceleration_amplitude,
        "optimum_acceleration_time_s": best.acceleration_time,
        "evaluations": count[0],
    }


def numerical_optimum(config: RunConfig) -> pd.DataFrame:
    """Differential evolution against Eq. 15's heuristic at a few frequencies (beyond the paper).

    One row per (actuator model, frequency) of :data:`OPTIMUM_FREQUENCIES`, with the
    velocities of the saw-tooth, the Eq. 15 design and the optimum (m/s and mm/s), the
    optimum's parameters and the settling time in cycles of f_s.
    """
    popsize, maxiter = OPTIMIZER_BUDGET[config.profile]
    points, cycles = [], []
    for model, frequencies in OPTIMUM_FREQUENCIES[config.profile].items():
        if not frequencies:
            continue
        c = section5_fields(actuator_model=model)
        d = designs([c], config).iloc[0]
        for f in frequencies:
            points.append({**c, "frequency": float(f), **design_fields(d),
                           "micro_vibration_frequency": float(d["micro_vibration_frequency_Hz"]),
                           "popsize": popsize, "maxiter": maxiter})
            cycles.append(float(d["micro_vibration_frequency_Hz"]))
    table = sweep.run(optimum_point, points, description="waveform optimisation", config=config)
    table["frequency_kHz"] = table["frequency"] / 1e3
    for name in ("sawtooth", "eq15", "optimum"):
        table[f"velocity_{name}_mm_per_s"] = table[f"velocity_{name}_m_per_s"] * 1e3
    table["optimum_settling_cycles"] = table["optimum_settling_time_s"] * np.array(cycles)
    table["left_on_table_mm_per_s"] = table["velocity_optimum_mm_per_s"] - table["velocity_eq15_mm_per_s"]
    return table


def settling_scan(config: RunConfig, acceleration_time: float | None = None,
                  acceleration_amplitude: float | None = None, actuator_model: str = "rigid") -> pd.DataFrame:
    """Step at 100 Hz (Fig. 9a protocol) against the settling time t_s ∈ [0, 2/f_s].

    t_a and Δ_a default to the Eq. 15 design; give others (e.g. the numerical optimum's) to
    scan with them. Adds ``settling_cycles`` (t_s·f_s), ``step_nm`` and the saw-tooth's
    ``sawtooth_step_nm`` for reference.
    """
    c = section5_fields(actuator_model=actuator_model)
    d = designs([c], config).iloc[0]
    f_s = float(d["micro_vibration_frequency_Hz"])
    t_a = float(d["acceleration_time_s"]) if acceleration_time is None else float(acceleration_time)
    d_a = (float(d["acceleration_amplitude_m"]) if acceleration_amplitude is None
           else float(acceleration_amplitude))
    points = [{**c, "frequency": STEP_FREQUENCY, "waveform": "optimized", "settling_time": float(t_s),
               "acceleration_time": t_a, "acceleration_amplitude": d_a}
              for t_s in np.linspace(0.0, 2.0 / f_s, SCAN_POINTS[config.profile])]
    points.append({**c, "frequency": STEP_FREQUENCY, "waveform": "sawtooth", "settling_time": 0.0,
                   "acceleration_time": 0.0, "acceleration_amplitude": 0.0})
    table = sweep.run(step_point, points, description="settling scan", config=config)
    saw = float(table["mean_step_m"].iloc[-1])
    table = table.iloc[:-1].copy()
    table["settling_cycles"] = table["settling_time"] * f_s
    table["settling_time_us"] = table["settling_time"] * 1e6
    table["step_nm"] = table["mean_step_m"] * 1e9
    table["sawtooth_step_nm"] = saw * 1e9
    table["eq15_settling_cycles"] = float(d["settling_time_s"]) * f_s
    return table


def flexible_study(config: RunConfig) -> pd.DataFrame:
    """Does the gain survive flexible actuators? (beyond the paper, Section 6's outlook).

    For rigid and flexible actuators (Table 2, ζ assumed), each with the Eq. 15 design made
    from its own saw-tooth response, and additionally the flexible drive driven with the
    rigid drive's design: velocity by the chapter's protocol
    (:func:`passmd.protocols.velocity.waveform_velocity`) at :data:`FLEXIBLE_FREQUENCIES`, for the
    saw-tooth and both optimized variants.
    """
    rigid, flexible = section5_fields(actuator_model="rigid"), section5_fields(actuator_model="flexible")
    made = designs([rigid, flexible], config)
    cases = [(rigid, "rigid", made.iloc[0]), (flexible, "flexible", made.iloc[1]),
             (flexible, "rigid", made.iloc[0])]
    points = []
    for c, source, d in cases:
        for f in FLEXIBLE_FREQUENCIES[config.profile]:
            for waveform, rule in VARIANTS:
                if waveform == "sawtooth" and source != c["actuator_model"]:
                    continue
                points.append({**c, "frequency": float(f), "waveform": waveform, "short_period": rule,
                               **design_fields(d), "design_from": source})
    table = sweep.run(study_point, points, description="flexible study", config=config)
    return velocity_columns(table)


def study_point(hemisphere_radius: float, preload: float, runner: str, actuator_model: str, frequency: float,
                waveform: str, short_period: str, settling_time: float, acceleration_time: float,
                acceleration_amplitude: float, design_from: str, friction_coefficient: float) -> dict:
    """Velocity of one case of :func:`flexible_study` (``design_from`` labels the design's drive)."""
    drive = section5_drive(hemisphere_radius, preload, runner, actuator_model, friction_coefficient)
    design = None if waveform == "sawtooth" else make_design(
        settling_time, acceleration_time, acceleration_amplitude)
    v = waveform_velocity(drive, drive.actuator.full_stroke_amplitude, frequency, waveform, design,
                          short_period)
    return {"velocity_m_per_s": v}


def optimum_at(optimum: pd.DataFrame, frequency: float = STEP_FREQUENCY, actuator_model: str = "rigid"
               ) -> pd.Series:
    """The :func:`numerical_optimum` row of one actuator model at one frequency (default: rigid,
    100 Hz)."""
    rows = optimum[(optimum["actuator_model"] == actuator_model) & (optimum["frequency"] == frequency)]
    return rows.iloc[0]


def settling_scans(config: RunConfig) -> pd.DataFrame:
    """Step at 100 Hz against the settling time, with Eq. 15's acceleration and with the optimum's.

    The two :func:`settling_scan` tables, tagged with a
    ``series`` label: Eq. 15's t_a and Δ_a, and the acceleration time and amplitude of the
    numerical optimum at 100 Hz (:func:`optimum_at`).
    """
    low = optimum_at(numerical_optimum(config))
    scans = {
        "Eq. 15's t_a, Δ_a": settling_scan(config),
        "optimum's V_a, Δ_a (100 Hz)": settling_scan(config, low["optimum_acceleration_time_s"],
                                                     low["optimum_acceleration_amplitude_m"]),
    }
    return pd.concat([scan.assign(series=label) for label, scan in scans.items()], ignore_index=True)


#: The chapter's rows of the figure table.
FIGURES = tuple(FigureSpec(name, title, "waveform_optimum", compute, f"driving_waveform:{plot}") for
                name, title, compute, plot in (
    ("study_settling_scan", "Step at 100 Hz against the settling time, Eq. 15's and the optimum's "
     "acceleration (beyond the paper)", settling_scans, "plot_settling_scans"),
    ("study_optimum", "Velocity of Eq. 15's design and of a numerical optimum relative to the "
     "saw-tooth (beyond the paper)", numerical_optimum, "plot_optimum"),
    ("study_flexible", "Gain of the optimized waveform with rigid and flexible actuators "
     "(beyond the paper)", flexible_study, "plot_flexible"),
))
