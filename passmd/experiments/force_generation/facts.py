"""Facts the force-generation chapter reads from the Fig. 7 data (Section 4.2).

Small functions of the figures' tidy tables (:mod:`passmd.experiments.force_generation.figures`) that
return the numbers, tables and series the chapter glues into its prose: the models' curves and
full-stroke forces, their difference against the paper's, the onsets, the stall-cycle measures
(the deflection swing of the actuators and the stroke it costs), the preload grid and the
frequency scatter. Display units: nm, mN, µm, Hz, %.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from passmd.experiments.force_generation.figures import (
    CYCLE_DRIVE,
    EARLIER,
    FORCE_FREQUENCY,
    PANELS,
    PANELS_FULL_STROKE_NM,
    THIS,
    force_difference,
    force_drive,
)
from passmd.model.theory import normal_forces, runner_frequency
from passmd.protocols import stall

#: Columns of the figure data that are timings of this machine, left out of the published data.
TIMING_COLUMNS = ("cpu_time_s", "onset_cpu_time_s")


def published(frame: pd.DataFrame) -> pd.DataFrame:
    """A figure's data as the book publishes it: without the machine's timings."""
    return frame.drop(columns=list(TIMING_COLUMNS), errors="ignore")


def stall_protocol_facts() -> dict:
    """The stall protocol's settings in the chapter's units: drive frequency (Hz), window and half
    window (periods), absolute (mN) and relative (%) tolerance, first and largest run (periods)."""
    return {"f_drive": FORCE_FREQUENCY, "window": stall.STALL_WINDOW, "half_window": stall.STALL_WINDOW // 2,
            "abs_tol_mN": stall.STALL_ABS_TOLERANCE * 1e3, "rel_tol_pct": stall.STALL_REL_TOLERANCE * 100,
            "max_periods": stall.MAX_PERIODS, "initial_periods": stall.INITIAL_PERIODS}


def model_curve(frame: pd.DataFrame, model: tuple, preload: float) -> pd.DataFrame:
    """The rows of one (actuator model, μ) at one preload, sorted by amplitude."""
    sel = frame[(frame["actuator_model"] == model[0]) & np.isclose(frame["friction_coefficient"], model[1])
                & np.isclose(frame["preload_N"], preload)]
    return sel.sort_values("amplitude_nm")


def drive_facts(preload: float = max(PANELS["fig7a"][1])) -> dict:
    """Load-cell stiffness k (N/m), the runner's swing on the load cell alone (Hz) and its linear
    frequency on the contacts (kHz) for the Fig. 7a drive (R = 1 mm, flexible, μ = 0.2)."""
    drive = force_drive(PANELS["fig7a"][0], preload, *THIS)
    k = drive.load_cell_stiffness
    return {"k": k, "f_load_cell": float(np.sqrt(k / drive.runner_mass) / (2 * np.pi)),
            "f_runner_kHz": runner_frequency(drive) / 1e3}


def stall_summary(frames) -> dict:
    """Points, stalled points and the least and most periods over the given figure frames."""
    panels = pd.concat(list(frames))
    return {"n_points": len(panels), "n_converged": int(panels["converged"].sum()),
            "periods_min": int(panels["periods"].min()), "periods_max": int(panels["periods"].max())}


def full_stroke_row(frame: pd.DataFrame, model: tuple, preload: float) -> pd.Series:
    """The run of one model at one preload at the largest amplitude of the frame."""
    return model_curve(frame, model, preload).iloc[-1]


def full_stroke_facts(fig7a: pd.DataFrame, paper_difference_mN: float) -> dict:
    """Fig. 7a at its higher preload and the full stroke: both models' forces (mN), the runner travel
    F_gen/k of this paper's model (µm), its periods and following force (mN), and the difference of
    the two models against the paper's (``paper_difference_mN``, the 115 mN claim)."""
    preload = max(PANELS["fig7a"][1])
    k = drive_facts(preload)["k"]
    this, earlier = full_stroke_row(fig7a, THIS, preload), full_stroke_row(fig7a, EARLIER, preload)
    diff = force_difference(fig7a, preload)
    at_full = diff[np.isclose(diff["amplitude_nm"], PANELS_FULL_STROKE_NM["fig7a"])]
    difference = at_full["difference_mN"].iloc[0]
    return {
        "F_full_flex_mN": this["generated_force_mN"], "F_full_rigid_mN": earlier["generated_force_mN"],
        "x_full_um": this["generated_force_mN"] * 1e-3 / k * 1e6, "periods_full_flex": int(this["periods"]),
        "piezo_full_mN": this["piezo_mean_force_mN"], "diff_full_mN": difference,
        "diff_full_dev_pct": 100 * abs(difference - paper_difference_mN) / paper_difference_mN,
    }


