"""Claim extractors of Section 5: the driving waveform of Figs. 8–10 (and the abstract's and
conclusion's claims drawn from them).

Decides the ledger's Section 5 rows (``passmd/data/reference/claims.csv``). Section 5.1, from
the time series of Figs. 8 and 9a and the resolved fly-back window (``fig8b_window``): the
saw-tooth's back step and whether its micro-vibration dies within the next stick phase, the
micro-vibration after the optimized waveform's acceleration against the saw-tooth's f_s, t_a
starting at the runner's velocity maximum, stick during t_a, the contacts deformed to u_x,max
after the fly-back, the runner fastest at the end of t_a and slipping forward further than the
hemispheres move (Sub-phase II). Section 5.2, from Fig. 9a's three periods (at the ledger's
reading of μ) and the steady velocities of Figs. 9b and 10 (at its reading of the short-period
rule of the optimized waveform): final positions and step increase, the velocity gain, the
saw-tooth's step and velocity, the frequencies where the velocity turns and where t_s no longer
fits, the reachable maxima of Fig. 10 (interior and where the paper puts them, else
inconclusive) and their orderings over preload, radius and runner material, the 0.1 N maximum
at the loss of stick. Evidence functions add the numbers behind an ordering (Fig. 10: at the
paper's 110 kHz).

Each extractor reads the figure tables of :mod:`passmd.experiments.driving_waveform.figures` and returns
what :mod:`passmd.ledger.checks` compares with the paper; a grid that cannot locate what a claim names
(a maximum at the grid's edge, too few samples in a phase) makes the claim inconclusive.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pandas as pd

from passmd.experiments.driving_waveform.figures import (
    FREQUENCIES,
    PAPER_MAXIMUM_KHZ,
    SECTION5_FRICTION,
    WINDOW_SAMPLES_PER_ACCELERATION,
    at_section5_friction,
    range_maximum,
    variant_name,
)
from passmd.ledger.checks import ClaimFails, NotEvaluable, evidence, extractor
from passmd.protocols.velocity import FULL_SLIDING_SHARE

__all__ = ["AT_OR_BELOW_80", "CONTROLLABLE", "GRID_STEP_KHZ", "NEAR_110", "Named", "at_frequency",
           "optimized_period_timing", "reachable_maximum", "turning_point"]


def _fig9a_run(results, waveform: str, reading=None) -> pd.DataFrame:
    """Fig. 9a's per-period rows of one waveform at a ledger reading's μ (default 0.2)."""
    mu = SECTION5_FRICTION if reading is None else float(reading["friction_coefficient"])
    table = at_section5_friction(results["fig9a"], mu)
    rows = table[(table["waveform"] == waveform) & (table["view"] == "period")].sort_values("period")
    if rows.empty:
        raise NotEvaluable(f"no Fig. 9a {waveform} run at μ = {mu:g}")
    return rows


def _series(table: pd.DataFrame, variant: str, **where) -> pd.DataFrame:
    sel = table["variant"] == variant
    for column, value in where.items():
        sel &= np.isclose(table[column], value, rtol=1e-9, atol=0) if isinstance(value, float) else (
            table[column] == value)
    part = table[sel].sort_values("frequency")
    if part.empty:
        raise NotEvaluable(f"no {variant} rows for {where}")
    return part


def _optimized(reading) -> str:
    """The optimized variant of a ledger reading (axis ``short_period`` of passmd.ledger.readings)."""
    return variant_name("optimized", reading["short_period"])


#: One step of the paper's 5 kHz frequency grid (Section 5.2): how near a located maximum must lie
#: to the frequency the paper names for it.
GRID_STEP_KHZ = 5.0


class Named(NamedTuple):
    """Where the paper puts a Fig. 10 series' reachable maximum: ``low``–``high`` kHz, in words."""

    low: float
    high: float
    text: str


