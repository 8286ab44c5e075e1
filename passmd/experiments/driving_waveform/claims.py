"""Claim extractors of Section 5.1: the driving waveform's time series (Figs. 8 and 9a).

Decides the ledger's Section 5.1 rows (``passmd/data/reference/claims.csv``) from the time series
of Figs. 8 and 9a and the resolved fly-back window (``fig8b_window``): the saw-tooth's back step
and whether its micro-vibration dies within the next stick phase, the micro-vibration after the
optimized waveform's acceleration against the saw-tooth's f_s, t_a starting at the runner's
velocity maximum, stick during t_a, the contacts deformed to u_x,max after the fly-back, the
runner fastest at the end of t_a and slipping forward further than the hemispheres move
(Sub-phase II). Section 5.2's positions and velocities are in
:mod:`passmd.experiments.driving_waveform.claims_velocity`. Each extractor reads the figure tables
of :mod:`passmd.experiments.driving_waveform.figures` and returns what :mod:`passmd.ledger.checks`
compares with the paper; too few samples in a phase make the claim inconclusive.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd.experiments.driving_waveform.figures import (
    at_section5_friction,
)
from passmd.experiments.driving_waveform.runs import (
    SECTION5_FRICTION,
    WINDOW_SAMPLES_PER_ACCELERATION,
)
from passmd.ledger.checks import NotEvaluable, evidence, extractor
from passmd.protocols.velocity import FULL_SLIDING_SHARE

__all__ = ["optimized_period_timing"]


def _fig9a_run(results, waveform: str, reading=None) -> pd.DataFrame:
    """Fig. 9a's per-period rows of one waveform at a ledger reading's μ (default 0.2)."""
    mu = SECTION5_FRICTION if reading is None else float(reading["friction_coefficient"])
    table = at_section5_friction(results["fig9a"], mu)
    rows = table[(table["waveform"] == waveform) & (table["view"] == "period")].sort_values("period")
    if rows.empty:
        raise NotEvaluable(f"no Fig. 9a {waveform} run at μ = {mu:g}")
    return rows


#: Why the Fig. 8a back-step and the full sliding after the fly-back cannot fail: at 202 nm the
#: fly-back is six to ten times the presliding u_x,max of either contact side (31 and 20 nm at
#: 0.4 N, Eq. 10), so every contact slides fully and the friction it transmits while sliding pulls
#: the runner back. u_x,max scales as (E*, G*)^(-2/3), so this holds for any contact down to about
#: a sixteenth of the Table 1 stiffness (checked with E*, G* scaled 0.5x to 100x: back-step
#: 0.07-0.11 nm, both groups at slip share 1).
_FLYBACK_SLIDES = ("holds for any contact stiffness down to a sixteenth of Table 1's at 202 nm: the "
                   "fly-back is six to ten times the presliding u_x,max of either side (Eq. 10), so every "
                   "contact slides fully and drags the runner back; with E*, G* scaled 0.5x to 100x the "
                   "check still holds")


@extractor("fig8a-back-step", not_informative=_FLYBACK_SLIDES)
def _fig8a_back_step(results):
    return {"lhs": float(results["fig8a"]["first_back_step_m"].iloc[0]) * 1e9, "rhs": 0.0}


def optimized_period_timing(results) -> dict:
    """Timing of the runner in the optimized period of Fig. 8b (µs), from the zoomed trace.

    ``flyback_end`` (point 4 minus t_s), ``reversal`` (the runner's backward extreme between
    points 2 and 5, Section 5.1's point 3), ``point4`` (end of t_s, start of t_a), ``t_s`` and
    the design's ``f_s`` (Hz). Inconclusive when the trace or the points are missing.
    """
    table = results["fig8b"]
    points = table[table["view"] == "point"].set_index("point")
    zoom = table[table["view"] == "zoom"].sort_values("time_us")
    if zoom.empty or not {"2", "4", "5"} <= set(points.index.astype(str)):
        raise NotEvaluable("the Fig. 8b trace or its points 2, 4 and 5 are missing")
    points.index = points.index.astype(str)
    t2, t4, t5 = (float(points.at[p, "time_us"]) for p in ("2", "4", "5"))
    t_s = float(points.at["4", "settling_time_s"]) * 1e6
    window = zoom[(zoom["time_us"] >= t2) & (zoom["time_us"] <= t5)]
    if len(window) < 3:
        raise NotEvaluable("fewer than three trace samples between points 2 and 5")
    reversal = float(window.loc[window["runner_position_nm"].idxmin(), "time_us"])
    return {"flyback_end": t4 - t_s, "reversal": reversal, "point4": t4, "t_s": t_s,
            "f_s": float(points.at["4", "micro_vibration_frequency_Hz"])}


@extractor("sec5-response-to-optimized-similar")
def _response_similar(results):
    # Eq. 15 is designed from the saw-tooth's micro-vibration f_s; the response that matters is the
    # one after the two waveforms differ, i.e. after the acceleration t_a. Fig. 9a's optimized run
    # measures f_s after its first acceleration, the saw-tooth run after its first fly-back.
    f_s = {w: float(_fig9a_run(results, w)["micro_vibration_frequency_Hz"].iloc[0]) / 1e3
           for w in ("optimized", "sawtooth")}
    return {"lhs": f_s["optimized"], "rhs": f_s["sawtooth"]}


@evidence("sec5-response-to-optimized-similar")
def _response_similar_evidence(results):
    timing = optimized_period_timing(results)
    return [f"the runner reverses {timing['reversal'] - timing['flyback_end']:.2f} µs after the fly-back, "
            f"t_s = {timing['t_s']:.2f} µs (before t_a the two waveforms are the same)"]


@extractor("sec5-1-acceleration-starts-at-velocity-maximum")
def _acceleration_phase(results):
    timing = optimized_period_timing(results)
    return (timing["point4"] - timing["reversal"]) * 1e-6 * timing["f_s"]


@evidence("sec5-1-acceleration-starts-at-velocity-maximum")
def _acceleration_phase_evidence(results):
    t = optimized_period_timing(results)
    return [f"fly-back ends at {t['flyback_end']:.2f} µs, the runner reverses at {t['reversal']:.2f} µs, "
            f"t_s ends (point 4) at {t['point4']:.2f} µs; f_s = {t['f_s'] / 1e3:.4g} kHz"]


def _window_phase(results, phases: tuple[str, ...]) -> pd.DataFrame:
    """Rows of the resolved fly-back window (``fig8b_window``) in the given phases.

    Inconclusive when a phase holds fewer than :data:`WINDOW_SAMPLES_PER_ACCELERATION` // 2
    samples: the record then cannot resolve it.
    """
    table = results["fig8b_window"]
    rows = table[table["phase"].isin(phases)]
    for phase in phases:
        n = int((rows["phase"] == phase).sum())
        if n < WINDOW_SAMPLES_PER_ACCELERATION // 2:
            raise NotEvaluable(f"only {n} recorded samples in the {phase} phase of the fly-back window")
    return rows


@extractor("sec5-1-stick-during-acceleration")
def _stick_during_acceleration(results):
    # Section 5.1 chooses V_a so that the runner still sticks during t_a: no contact group may
    # reach full sliding (slip share 1) between points 4 and 5.
    rows = _window_phase(results, ("acceleration",))
    share = float(rows[["slip_share_1", "slip_share_2"]].to_numpy().max())
    return {"lhs": share, "rhs": FULL_SLIDING_SHARE}


@evidence("sec5-1-stick-during-acceleration")
def _stick_during_acceleration_evidence(results):
    rows = _window_phase(results, ("settling", "acceleration"))
    end_settling = rows[rows["phase"] == "settling"].iloc[-1]
    acc = rows[rows["phase"] == "acceleration"]
    first_full = acc.loc[acc[["slip_share_1", "slip_share_2"]].max(axis=1) >= FULL_SLIDING_SHARE, "time_s"]
    start = float(acc["acceleration_start_s"].iloc[0])
    lines = [f"slip shares at the end of t_s: side 1 {end_settling['slip_share_1']:.2f}, side 2 "
             f"{end_settling['slip_share_2']:.2f}"]
    if len(first_full):
        lines.append(f"a contact group slides fully {(float(first_full.iloc[0]) - start) * 1e9:.0f} ns into "
                     f"t_a = {(float(acc['acceleration_end_s'].iloc[0]) - start) * 1e9:.0f} ns")
    return lines


@extractor("sec5-1-spring-deformed-to-ux-max-after-flyback", not_informative=_FLYBACK_SLIDES)
def _deformed_to_ux_max(results):
    # The contact's tangential displacement reaches u_x,max exactly when the whole contact slides
    # (slip share 1); every contact group must get there between the fly-back and the end of t_s.
    rows = _window_phase(results, ("flyback", "settling"))
    return float(rows[["slip_share_1", "slip_share_2"]].max(axis=0).min())


@extractor("sec5-1-fastest-at-end-of-acceleration")
def _fastest_at_point5(results):
    # Section 5.1: at point 5 (end of t_a) the runner has its highest velocity. The time of the
    # runner's largest forward velocity from point 4 to the end of the window, after point 5, in
    # units of t_a; a maximum at the window's last sample does not locate it (inconclusive).
    rows = _window_phase(results, ("acceleration", "after"))
    v = rows["runner_velocity_m_per_s"].to_numpy()
    k = int(np.argmax(v))
    if k == v.size - 1:
        raise NotEvaluable("the runner's velocity is largest at the last sample of the window")
    row = rows.iloc[0]
    t_a = float(row["acceleration_end_s"] - row["acceleration_start_s"])
    return (float(rows["time_s"].iloc[k]) - float(row["acceleration_end_s"])) / t_a


@evidence("sec5-1-fastest-at-end-of-acceleration")
def _fastest_at_point5_evidence(results):
    rows = _window_phase(results, ("acceleration", "after"))
    acc = rows[rows["phase"] == "acceleration"]
    k = int(np.argmax(rows["runner_velocity_m_per_s"].to_numpy()))
    return [f"runner velocity at point 5: {acc['runner_velocity_m_per_s'].iloc[-1] * 1e3:.3f} mm/s; largest, "
            f"{rows['runner_velocity_m_per_s'].iloc[k] * 1e3:.3f} mm/s, "
            f"{(rows['time_s'].iloc[k] - acc['acceleration_end_s'].iloc[0]) * 1e6:.2f} µs after point 5"]


@extractor("sec5-1-runner-overshoots-in-slip")
def _overshoot(results):
    # Sub-phase II: from point 4 to the runner's forward extreme after point 5, the runner moves
    # further than the hemispheres do over the same time (the acceleration Δ_a included).
    table = results["fig8b"]
    points = table[table["view"] == "point"].set_index("point")
    points.index = points.index.astype(str)
    zoom = table[table["view"] == "zoom"].sort_values("time_us")
    if zoom.empty or not {"4", "5"} <= set(points.index):
        raise NotEvaluable("the Fig. 8b trace or its points 4 and 5 are missing")
    after = zoom[zoom["time_us"] >= float(points.at["5", "time_us"])]
    if len(after) < 3:
        raise NotEvaluable("fewer than three trace samples after point 5")
    k = int(np.argmax(after["runner_position_nm"].to_numpy()))
    if k == len(after) - 1:
        raise NotEvaluable("the runner is still moving forward at the last sample of the trace")
    start, extreme = points.loc["4"], after.iloc[k]
    return {"lhs": float(extreme["runner_position_nm"] - start["runner_position_nm"]),
            "rhs": float(extreme["piezo_position_nm"] - start["piezo_position_nm"])}


#: The part of the period, before the next fly-back, over which the residual vibration is measured.
_RESIDUAL_SHARE = 0.2
#: Largest record spacing, in micro-vibration periods, at which a vibration's amplitude is read.
_SAMPLES_PER_VIBRATION = 4
#: 'Completely damped': the relative vibration has fallen below a tenth (20 dB) of its amplitude
#: after the slip.
_DAMPED_SHARE = 0.1


@extractor("fig8a-micro-vibration-damped-within-next-stick")
def _micro_vibration_damped(results):
    # Fig. 8a: the relative velocity runner − hemispheres right after the first slip (zoom view)
    # against its largest value in the last fifth of the following stick phase (full view).
    table = results["fig8a"]
    points = table[table["view"] == "point"].set_index("point")
    points.index = points.index.astype(str)
    f_s = float(table["micro_vibration_frequency_Hz"].iloc[0])
    full = table[table["view"] == "full"].sort_values("time_s")
    zoom = table[table["view"] == "zoom"].sort_values("time_s")
    if "1" not in points.index or full.empty or zoom.empty or not np.isfinite(f_s):
        raise NotEvaluable("the Fig. 8a trace, its point 1 or its micro-vibration frequency is missing")
    spacing = float(np.diff(full["time_s"].to_numpy()).max())
    if spacing > 1.0 / (_SAMPLES_PER_VIBRATION * f_s):
        raise NotEvaluable(f"the whole-run record ({spacing * 1e6:.3g} µs apart) cannot resolve the "
                           f"{f_s / 1e3:.3g} kHz micro-vibration")

    def relative(rows):
        t = rows["time_s"].to_numpy()
        hemispheres = np.gradient(rows["piezo_position_m"].to_numpy(), t)
        return rows["runner_velocity_m_per_s"].to_numpy() - hemispheres

    flyback_end = float(full["time_s"].max()) / 2.0  # the first of Fig. 8a's two periods ends here
    period = flyback_end
    after_slip = zoom[zoom["time_s"] > flyback_end]
    late = full[(full["time_s"] >= flyback_end + (1 - _RESIDUAL_SHARE) * period)
                & (full["time_s"] < flyback_end + period - (flyback_end - float(points.at["1", "time_s"])))]
    if len(after_slip) < 3 or len(late) < 3:
        raise NotEvaluable("too few samples after the slip or at the end of the following stick phase")
    initial = float(np.abs(relative(after_slip)).max())
    residual = float(np.abs(relative(late)).max())
    return {"lhs": residual / initial, "rhs": _DAMPED_SHARE}
