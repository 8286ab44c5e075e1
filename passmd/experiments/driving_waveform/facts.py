"""Facts the driving-waveform chapter reads from the data of Figs. 8–10 and the studies (Section 5).

Small functions of the figures' tidy tables (:mod:`passmd.experiments.driving_waveform.figures`) and
of the studies beyond the paper (:mod:`passmd.experiments.driving_waveform.figures_studies`) that return
the numbers and tables the chapter glues into its prose: the Eq. 15 design, the response of Fig. 8a, the
resolved fly-back window, the positions of Fig. 9a, the velocities of Fig. 9b, the reachable
maxima of Fig. 10 and the numerical optimum on rigid and flexible actuators. Display units: nm,
µs, kHz, mm/s, %.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd.experiments.driving_waveform.figures import (
    FIG10A_PRELOADS,
    FULL_SLIDING_SHARE,
    PAPER_MAXIMUM_KHZ,
    at_section5_friction,
    range_maximum,
)
from passmd.experiments.driving_waveform.figures_runs import (
    STEP_FREQUENCY,
    section5_fields,
)
from passmd.experiments.driving_waveform.figures_studies import optimum_at, step_point
from passmd.model import theory, waveforms
from passmd.model.parameters import Drive


def friction_acceleration(drive: Drive) -> float:
    """Largest acceleration friction can give the runner, a_f = μ ΣF_N / m_r (m/s², six contacts)."""
    forces = theory.drive_theory(drive)["normal_force_N"]
    return drive.friction_coefficient * (2 * forces[0] + 4 * forces[1]) / drive.runner_mass


def design_facts(design: pd.Series, drive: Drive) -> dict:
    """The Eq. 15 design of a drive (a :func:`~passmd.experiments.driving_waveform.figures_runs.designs` row)
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


def startup_facts(fig9b_data: pd.DataFrame, frequency: float = PAPER_MAXIMUM_KHZ * 1e3) -> dict:
    """The saw-tooth's steady and first-to-last velocity at ``frequency`` (mm/s) and the largest
    drift between the third and fourth quarter of any Fig. 9b run (%)."""
    rows = fig9b_data[(fig9b_data["variant"] == "sawtooth") & np.isclose(fig9b_data["frequency"], frequency)]
    saw = rows.iloc[0]
    return {"v110_steady": saw["velocity_mm_per_s"], "v110_sim": saw["simulator_mean_velocity_m_per_s"] * 1e3,
            "max_drift_pct": np.nanmax(np.abs(fig9b_data["velocity_drift"])) * 100}


def fig9b_facts(fig9b_data: pd.DataFrame, design: pd.Series, drive: Drive) -> dict:
    """Fig. 9b: up to which frequency the full t_s fits (kHz); the room for t_s in a period at the
    paper's 110 kHz (µs), the f_s it would need (kHz) and the contact-stiffness factor that means; the
    optimized velocity there; the skip variant's largest gain up to 110 kHz (mm/s, %, kHz); the
    saw-tooth's step at the grid's ends (nm)."""
    opt = fig9b_data[fig9b_data["variant"] == "optimized"].set_index("frequency")
    saw = fig9b_data[fig9b_data["variant"] == "sawtooth"].set_index("frequency")
    skip = fig9b_data[fig9b_data["variant"] == "optimized_skip"].set_index("frequency")
    fits = opt.index[opt["settling_fits"].astype(bool)]
    paper_f = PAPER_MAXIMUM_KHZ * 1e3
    t_s_max = (1 / paper_f - waveforms.flyback_time(drive.actuator.full_stroke_amplitude, drive)
               - design["acceleration_time_s"])
    f_s_needed = 0.5 / t_s_max
    gain = (skip["velocity_mm_per_s"] - saw["velocity_mm_per_s"])[saw.index <= paper_f]
    return {"fit_limit_kHz": fits.max() / 1e3, "t_s_room_us": t_s_max * 1e6,
            "f_s_needed_kHz": f_s_needed / 1e3,
            "stiffness_factor": (f_s_needed / design["micro_vibration_frequency_Hz"]) ** 2,
            "v110_opt": opt.loc[paper_f, "velocity_mm_per_s"], "skip_gain_max": gain.max(),
            "skip_gain_f": gain.idxmax() / 1e3,
            "skip_gain_pct": 100 * gain.max() / saw.loc[gain.idxmax(), "velocity_mm_per_s"],
            "saw_step_1k": saw.loc[saw.index.min(), "step_nm"],
            "saw_step_130k": saw.loc[saw.index.max(), "step_nm"]}


def reachable_table(table: pd.DataFrame, key: str) -> pd.DataFrame:
    """Largest steady velocity of each value of ``key`` and waveform variant, where on the grid it lies
    (and whether at the grid's edge), the back-step there and the design's f_s."""
    rows = []
    for value, part in table.groupby(key, sort=False):
        for variant in ("sawtooth", "optimized", "optimized_skip"):
            series = part[part["variant"] == variant]
            best = range_maximum(series)
            edge = best["frequency_kHz"] in (series["frequency_kHz"].min(), series["frequency_kHz"].max())
            rows.append({key: value, "variant": variant, "max velocity (mm/s)": best["velocity_mm_per_s"],
                         "at (kHz)": best["frequency_kHz"], "at the grid's edge": edge,
                         "back-step there (nm)": best["back_step_nm"],
                         "f_s (kHz)": best["micro_vibration_frequency_Hz"] / 1e3})
    return pd.DataFrame(rows)


def stick_lost(fig10a_data: pd.DataFrame, preload: float = min(FIG10A_PRELOADS)) -> dict:
    """Frequencies (kHz) where the optimized waveform loses the stick during t_a at ``preload``:
    ``all`` of them and those ``with_full_settling`` (the full t_s fits)."""
    rows = fig10a_data[(fig10a_data["variant"] == "optimized") & np.isclose(fig10a_data["preload"], preload)]
    lost = rows[~rows["stick_during_acceleration"].astype(bool)]
    return {"all": list(lost["frequency_kHz"]),
            "with_full_settling": list(lost[lost["settling_fits"].astype(bool)]["frequency_kHz"])}


def optimum_table(optimum: pd.DataFrame) -> pd.DataFrame:
    """The :func:`~passmd.experiments.driving_waveform.figures_studies.numerical_optimum` table as the chapter
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
    :func:`~passmd.experiments.driving_waveform.figures_runs.designs` row): its gain (%), t_s (cycles), V_a
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
    ``drive`` made flexible), the rigid optimum's t_a (µs) and the gain of the optimum found on the
    flexible drive itself (%; nan when the profile does not optimise it)."""
    flexible = optimum[optimum["actuator_model"] == "flexible"]
    return {
        "f_s_flex_kHz": flexible_design["micro_vibration_frequency_Hz"] / 1e3,
        "f_ratio_flex": (flexible_design["micro_vibration_frequency_Hz"]
                         / flexible_design["linear_frequency_Hz"]),
        "flex_carry_gain": carried.iloc[1]["gain (%)"],
        "actuator_MHz": drive.replace(actuator_model="flexible").actuator.natural_frequency / 1e6,
        "carry_us": optimum_at(optimum)["optimum_acceleration_time_s"] * 1e6,
        "flex_opt_gain": (100 * (flexible.iloc[0]["velocity_optimum_m_per_s"]
                                 / flexible.iloc[0]["velocity_sawtooth_m_per_s"] - 1)
                          if len(flexible) else float("nan")),
    }