def band_difference(fig7freq: pd.DataFrame, low: float = 80.0, high: float = 120.0,
                    radius_mm: float = PANELS["fig7a"][0] * 1e3) -> pd.Series:
    """F_gen(rigid) − F_gen(flexible) at the full stroke at each frequency in [low, high] Hz (mN)."""
    band = fig7freq[np.isclose(fig7freq["radius_mm"], radius_mm) & (fig7freq["frequency_Hz"] >= low)
                    & (fig7freq["frequency_Hz"] <= high)]
    pivot = band.pivot_table(index="frequency_Hz", columns="actuator_model", values="generated_force_mN")
    return pivot["rigid"] - pivot["flexible"]


def panel_full_stroke(frame: pd.DataFrame, name: str) -> dict:
    """F_gen of both models at the full stroke for each preload of a Fig. 7 panel (mN), keyed
    ``"<preload>_rigid"``/``"<preload>_flexible"`` with the preload written without its dot."""
    out = {}
    for preload in PANELS[name][1]:
        tag = f"{preload:g}".replace(".", "")
        out[f"{tag}_rigid"] = full_stroke_row(frame, EARLIER, preload)["generated_force_mN"]
        out[f"{tag}_flex"] = full_stroke_row(frame, THIS, preload)["generated_force_mN"]
    return out


def panel_differences(data: dict) -> dict:
    """:func:`~passmd.experiments.force_generation.figures.force_difference` of every preload of both Fig. 7
    panels, keyed ``"<panel> <preload> N"``."""
    return {f"{name} {p:g} N": force_difference(data[name], p) for name in PANELS for p in PANELS[name][1]}


def onset_table(panels: pd.DataFrame) -> pd.DataFrame:
    """Simulated and closed-form (Eq. 11 rigid, Eq. 12 flexible) onsets of each curve (nm)."""
    return (panels.drop_duplicates(["radius_mm", "preload_N", "actuator_model", "friction_coefficient"])
            [["radius_mm", "preload_N", "actuator_model", "friction_coefficient", "onset_nm",
              "analytic_onset_nm"]])


def onset_ratios(onsets: pd.DataFrame) -> dict:
    """How far the rigid model's onset lies above the flexible one's (%), simulated and closed form."""
    wide = onsets.pivot_table(index=["radius_mm", "preload_N"], columns="actuator_model",
                              values=["onset_nm", "analytic_onset_nm"])
    sim = (wide[("onset_nm", "rigid")] / wide[("onset_nm", "flexible")] - 1) * 100
    eq = (wide[("analytic_onset_nm", "rigid")] / wide[("analytic_onset_nm", "flexible")] - 1) * 100
    return {"onset_ratio_min": sim.min(), "onset_ratio_max": sim.max(), "eq_ratio_min": eq.min(),
            "eq_ratio_max": eq.max()}


def difference_above_onsets(data: dict, differences: dict) -> dict:
    """The model difference from the amplitude where both models generate force on, per preload,
    as ``{"x": amplitudes_nm, "y": differences_mN}`` for :func:`passmd.ledger.checks.check_trend`."""
    above = {}
    for key, d in differences.items():
        name, p = key.split()[0], float(key.split()[1])
        rows = data[name][np.isclose(data[name]["preload_N"], p)]
        part = d[d["amplitude_nm"] >= rows["onset_nm"].max()]
        above[key] = {"x": part["amplitude_nm"].to_numpy(), "y": part["difference_mN"].to_numpy()}
    return above