#: The paper's 110 kHz (Fig. 10a at 0.4 N; Figs. 10b, 10c are 'set similar'), within one grid step.
NEAR_110 = Named(PAPER_MAXIMUM_KHZ - GRID_STEP_KHZ, PAPER_MAXIMUM_KHZ + GRID_STEP_KHZ,
                 f"{PAPER_MAXIMUM_KHZ:g} kHz the paper names")
#: A maximal controllable frequency the paper does not name: at most its 110 kHz control limit.
CONTROLLABLE = Named(-np.inf, PAPER_MAXIMUM_KHZ + GRID_STEP_KHZ,
                     f"controllable range (at most {PAPER_MAXIMUM_KHZ:g} kHz) the paper names")
#: 0.1 N: stick lost above 80 kHz, so its maximum at or below 80 kHz.
AT_OR_BELOW_80 = Named(-np.inf, 80.0 + GRID_STEP_KHZ, "80 kHz or below, as the paper names")


def reachable_maximum(part: pd.DataFrame, near: Named | None = None) -> pd.Series:
    """The row of the largest steady velocity of one series (assumption ``controllable_frequency``).

    A maximum must be interior, and lie where the paper puts it (``near``, e.g. :data:`NEAR_110`):
    a largest velocity at either end of the frequency grid, or away from the frequency the paper
    names, does not locate the reachable maximum the claim is about, and the claim is
    inconclusive (:class:`passmd.ledger.checks.NotEvaluable`), the same for every Fig. 10 series.
    """
    best = range_maximum(part)
    f = part["frequency_kHz"].to_numpy()
    at = float(best["frequency_kHz"])
    if np.isclose(at, f.min()) or np.isclose(at, f.max()):
        raise NotEvaluable(
            f"no interior maximum: the largest velocity ({best['velocity_mm_per_s']:.3g} mm/s) lies at the "
            f"grid's edge, {at:g} kHz of {f.min():g}–{f.max():g} kHz")
    if near is not None and not near.low - 1e-9 <= at <= near.high + 1e-9:
        raise NotEvaluable(
            f"the largest velocity ({best['velocity_mm_per_s']:.3g} mm/s) lies at {at:g} kHz, not near the "
            f"{near.text}: it is not the reachable maximum the claim is about")
    return best


def _up_to(part: pd.DataFrame, limit_kHz: float) -> pd.DataFrame:
    return part[part["frequency_kHz"] <= limit_kHz + 1e-9]


def _paired(a: pd.DataFrame, b: pd.DataFrame, column: str, relation: str) -> dict:
    """``{'lhs', 'rhs'}``: ``column`` of two series at their common grid frequencies up to 110 kHz.

    The claim is about every frequency of the paper's grid up to 110 kHz: where the series lack
    some of them (a coarser profile) and ``lhs relation rhs`` holds at every one they have, the
    claim is inconclusive on that grid (a failure at any frequency decides it).
    """
    a, b = _up_to(a, PAPER_MAXIMUM_KHZ), _up_to(b, PAPER_MAXIMUM_KHZ)
    common = np.intersect1d(*(np.round(x["frequency_kHz"].to_numpy(), 9) for x in (a, b)))
    if common.size == 0:
        raise NotEvaluable("the two series share no grid frequency up to 110 kHz")
    lhs, rhs = (x.set_index(np.round(x["frequency_kHz"].to_numpy(), 9)).loc[common, column]
                .to_numpy(dtype=float) for x in (a, b))
    paper = np.round(FREQUENCIES["paper"] / 1e3, 9)
    missing = np.setdiff1d(paper[paper <= PAPER_MAXIMUM_KHZ + 1e-9], common)
    holds = np.all(lhs < rhs) if relation == "<" else np.all(lhs > rhs)
    if missing.size and holds:
        raise NotEvaluable(f"holds at the {common.size} grid frequencies computed up to 110 kHz; "
                           f"{missing.size} of the paper's grid are not computed on this profile, e.g. "
                           f"{missing[0]:g} kHz")
    return {"lhs": lhs, "rhs": rhs}


