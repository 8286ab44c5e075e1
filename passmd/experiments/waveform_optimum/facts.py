"""Facts the chapter beyond the paper reads from its studies: the numerical optimum, flexible actuators.

Small functions of the studies' tidy tables (:mod:`passmd.experiments.waveform_optimum.figures`) that
return the numbers and tables the chapter glues into its prose. Display units: nm, µs, kHz, mm/s, %.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd.experiments.driving_waveform.figures import section5_fields
from passmd.experiments.waveform_optimum.figures import optimum_at, step_point
from passmd.protocols.section5 import STEP_FREQUENCY


def optimum_table(optimum: pd.DataFrame) -> pd.DataFrame:
    """The :func:`~passmd.experiments.waveform_optimum.figures.numerical_optimum` table as the chapter
    shows it
    (mm/s, nm, cycles of f_s)."""
    shown = optimum[["actuator_model", "frequency_kHz", "velocity_sawtooth_mm_per_s",
                     "velocity_eq15_mm_per_s", "velocity_optimum_mm_per_s", "left_on_table_mm_per_s",
                     "optimum_settling_cycles", "optimum_acceleration_velocity_m_per_s",
                     "optimum_acceleration_amplitude_m", "evaluations"]].copy()
    shown["optimum_acceleration_velocity_m_per_s"] *= 1e3
    shown["optimum_acceleration_amplitude_m"] *= 1e9
    return shown.rename(columns={"optimum_acceleration_velocity_m_per_s": "V_a (mm/s)",
                                 "optimum_acceleration_amplitude_m": "Δ_a (nm)",
                                 "optimum_settling_cycles": "t_s·f_s"})


def optimum_facts(optimum: pd.DataFrame, design: pd.Series, a_f: float) -> dict:
    """The rigid optimum at 100 Hz against the saw-tooth and the Eq. 15 ``design`` (a
    :func:`~passmd.protocols.section5.designs` row): its gain (%), t_s (cycles), V_a
    (mm/s), Δ_a (nm), t_a (µs and × Eq. 15's), the slide V_a²/2a_f (nm, ``a_f`` the friction
    acceleration), Eq. 15's V_a over the optimum's, the gain per period (nm); and the gain (%) at
    the highest frequency optimised (kHz)."""
    low = optimum_at(optimum)
    high = optimum[optimum["actuator_model"] == "rigid"].iloc[-1]
    return {
        "opt_gain_100": 100 * (low["velocity_optimum_m_per_s"] / low["velocity_sawtooth_m_per_s"] - 1),
        "opt_ts_cycles": low["optimum_settling_cycles"],
        "opt_va_mm_s": low["optimum_acceleration_velocity_m_per_s"] * 1e3,
        "opt_da_nm": low["optimum_acceleration_amplitude_m"] * 1e9,
        "opt_ta_us": low["optimum_acceleration_time_s"] * 1e6,
        "ta_ratio": low["optimum_acceleration_time_s"] / design["acceleration_time_s"],
        "slide_nm": low["optimum_acceleration_velocity_m_per_s"] ** 2 / (2 * a_f) * 1e9,
        "va_ratio": design["acceleration_velocity_m_per_s"] / low["optimum_acceleration_velocity_m_per_s"],
        "gain_nm": ((low["velocity_optimum_m_per_s"] - low["velocity_sawtooth_m_per_s"])
                    / STEP_FREQUENCY * 1e9),
        "opt_gain_hi": 100 * (high["velocity_optimum_m_per_s"] / high["velocity_sawtooth_m_per_s"] - 1),
        "opt_hi_kHz": high["frequency_kHz"],
    }


def carried_steps(optimum: pd.DataFrame) -> pd.DataFrame:
    """Step at 100 Hz (Fig. 9a protocol) of the saw-tooth and of the rigid drive's 100 Hz optimum, on
    rigid and flexible actuators (nm), and the optimum's gain (%)."""
    low = optimum_at(optimum)
    carry = {"settling_time": low["optimum_settling_time_s"],
             "acceleration_time": low["optimum_acceleration_time_s"],
             "acceleration_amplitude": low["optimum_acceleration_amplitude_m"]}
    none = {"settling_time": 0.0, "acceleration_time": 0.0, "acceleration_amplitude": 0.0}
    rows = []
    for model in ("rigid", "flexible"):
        step = {waveform: step_point(**section5_fields(actuator_model=model), frequency=STEP_FREQUENCY,
                                     waveform=waveform, **fields)["mean_step_m"]
                for waveform, fields in (("sawtooth", none), ("optimized", carry))}
        rows.append({"actuators": model, "saw-tooth step (nm)": step["sawtooth"] * 1e9,
                     "rigid optimum's step (nm)": step["optimized"] * 1e9,
                     "gain (%)": 100 * (step["optimized"] / step["sawtooth"] - 1)})
    return pd.DataFrame(rows)


def flexible_facts(optimum: pd.DataFrame, flexible_design: pd.Series, carried: pd.DataFrame, drive) -> dict:
    """Flexible actuators: their design's f_s (kHz) and its ratio to the linear estimate, the rigid
    optimum's gain on them (%, from :func:`carried_steps`), the actuators' natural frequency (MHz,
    ``drive`` made flexible), the rigid optimum's t_a (µs) and what the optimum found on the
    flexible drive itself gains (``flex_opt_text``, a sentence: the profile may not optimise it)."""
    flexible = optimum[optimum["actuator_model"] == "flexible"]
    if len(flexible):
        row = flexible.iloc[0]
        gain = 100 * (row["velocity_optimum_m_per_s"] / row["velocity_sawtooth_m_per_s"] - 1)
        opt_text = (f"Differential evolution run on the flexible drive itself finds {gain:.0f} % at "
                    f"{row['frequency_kHz']:g} kHz.")
    else:
        opt_text = ("This build's profile does not run differential evolution on the flexible drive itself "
                    "(the paper profile does).")
    return {
        "f_s_flex_kHz": flexible_design["micro_vibration_frequency_Hz"] / 1e3,
        "f_ratio_flex": (flexible_design["micro_vibration_frequency_Hz"]
                         / flexible_design["linear_frequency_Hz"]),
        "flex_carry_gain": carried.iloc[1]["gain (%)"],
        "actuator_MHz": drive.replace(actuator_model="flexible").actuator.natural_frequency / 1e6,
        "carry_us": optimum_at(optimum)["optimum_acceleration_time_s"] * 1e6,
        "flex_opt_text": opt_text,
    }


def scan_facts(scans: pd.DataFrame) -> dict:
    """The settling scans (:func:`~passmd.experiments.waveform_optimum.figures.settling_scans`): where on
    the scan's grid the step with Eq. 15's acceleration is smallest and largest and where the step with
    the optimum's acceleration is largest (cycles of f_s), the scan's spacing (cycles) and how far the
    latter's step rises above the saw-tooth's there (nm)."""
    eq15, slow = (part.sort_values("settling_cycles") for _, part in scans.groupby("series", sort=False))
    best = slow.loc[slow["step_nm"].idxmax()]
    return {"scan_eq15_min_cycles": eq15.loc[eq15["step_nm"].idxmin(), "settling_cycles"],
            "scan_eq15_max_cycles": eq15.loc[eq15["step_nm"].idxmax(), "settling_cycles"],
            "scan_slow_max_cycles": best["settling_cycles"],
            "scan_slow_gain_nm": best["step_nm"] - best["sawtooth_step_nm"],
            "scan_spacing_cycles": float(np.diff(eq15["settling_cycles"]).min())}