def _cycle_runs(cycle: pd.DataFrame) -> pd.DataFrame:
    return cycle.drop_duplicates(["actuator_model", "friction_coefficient"]).set_index(
        ["actuator_model", "friction_coefficient"])


def deflection_swing(cycle: pd.DataFrame, model: str, mu: float, side: int) -> float:
    """Deflection swing of an actuator in the fly-back (nm): from T/k_p (measured before the
    fly-back) to −μF_N/k_p (sliding contact); zero for rigid actuators."""
    if model == "rigid":
        return 0.0
    preload = float(cycle["preload_N"].iloc[0])
    forces = np.asarray(normal_forces(preload, 6), dtype=float)
    k_p = force_drive(CYCLE_DRIVE[0], preload, "flexible", 0.2).actuator.stiffness
    before = _cycle_runs(cycle).loc[(model, mu), f"deflection_before_flyback_side{side}_nm"]
    return before + mu * forces[side - 1] / k_p * 1e9


def cycle_measures(cycle: pd.DataFrame) -> pd.DataFrame:
    """One row per run of the stall-cycle figure: F_gen against Σ μF_N, deflections, back-slide, slip."""
    runs = _cycle_runs(cycle)
    return pd.DataFrame({
        "actuator": [m for m, _ in runs.index],
        "μ": [mu for _, mu in runs.index],
        "F_gen [mN]": runs["generated_force_mN"].to_numpy(),
        "Σ μF_N [mN]": runs["sliding_capacity_mN"].to_numpy(),
        "F_gen / Σ μF_N": (runs["generated_force_mN"] / runs["sliding_capacity_mN"]).to_numpy(),
        "T/k_p before fly-back, side 1 / 2 [nm]": [
            f"{a:.1f} / {b:.1f}" for a, b in zip(runs["deflection_before_flyback_side1_nm"],
                                                 runs["deflection_before_flyback_side2_nm"], strict=True)],
        "swing T/k_p + μF_N/k_p, side 1 / 2 [nm]": [
            f"{deflection_swing(cycle, m, mu, 1):.1f} / {deflection_swing(cycle, m, mu, 2):.1f}"
            for m, mu in runs.index],
        "back-slide [nm]": runs["back_slide_nm"].to_numpy(),
        "full sliding [µs]": runs["full_slip_time_us"].to_numpy(),
        "mean slip share, side 1 / 2": [
            f"{a:.3f} / {b:.3f}" for a, b in zip(runs["mean_slip_share_side1"], runs["mean_slip_share_side2"],
                                                 strict=True)],
    })


def cycle_facts(cycle: pd.DataFrame) -> dict:
    """Stall forces of the four combinations (mN), the effect of μ and of the actuators' flexibility,
    F_gen / Σ μF_N of the rigid runs, the largest mean slip share (%), sample spacing (µs), preload
    (N) and amplitude (nm) of the stall-cycle figure."""
    runs = _cycle_runs(cycle)
    force = runs["generated_force_mN"]
    ratio = runs["generated_force_mN"] / runs["sliding_capacity_mN"]
    return {
        "F_r03": force[("rigid", 0.3)], "F_r02": force[("rigid", 0.2)],
        "F_f03": force[("flexible", 0.3)], "F_f02": force[("flexible", 0.2)],
        "mu_effect_rigid": force[("rigid", 0.3)] - force[("rigid", 0.2)],
        "mu_effect_flex": force[("flexible", 0.3)] - force[("flexible", 0.2)],
        "flex_effect_03": force[("rigid", 0.3)] - force[("flexible", 0.3)],
        "flex_effect_02": force[("rigid", 0.2)] - force[("flexible", 0.2)],
        "ratio_r03": ratio[("rigid", 0.3)], "ratio_r02": ratio[("rigid", 0.2)],
        "spacing_us": float(cycle["sample_spacing_us"].iloc[0]),
        "cycle_preload": float(cycle["preload_N"].iloc[0]),
        "slip_max_pct": 100 * float(
            runs[["mean_slip_share_side1", "mean_slip_share_side2"]].to_numpy().max()),
        "a_full": float(cycle["amplitude_nm"].iloc[0]),
    }