def at_frequency(part: pd.DataFrame, frequency_kHz: float) -> pd.Series:
    """The row of a series at a grid frequency (kHz); inconclusive when the grid lacks it."""
    rows = part[np.isclose(part["frequency_kHz"], frequency_kHz)]
    if rows.empty:
        raise NotEvaluable(f"the frequency grid has no point at {frequency_kHz:g} kHz")
    return rows.iloc[0]


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


#: Axis of passmd.ledger.readings the Fig. 9a claims depend on: Section 5's unstated μ.
_FIG9A_AXES = ("friction_coefficient",)


@extractor("fig9a-standard-position-552nm", depends_on=_FIG9A_AXES)
def _fig9a_standard(results, reading):
    return float(_fig9a_run(results, "sawtooth", reading)["settled_position_m"].iloc[-1]) * 1e9


@extractor("fig9a-optimized-position-716nm", depends_on=_FIG9A_AXES)
def _fig9a_optimized(results, reading):
    return float(_fig9a_run(results, "optimized", reading)["settled_position_m"].iloc[-1]) * 1e9


@extractor("fig9a-step-increase-46.8pct", depends_on=_FIG9A_AXES)
def _fig9a_increase(results, reading):
    std = _fig9a_run(results, "sawtooth", reading)["settled_position_m"].to_numpy()
    opt = _fig9a_run(results, "optimized", reading)["settled_position_m"].to_numpy()
    return 100.0 * (opt[-1] - std[-1]) / (std[-1] - std[0])


@extractor("fig9a-optimized-step-larger", depends_on=_FIG9A_AXES)
def _fig9a_step_larger(results, reading):
    steps = {w: float(np.mean(np.diff(_fig9a_run(results, w, reading)["settled_position_m"].to_numpy())))
             * 1e9 for w in ("optimized", "sawtooth")}
    return {"lhs": steps["optimized"], "rhs": steps["sawtooth"]}


def _fig9b_pair(results, reading):
    table = results["fig9b"]
    saw, opt = _series(table, "sawtooth"), _series(table, _optimized(reading))
    return saw["frequency_kHz"].to_numpy(), saw["velocity_mm_per_s"].to_numpy(), opt


@extractor("fig9b-optimized-faster-below-110khz", depends_on=("short_period",))
def _fig9b_faster(results, reading):
    f, v_saw, opt = _fig9b_pair(results, reading)
    return {"x": f, "holds": opt["velocity_mm_per_s"].to_numpy() > v_saw}


def _largest_gain(results, reading):
    f, v_saw, opt = _fig9b_pair(results, reading)
    below = f <= PAPER_MAXIMUM_KHZ
    gain = opt["velocity_mm_per_s"].to_numpy()[below] - v_saw[below]
    i = int(np.argmax(gain))
    return gain[i], v_saw[below][i]


@extractor("fig9b-max-gain-2.5mm_s", depends_on=("short_period",))
def _fig9b_max_gain(results, reading):
    return float(_largest_gain(results, reading)[0])


@extractor("abstract-velocity-gain-15pct", depends_on=("short_period",))
def _velocity_gain_pct(results, reading):
    gain, v_saw = _largest_gain(results, reading)
    return float(100.0 * gain / v_saw)


def _above(results, variant):
    part = _series(results["fig9b"], variant)
    part = part[part["frequency_kHz"] >= PAPER_MAXIMUM_KHZ - 1e-9]
    if len(part) < 2:
        raise NotEvaluable("fewer than two grid frequencies at or above 110 kHz")
    return {"x": part["frequency_kHz"].to_numpy(), "y": part["velocity_mm_per_s"].to_numpy()}


