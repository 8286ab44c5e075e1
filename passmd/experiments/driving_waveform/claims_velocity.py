"""Claim extractors of Section 5.2: positions and steady velocities (Figs. 9a, 9b and 10).

Decides the ledger's Section 5.2 rows (``passmd/data/reference/claims.csv``), and the abstract's
and conclusion's claims drawn from them, from Fig. 9a's three periods (at the ledger's reading of
μ) and the steady velocities of Figs. 9b and 10 (at its reading of the short-period rule of the
optimized waveform): final positions and step increase, the velocity gain, the saw-tooth's step
and velocity, the frequencies where the velocity turns and where t_s no longer fits, the
reachable maxima of Fig. 10 (interior and where the paper puts them, else inconclusive) and their
orderings over preload, radius and runner material, the 0.1 N maximum at the loss of stick.
Evidence functions add the numbers behind an ordering (Fig. 10: at the paper's 110 kHz). Each
extractor reads the figure tables of :mod:`passmd.experiments.driving_waveform.figures`; a grid
that cannot locate what a claim names (a maximum at the grid's edge) makes the claim inconclusive.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pandas as pd

from passmd.experiments.driving_waveform.claims import _fig9a_run
from passmd.experiments.driving_waveform.figures import (
    FREQUENCIES,
    PAPER_MAXIMUM_KHZ,
    range_maximum,
)
from passmd.experiments.driving_waveform.runs import (
    variant_name,
)
from passmd.ledger.checks import ClaimFails, NotEvaluable, evidence, extractor

__all__ = ["AT_OR_BELOW_80", "CONTROLLABLE", "GRID_STEP_KHZ", "NEAR_110", "Named", "at_frequency",
           "reachable_maximum", "turning_point"]


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