def equivalent_stroke(fig7a: pd.DataFrame, cycle: pd.DataFrame) -> dict:
    """The amplitude at which the rigid μ = 0.3 drive of Fig. 7a stalls at the flexible μ = 0.3 stall
    force of the cycle figure (interpolated between stalled amplitudes above the onset; nan when the
    curve does not bracket it monotonically), the stroke lost (nm) against the swing of each side
    (:func:`deflection_swing`), and whether loss and side-1 swing agree within 25 %."""
    preload = float(cycle["preload_N"].iloc[0])
    curve = model_curve(fig7a, EARLIER, preload)
    curve = curve[curve["converged"] & (curve["amplitude_nm"] >= curve["onset_nm"])]
    target = _cycle_runs(cycle)["generated_force_mN"][("flexible", 0.3)]
    monotone = bool(np.all(np.diff(curve["generated_force_mN"].to_numpy()) > 0))
    inside = curve["generated_force_mN"].min() <= target <= curve["generated_force_mN"].max()
    a_eq = (float(np.interp(target, curve["generated_force_mN"], curve["amplitude_nm"]))
            if monotone and inside else math.nan)
    a_full = float(cycle["amplitude_nm"].iloc[0])
    swing1, swing2 = deflection_swing(cycle, "flexible", 0.3, 1), deflection_swing(cycle, "flexible", 0.3, 2)
    loss = a_full - a_eq
    return {"a_eq_nm": a_eq, "a_full_nm": a_full, "loss_nm": loss, "swing1_nm": swing1, "swing2_nm": swing2,
            "agrees": bool(abs(loss - swing1) <= 0.25 * swing1), "curve_points": len(curve)}


def grid_facts(grid: pd.DataFrame) -> dict:
    """At the grid's largest amplitude: at how many of the preloads the earlier model generates more
    force, the exceptions ``under`` as (radius mm, preload N), and how many grid points stalled."""
    top = grid[np.isclose(grid["amplitude_fraction"], grid["amplitude_fraction"].max())]
    wide = top.pivot_table(index=["radius_mm", "preload_N"], columns="actuator_model",
                           values="generated_force_mN")
    over = wide["rigid"] > wide["flexible"]
    return {"n_over": int(over.sum()), "n_all": len(over), "under": list(wide[~over].index),
            "grid_converged": int(grid["converged"].sum()), "grid_points": len(grid)}


def frequency_spread(fig7freq: pd.DataFrame, low: float, high: float) -> dict:
    """Largest relative spread of F_gen over the frequencies in [low, high] Hz, per radius and model.

    ``spread_pct`` (max − min over the mean, %), ``frequencies`` (how many lie in the band) and
    the band's lowest and highest frequency ``low_Hz``, ``high_Hz``.
    """
    sel = fig7freq[(fig7freq["frequency_Hz"] >= low) & (fig7freq["frequency_Hz"] <= high)]
    forces = sel.groupby(["radius_mm", "actuator_model"])["generated_force_mN"]
    rel = forces.agg(lambda v: np.ptp(v) / np.mean(v))
    return {"spread_pct": 100 * rel.max(), "frequencies": sel["frequency_Hz"].nunique(),
            "low_Hz": sel["frequency_Hz"].min(), "high_Hz": sel["frequency_Hz"].max()}


def stall_cpu_seconds(data: dict) -> float:
    """CPU time of the stall runs and onset searches of the Fig. 7 tables (s; onsets once per table)."""
    cpu = sum(float(data[n]["cpu_time_s"].sum()) for n in ("fig7a", "fig7b", "fig7grid", "fig7freq"))
    cpu += sum(float(data[n]["onset_cpu_time_s"].drop_duplicates().sum())
               for n in ("fig7a", "fig7b", "fig7grid"))
    return cpu