def turning_point(part: pd.DataFrame, where_kHz: float) -> pd.DataFrame:
    """The part of a velocity series from its turning point on, when it rises and then falls there.

    "Began decreasing above X" needs a rise before the fall and the turning point (the largest
    velocity) within one grid step of X. Raises :class:`passmd.ledger.checks.ClaimFails` naming the
    located turning point otherwise, and :class:`passmd.ledger.checks.NotEvaluable` when fewer than
    two grid points follow it.
    """
    f = part["frequency_kHz"].to_numpy()
    v = part["velocity_mm_per_s"].to_numpy(dtype=float)
    if not np.all(np.isfinite(v)):
        raise NotEvaluable("non-finite velocities on the frequency grid")
    i = int(np.argmax(v))
    if i == len(f) - 1:
        raise ClaimFails(f"the velocity still rises at the grid's last point ({f[i]:g} kHz): it never "
                         "begins decreasing")
    if i == 0:
        raise ClaimFails(f"no rise before the fall: the velocity is largest at the grid's first point "
                         f"({f[0]:g} kHz, {v[0]:.3g} mm/s) and {v[-1]:.3g} mm/s at {f[-1]:g} kHz")
    step = min(f[i] - f[i - 1], f[i + 1] - f[i])
    if abs(f[i] - where_kHz) > step:
        raise ClaimFails(f"the velocity turns at {f[i]:g} kHz ({v[i]:.3g} mm/s), not within one grid step "
                         f"({step:g} kHz) of {where_kHz:g} kHz")
    return part.iloc[i:]


@extractor("fig9b-optimized-decreases-above-110khz", depends_on=("short_period",))
def _fig9b_opt_decreases(results, reading):
    after = turning_point(_series(results["fig9b"], _optimized(reading)), PAPER_MAXIMUM_KHZ)
    if len(after) < 2:
        raise NotEvaluable("fewer than two grid frequencies from the turning point on")
    return {"x": after["frequency_kHz"].to_numpy(), "y": after["velocity_mm_per_s"].to_numpy()}


@extractor("fig9b-standard-increases-above-110khz")
def _fig9b_std_increases(results):
    return _above(results, "sawtooth")


@extractor("fig9b-step-decreases-with-frequency")
def _fig9b_step_decreases(results):
    saw = _series(results["fig9b"], "sawtooth")
    return {"x": saw["frequency_kHz"].to_numpy(), "y": saw["step_nm"].to_numpy()}


@extractor("fig9b-sawtooth-velocity-16.5mm_s-at-110khz")
def _fig9b_sawtooth_110(results):
    return float(at_frequency(_series(results["fig9b"], "sawtooth"), PAPER_MAXIMUM_KHZ)["velocity_mm_per_s"])


@extractor("fig9b-no-time-to-settle-above-110khz")
def _fig9b_settling(results):
    opt = _series(results["fig9b"], "optimized")
    return {"x": opt["frequency_kHz"].to_numpy(), "holds": opt["settling_fits"].to_numpy(dtype=float)}


def _fig10a_part(results, preload, reading):
    return _series(results["fig10a"], _optimized(reading), preload=preload)


#: Where the paper puts each Fig. 10a preload's reachable maximum.
_FIG10A_NEAR = {0.4: NEAR_110, 1.0: CONTROLLABLE, 0.1: AT_OR_BELOW_80}


def _fig10a_max(results, preload, reading):
    return reachable_maximum(_fig10a_part(results, preload, reading), _FIG10A_NEAR[preload])


@extractor("fig10a-max-velocity-19mm_s", depends_on=("short_period",))
def _fig10a_vmax(results, reading):
    return float(_fig10a_max(results, 0.4, reading)["velocity_mm_per_s"])


@extractor("fig10a-max-velocity-at-110khz", depends_on=("short_period",))
def _fig10a_fmax(results, reading):
    # where the maximum lies is the claim itself: only an interior maximum is required
    return float(reachable_maximum(_fig10a_part(results, 0.4, reading))["frequency_kHz"])


@extractor("fig10a-1n-slower", depends_on=("short_period",))
def _fig10a_1n_slower(results, reading):
    return {"lhs": float(_fig10a_max(results, 1.0, reading)["velocity_mm_per_s"]),
            "rhs": float(_fig10a_max(results, 0.4, reading)["velocity_mm_per_s"])}


@extractor("fig10a-1n-larger-back-step", depends_on=("short_period",))
def _fig10a_1n_back(results, reading):
    return {"lhs": float(_fig10a_max(results, 1.0, reading)["back_step_nm"]),
            "rhs": float(_fig10a_max(results, 0.4, reading)["back_step_nm"])}


