"""Facts the driving-waveform chapter reads from the data of Figs. 8 and 9a (Section 5.1).

Small functions of the figures' tidy tables (:mod:`passmd.experiments.driving_waveform.figures`) that
return the numbers and tables the chapter glues into its prose: the Eq. 15 design, the response of
Fig. 8a, the slip during the accelerations of Fig. 9b's runs, the resolved fly-back window and the
positions of Fig. 9a. Display units: nm, µs, kHz, mm/s, %.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd.experiments.driving_waveform.figures import at_section5_friction
from passmd.model import theory, waveforms
from passmd.model.parameters import Drive
from passmd.protocols.section5 import STEP_FREQUENCY
from passmd.protocols.velocity import FULL_SLIDING_SHARE


def friction_acceleration(drive: Drive) -> float:
    """Largest acceleration friction can give the runner, a_f = μ ΣF_N / m_r (m/s², six contacts)."""
    forces = theory.drive_theory(drive)["normal_force_N"]
    return drive.friction_coefficient * (2 * forces[0] + 4 * forces[1]) / drive.runner_mass


def design_facts(design: pd.Series, drive: Drive) -> dict:
    """The Eq. 15 design of a drive (a :func:`~passmd.protocols.section5.designs` row)
    and the
    drive's numbers behind it."""
    presliding = theory.drive_theory(drive)["presliding_m"]
    amplitude = drive.actuator.full_stroke_amplitude
    return {
        "f_s_kHz": design["micro_vibration_frequency_Hz"] / 1e3,
        "f_lin_kHz": design["linear_frequency_Hz"] / 1e3,
        "f_ratio": design["micro_vibration_frequency_Hz"] / design["linear_frequency_Hz"],
        "t_s_us": design["settling_time_s"] * 1e6, "t_a_us": design["acceleration_time_s"] * 1e6,
        "delta_a_nm": design["acceleration_amplitude_m"] * 1e9,
        "v_a_mm_s": design["acceleration_velocity_m_per_s"] * 1e3,
        "v_r_mm_s": design["runner_velocity_m_per_s"] * 1e3,
        "u_max_1_nm": presliding[0] * 1e9, "u_max_2_nm": presliding[1] * 1e9,
        "a_f": friction_acceleration(drive),
        "A_nm": amplitude * 1e9, "t_fb_us": waveforms.flyback_time(amplitude, drive) * 1e6,
    }


def design_table(design: pd.Series) -> pd.DataFrame:
    """The steps of the Eq. 15 design in display units, one row per quantity."""
    return pd.DataFrame({
        "quantity": ["f_s (measured)", "t_s = 1/(2 f_s)", "V_r (runner at the end of t_s)",
                     "u_x,max (side 2, Eq. 10)", "V_a (slew-rate limit)", "t_a = u_x,max/(V_a − V_r)",
                     "Δ_a = V_a t_a"],
        "value": [design["micro_vibration_frequency_Hz"] / 1e3, design["settling_time_s"] * 1e6,
                  design["runner_velocity_m_per_s"] * 1e3, design["presliding_m"] * 1e9,
                  design["acceleration_velocity_m_per_s"] * 1e3, design["acceleration_time_s"] * 1e6,
                  design["acceleration_amplitude_m"] * 1e9],
        "unit": ["kHz", "µs", "mm/s", "nm", "mm/s", "µs", "nm"],
    })


def fig8a_facts(fig8a_data: pd.DataFrame, drive: Drive) -> dict:
    """Fig. 8a: the first back-step (nm), reversal (point 3) and fastest forward motion (point 4) after
    the fly-back (µs), and each side's largest slip share on the way to the reversal, past the
    fly-back's own full sliding (two fly-back durations)."""
    points = fig8a_data[fig8a_data["view"] == "point"].set_index("point")
    period = 1 / STEP_FREQUENCY
    zoom = fig8a_data[fig8a_data["view"] == "zoom"]
    after_slip = period + 2 * waveforms.flyback_time(drive.actuator.full_stroke_amplitude, drive)
    swing = zoom[(zoom["time_s"] > after_slip) & (zoom["time_s"] <= points.loc["3", "time_s"])]
    return {"back_step_nm": fig8a_data["first_back_step_m"].iloc[0] * 1e9,
            "t3_after_us": (points.loc["3", "time_s"] - period) * 1e6,
            "t4_after_us": (points.loc["4", "time_s"] - period) * 1e6,
            "share3_side2": swing["slip_share_2"].max(), "share3_side1": swing["slip_share_1"].max()}


def acceleration_slip(fig9b_data: pd.DataFrame) -> dict:
    """Fig. 9b's optimized runs whose full settling time fits: their frequencies (kHz) and the least
    of their largest slip shares during the acceleration."""
    fits = fig9b_data[(fig9b_data["variant"] == "optimized") & fig9b_data["settling_fits"].astype(bool)]
    return {"share5": fits["max_slip_share_acceleration"].min(),
            "frequencies_kHz": list(fits["frequency_kHz"])}


def window_facts(window: pd.DataFrame) -> dict:
    """The resolved fly-back window: record spacing inside t_a (ns), the smaller of the two groups'
    largest slip shares in the fly-back and t_s, the largest slip share during t_a, and whether
    each reaches full sliding."""
    fly = window[window["phase"].isin(["flyback", "settling"])]
    flyback_share = fly[["slip_share_1", "slip_share_2"]].max(axis=0).min()
    acceleration = window.loc[window["phase"] == "acceleration", ["slip_share_1", "slip_share_2"]]
    acceleration_share = acceleration.to_numpy().max()
    return {"window_spacing_ns": window["record_spacing_s"].iloc[0] * 1e9,
            "window_flyback_share": flyback_share, "window_acceleration_share": acceleration_share,
            "flyback_full": bool(flyback_share >= FULL_SLIDING_SHARE),
            "acceleration_full": bool(acceleration_share >= FULL_SLIDING_SHARE)}


def fig9a_facts(fig9a_data: pd.DataFrame) -> dict:
    """Fig. 9a at Section 5's μ: positions after periods 1 and 3 (nm), the mean steps (nm) and the
    change of the position after three periods relative to the saw-tooth's travel (%)."""
    per = at_section5_friction(fig9a_data[fig9a_data["view"] == "period"])
    x = {w: p.sort_values("period")["settled_position_m"].to_numpy() for w, p in per.groupby("waveform")}
    return {"x3_saw_nm": x["sawtooth"][-1] * 1e9, "x3_opt_nm": x["optimized"][-1] * 1e9,
            "x1_nm": x["sawtooth"][0] * 1e9,
            "increase_pct": (100 * (x["optimized"][-1] - x["sawtooth"][-1])
                             / (x["sawtooth"][-1] - x["sawtooth"][0])),
            "step_saw_nm": np.mean(np.diff(x["sawtooth"])) * 1e9,
            "step_opt_nm": np.mean(np.diff(x["optimized"])) * 1e9}


def step_increase_pct(standard_nm: float, optimized_nm: float, amplitude_nm: float) -> float:
    """Increase of the travel after three periods, from positions that are A plus two steps (%)."""
    return 100 * (optimized_nm - standard_nm) / (standard_nm - amplitude_nm)