@extractor("fig10a-0.1n-smaller-back-step", depends_on=("short_period",))
def _fig10a_01n_back(results, reading):
    # a preload's back-step, at every grid frequency of the controllable range (up to 110 kHz)
    return _paired(_fig10a_part(results, 0.1, reading), _fig10a_part(results, 0.4, reading),
                   "back_step_nm", "<")


@extractor("fig10a-0.1n-stick-lost-above-80khz")
def _fig10a_stick(results):
    part = _series(results["fig10a"], "optimized", preload=0.1)
    return {"x": part["frequency_kHz"].to_numpy(),
            "holds": part["stick_during_acceleration"].to_numpy(dtype=float)}


def stick_edge(part: pd.DataFrame) -> float:
    """The highest grid frequency (kHz) at which the runner still sticks during t_a, with stick lost
    at every grid frequency above it: where the loss of stick of the 0.1 N claim begins.

    :class:`passmd.ledger.checks.ClaimFails` when stick is never lost at the top of the grid or never
    holds at all.
    """
    f = part["frequency_kHz"].to_numpy()
    stick = part["stick_during_acceleration"].to_numpy(dtype=bool)
    if stick[-1]:
        raise ClaimFails(f"the runner still sticks during t_a at the grid's last frequency, {f[-1]:g} kHz: "
                         "no loss of stick limits the velocity")
    if not stick.any():
        raise ClaimFails("the runner slips during t_a at every grid frequency")
    return float(f[np.flatnonzero(stick)[-1]])


@extractor("fig10a-0.1n-maximum-at-or-below-80khz", depends_on=("short_period",))
def _fig10a_01n_at_80(results, reading):
    # the maximum is limited by the loss of stick: it lies at the last frequency before stick is lost
    part = _fig10a_part(results, 0.1, reading)
    return {"lhs": float(reachable_maximum(part)["frequency_kHz"]), "rhs": stick_edge(part)}


@evidence("fig10a-0.1n-maximum-at-or-below-80khz")
def _fig10a_01n_at_80_evidence(results):
    part = _series(results["fig10a"], "optimized", preload=0.1)
    fits = part.loc[part["settling_fits"].astype(bool), "frequency_kHz"]
    stick = part.loc[part["stick_during_acceleration"].astype(bool), "frequency_kHz"]
    fitting = f"{fits.max():g} kHz" if len(fits) else "no grid frequency"
    return [f"0.1 N: t_s = 1/(2 f_s) fits into the period up to {fitting}; the runner sticks during t_a at "
            f"{', '.join(f'{x:g}' for x in stick) or 'no grid frequency'} kHz"]


@extractor("fig10a-0.1n-slightly-slower", depends_on=("short_period",))
def _fig10a_01n_slower(results, reading):
    return {"lhs": float(_fig10a_max(results, 0.1, reading)["velocity_mm_per_s"]),
            "rhs": float(_fig10a_max(results, 0.4, reading)["velocity_mm_per_s"])}


#: Where the paper puts each Fig. 10b radius's reachable maximum ('set similar to Fig. 10a'; the
#: smaller radius has the lower maximal controllable frequency).
_FIG10B_NEAR = {1.0: NEAR_110, 0.25: CONTROLLABLE}


def _fig10b_part(results, radius_mm, reading):
    return _series(results["fig10b"], _optimized(reading), radius_mm=radius_mm)


def _fig10b_max(results, radius_mm, reading):
    return reachable_maximum(_fig10b_part(results, radius_mm, reading), _FIG10B_NEAR[radius_mm])


@extractor("fig10b-r1-faster", depends_on=("short_period",))
def _fig10b_faster(results, reading):
    # 'a higher velocity', at every grid frequency of the controllable range (up to 110 kHz)
    return _paired(_fig10b_part(results, 1.0, reading), _fig10b_part(results, 0.25, reading),
                   "velocity_mm_per_s", ">")


@extractor("fig10b-r1-higher-max-frequency", depends_on=("short_period",))
def _fig10b_frequency(results, reading):
    return {"lhs": float(_fig10b_max(results, 1.0, reading)["frequency_kHz"]),
            "rhs": float(_fig10b_max(results, 0.25, reading)["frequency_kHz"])}


@extractor("fig10b-r1-smaller-back-step", depends_on=("short_period",))
def _fig10b_back(results, reading):
    return {"lhs": float(_fig10b_max(results, 1.0, reading)["back_step_nm"]),
            "rhs": float(_fig10b_max(results, 0.25, reading)["back_step_nm"])}


def _fig10c_max(results, runner, reading):
    best = reachable_maximum(_series(results["fig10c"], _optimized(reading), runner=runner), NEAR_110)
    return float(best["velocity_mm_per_s"])


@extractor("fig10c-youngs-modulus-negligible", depends_on=("short_period",))
def _fig10c_negligible(results, reading):
    return {"lhs": _fig10c_max(results, "molybdenum", reading), "rhs": _fig10c_max(results, "steel", reading)}


@extractor("conclusion-youngs-modulus-weaker-than-preload-and-radius", depends_on=("short_period",))
def _conclusion_youngs(results, reading):
    material = abs(_fig10c_max(results, "molybdenum", reading) - _fig10c_max(results, "steel", reading))
    preload = abs(float(_fig10a_max(results, 1.0, reading)["velocity_mm_per_s"])
                  - float(_fig10a_max(results, 0.4, reading)["velocity_mm_per_s"]))
    radius = abs(float(_fig10b_max(results, 1.0, reading)["velocity_mm_per_s"])
                 - float(_fig10b_max(results, 0.25, reading)["velocity_mm_per_s"]))
    return {"lhs": material, "rhs": min(preload, radius)}


# Evidence where the paper makes the Fig. 10 claims: at its reachable maximum, 110 kHz.

def _at_paper_maximum(table, column, label, **where):
    row = at_frequency(_series(table, "optimized", **where), PAPER_MAXIMUM_KHZ)
    return float(row[column]), label


def _evidence_110(results, key, column, unit, pairs):
    out = []
    for where in pairs:
        value, _ = _at_paper_maximum(results[key], column, "", **where)
        name = ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}" for k, v in where.items())
        out.append(f"{column.replace('_mm_per_s', '').replace('_nm', '').replace('_', ' ')} at "
                   f"{PAPER_MAXIMUM_KHZ:g} kHz, {name}: {value:.4g} {unit} "
                   "(Eq. 15 waveform, settling time cut)")
    return out


def _fig10_evidence(claim_id, key, column, unit, pairs):
    return evidence(claim_id)(lambda results: _evidence_110(results, key, column, unit, pairs))


#: The evidence functions of the Fig. 10 claims, one per claim (found by passmd.ledger.checks).
_FIG10_EVIDENCE = tuple(_fig10_evidence(*spec) for spec in (
    ("fig10a-1n-slower", "fig10a", "velocity_mm_per_s", "mm/s", ({"preload": 1.0}, {"preload": 0.4})),
    ("fig10a-1n-larger-back-step", "fig10a", "back_step_nm", "nm", ({"preload": 1.0}, {"preload": 0.4})),
    ("fig10a-0.1n-smaller-back-step", "fig10a", "back_step_nm", "nm", ({"preload": 0.1}, {"preload": 0.4})),
    ("fig10a-0.1n-slightly-slower", "fig10a", "velocity_mm_per_s", "mm/s",
     ({"preload": 0.1}, {"preload": 0.4})),
    ("fig10b-r1-faster", "fig10b", "velocity_mm_per_s", "mm/s", ({"radius_mm": 1.0}, {"radius_mm": 0.25})),
    ("fig10b-r1-smaller-back-step", "fig10b", "back_step_nm", "nm",
     ({"radius_mm": 1.0}, {"radius_mm": 0.25})),
    ("fig10c-youngs-modulus-negligible", "fig10c", "velocity_mm_per_s", "mm/s",
     ({"runner": "molybdenum"}, {"runner": "steel"})),
))
