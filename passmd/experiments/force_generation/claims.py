"""Claim extractors of Section 4.2: the generated force of Fig. 7.

Decides the ledger's Section 4.2 rows (``passmd/data/reference/claims.csv``). The claims about the
simulated force are that it depends on the actuation amplitude, the preload, the hemisphere radius,
μ and the runner's material: this paper's model (flexible actuators, μ = 0.2) at half and full stroke
and at the panels' two preloads, and with one of R, μ or the runner changed, read from the ledger's
readings (:func:`~passmd.experiments.force_generation.figures.fig7_readings`,
:func:`~passmd.experiments.force_generation.figures.fig7_dependence_readings`: every point of the
fly-back rule, the actuator damping ζ and the drive frequency). Every other sentence of
Section 4.2 compares a model with the experiment of [12] (the agreement, the discrepancy and its
growth, its size of 115 mN, its causes, the other preloads' trends): the paper's text gives none of
the measured data, so they are claims about the experiment, inconclusive
(:mod:`passmd.ledger.rules`). Their model-against-model stand-ins (the earlier model of [12], rigid
actuators with μ = 0.3, against this paper's) are studies at the defaults, read from the figure
tables of :mod:`passmd.experiments.force_generation.figures` (stalled runs only, through
:func:`~passmd.experiments.force_generation.figures.force_difference` and
:func:`~passmd.experiments.force_generation.figures.model_rows`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd.experiments.force_generation.figures import (
    DEPENDENCE_PAIRS,
    EARLIER,
    PANELS,
    PANELS_FULL_STROKE_NM,
    THIS,
    force_difference,
    model_rows,
)
from passmd.ledger.checks import (
    ClaimFails,
    NoRun,
    NotEvaluable,
    Subset,
    evidence,
    experiment_claim,
    extractor,
)
from passmd.model.tables import PRELOAD_GRIDS

__all__ = ["DEPENDENCE_PERCENT", "dependence_pairs", "full_and_half_stroke", "readings_at"]

#: Axes of passmd.ledger.readings this paper's force runs depend on.
_FORCE_AXES = ("flyback", "damping_ratio", "force_frequency")
#: The smallest relative change of F_gen that counts as a dependence (%): 5 %, the scatter the force
#: chapter allows single stalled forces (counter-steps of its trends).
DEPENDENCE_PERCENT = 5.0


def _at_reading(table, reading):
    """The rows of a force readings table at a ledger reading: its fly-back rule, ζ and drive frequency."""
    return table[(table["flyback"] == reading["flyback"])
                 & np.isclose(table["damping_ratio"], float(reading["damping_ratio"]), rtol=1e-9, atol=0)
                 & np.isclose(table["frequency_Hz"], float(reading["force_frequency"]), rtol=1e-9, atol=0)]


def readings_at(results, reading) -> pd.DataFrame:
    """The rows of ``fig7_readings`` at a ledger reading (fly-back rule, ζ, drive frequency). Raises
    :class:`passmd.ledger.checks.NoRun` when the table holds none."""
    rows = _at_reading(results["fig7_readings"], reading)
    if rows.empty:
        raise NoRun(f"no force runs of this paper's model with the {reading['flyback']} fly-back, "
                    f"ζ = {reading['damping_ratio']:g} at {reading['force_frequency']:g} Hz")
    return rows.reset_index(drop=True)


def full_and_half_stroke(results, reading) -> dict:
    """This paper's F_gen (mN) at each panel preload, half and full stroke, at a reading:
    ``{(radius_mm, preload_N): (F at 0.5 A_max, F at A_max)}`` (stalled runs only)."""
    rows = readings_at(results, reading)
    out = {}
    for (radius, preload), group in rows.groupby(["radius_mm", "preload_N"]):
        group = group.set_index("amplitude_fraction").sort_index()
        if not group["converged"].all():
            raise NotEvaluable(f"a force run did not stall at R = {radius:g} mm, {preload:g} N")
        out[round(float(radius), 9), round(float(preload), 9)] = (float(group.at[0.5, "generated_force_mN"]),
                                              float(group.at[1.0, "generated_force_mN"]))
    return out


def _change(a: float, b: float) -> float:
    """|b − a| in % of the larger of the two."""
    scale = max(abs(a), abs(b))
    return 100.0 * abs(b - a) / scale if scale > 0 else 0.0


@extractor("fig7-force-depends-on-amplitude", depends_on=_FORCE_AXES)
def _depends_on_amplitude(results, reading) -> dict:
    # F_gen at full stroke against half stroke, at each of the four panel preloads
    pairs = full_and_half_stroke(results, reading)
    change = np.array([_change(*pair) for pair in pairs.values()])
    return {"lhs": change, "rhs": np.full(change.size, DEPENDENCE_PERCENT),
            "at": [p for _, p in pairs], "at_unit": "N"}


def dependence_pairs(results, reading) -> dict:
    """This paper's F_gen (mN) of each pair of
    :data:`~passmd.experiments.force_generation.figures.DEPENDENCE_PAIRS` at a reading: ``{pair name:
    (base, changed)}`` (stalled runs only)."""
    rows = _at_reading(results["fig7_dependence_readings"], reading)
    if rows.empty:
        raise NoRun(f"no force-dependence runs at {reading}")
    out = {}
    for pair in DEPENDENCE_PAIRS:
        mine = rows[rows["pair"] == pair].set_index("side")
        if not mine["converged"].all():
            raise NotEvaluable(f"a force run of the {pair} pair did not stall")
        out[pair] = (float(mine.at["base", "generated_force_mN"]),
                     float(mine.at["changed", "generated_force_mN"]))
    return out


@extractor("sec4-2-force-depends-on-radius-friction-material", depends_on=_FORCE_AXES)
def _depends_on_radius_friction_material(results, reading) -> dict:
    # F_gen with one input changed (R, μ, runner material) against the same run without the change
    pairs = dependence_pairs(results, reading)
    change = np.array([_change(*pair) for pair in pairs.values()])
    return {"lhs": change, "rhs": np.full(change.size, DEPENDENCE_PERCENT)}


@evidence("sec4-2-force-depends-on-radius-friction-material")
def _dependence_evidence(results) -> list:
    from passmd.ledger.readings import default_reading

    return [f"{name}: {base:.4g} mN → {changed:.4g} mN ({_change(base, changed):.3g} %, defaults)"
            for name, (base, changed) in dependence_pairs(results, default_reading()).items()]


@extractor("fig7-force-depends-on-preload", depends_on=_FORCE_AXES)
def _depends_on_preload(results, reading) -> dict:
    # F_gen at the full stroke, the panel's higher preload against its lower, for each radius
    forces = full_and_half_stroke(results, reading)
    change = []
    for radius, preloads in PANELS.values():
        low, high = (forces[round(radius * 1e3, 9), round(p, 9)][1] for p in sorted(preloads))
        change.append(_change(low, high))
    return {"lhs": np.array(change), "rhs": np.full(len(change), DEPENDENCE_PERCENT),
            "at": [radius * 1e3 for radius, _ in PANELS.values()], "at_unit": "mm"}


@evidence("fig7-force-depends-on-amplitude")
def _force_evidence(results) -> list:
    from passmd.ledger.readings import default_reading

    return [f"R = {r:g} mm, {p:g} N: {half:.4g} mN at half stroke, {full:.4g} mN at the full stroke "
            "(defaults)"
            for (r, p), (half, full) in full_and_half_stroke(results, default_reading()).items()]


# --------------------------------------------------------------------------------------
# Claims about the experiment of [12] (inconclusive: no measured data in the text)
# --------------------------------------------------------------------------------------

_EXPERIMENT_CLAIMS = (
    experiment_claim("fig7a-force-difference-115mn",
                     "the forces measured in [12] are shown only in Fig. 7a's plot"),
    experiment_claim("fig7a-discrepancy-grows-with-amplitude",
                     "the forces measured in [12] are shown only in Fig. 7a's plot"),
    experiment_claim("fig7b-discrepancy-grows-with-amplitude",
                     "the forces measured in [12] are shown only in Fig. 7b's plot"),
    experiment_claim("fig7-critical-amplitude-both-models",
                     "the critical amplitudes measured in [12] are shown only in Fig. 7's plot"),
    experiment_claim("fig7-flexible-covers-experiment",
                     "the forces and critical amplitudes measured in [12] are shown only in Fig. 7's plot"),
    experiment_claim("abstract-agreement-with-experiment",
                     "the experimental data of [12] are shown only in the plots of Figs. 6b and 7"),
    experiment_claim("sec4-2-friction-and-actuator-dynamics-cause-discrepancy",
                     "the discrepancy is between the earlier model and the forces measured in [12], which "
                     "are shown only in Fig. 7's plot"),
    experiment_claim("sec4-2-other-preloads-same-trend",
                     "the trends are those of the simulations against the forces measured in [12], which the "
                     "paper does not show for the other preloads"),
)


# --------------------------------------------------------------------------------------
# Studies: the earlier model of [12] against this paper's, at the defaults
# --------------------------------------------------------------------------------------


@extractor("study-fig7a-model-difference-115mn")
def _fig7a_difference(results) -> float:
    diff = force_difference(results["fig7a"], 0.8)
    full = diff[np.isclose(diff["amplitude_nm"], PANELS_FULL_STROKE_NM["fig7a"])]
    if full.empty:
        raise NotEvaluable("no stalled pair of runs at 202 nm and 0.8 N")
    return float(full["difference_mN"].iloc[0])


def _onset(table, model, preload: float, name: str) -> float:
    rows = model_rows(table, model, preload)
    if rows.empty:
        raise NotEvaluable(f"{name}: no runs for {model} at {preload:g} N")
    return float(rows["onset_nm"].iloc[0])


def _trend(results, name: str) -> dict:
    # The difference in the *level* of generated force: only amplitudes at which both models
    # generate force (above both onsets); between the onsets only one model does.
    table = results[name]
    out = {}
    for preload in PANELS[name][1]:
        onsets = [_onset(table, model, preload, name) for model in (EARLIER, THIS)]
        if not all(np.isfinite(onsets)):
            raise ClaimFails(f"{name}: a model generates no force up to the full stroke at {preload:g} N")
        diff = force_difference(table, preload)
        diff = diff[diff["amplitude_nm"] > max(onsets)]
        if len(diff) < 2:
            raise NotEvaluable(f"{name}: fewer than two stalled amplitudes above both onsets "
                               f"({max(onsets):.3g} nm) at {preload:g} N")
        out[f"{preload:g} N"] = {"x": diff["amplitude_nm"].to_numpy(), "y": diff["difference_mN"].to_numpy()}
    return out


@extractor("study-fig7a-model-difference-grows")
def _fig7a_trend(results) -> dict:
    return _trend(results, "fig7a")


@extractor("study-fig7b-model-difference-grows")
def _fig7b_trend(results) -> dict:
    return _trend(results, "fig7b")


@extractor("study-fig7-onsets-earlier-against-this-model")
def _fig7_onsets(results) -> dict:
    lhs, rhs = [], []
    for name in ("fig7a", "fig7b"):
        table = results[name]
        for preload in PANELS[name][1]:
            onset = {}
            for model in (EARLIER, THIS):
                onset[model] = _onset(table, model, preload, name)
                if not np.isfinite(onset[model]):
                    raise ClaimFails(f"{name}: no force generation up to the full stroke for {model} at "
                                     f"{preload:g} N")
            lhs.append(onset[EARLIER])
            rhs.append(onset[THIS])
    return {"lhs": np.array(lhs), "rhs": np.array(rhs)}


@extractor("study-fig7-earlier-model-above-at-every-preload")
def _other_preloads(results) -> dict:
    grid = results["fig7grid"]
    full = grid[np.isclose(grid["amplitude_fraction"], 1.0)]
    earlier, this = [], []
    for (radius, preload), rows in full.groupby(["radius_mm", "preload_N"]):
        pair = [rows[(rows["actuator_model"] == m) & np.isclose(rows["friction_coefficient"], mu)]
                for m, mu in (EARLIER, THIS)]
        if any(p.empty or not bool(p["converged"].iloc[0]) for p in pair):
            raise NotEvaluable(f"no stalled pair of runs at R = {radius:g} mm, {preload:g} N")
        earlier.append(float(pair[0]["generated_force_mN"].iloc[0]))
        this.append(float(pair[1]["generated_force_mN"].iloc[0]))
    if not earlier:
        raise NotEvaluable("no full-stroke runs on the preload grids")
    ours = {"lhs": np.array(earlier), "rhs": np.array(this)}
    missing = [f"{p:g} N at R = {r * 1e3:g} mm" for r, grid in PRELOAD_GRIDS.items() for p in grid
               if not (np.isclose(full["radius_mm"], r * 1e3) & np.isclose(full["preload_N"], p)).any()]
    # each preload's pair of runs is the same on every profile: a failure on part of the grid decides
    return Subset(ours, "the paper's preloads " + ", ".join(missing)) if missing else ours


@extractor("study-fig7-friction-and-actuators-lower-force")
def _causes(results) -> dict:
    cycle = results["fig7cycle"]
    force = {}
    for model, mu in (("rigid", 0.3), ("rigid", 0.2), ("flexible", 0.2)):
        rows = cycle[(cycle["actuator_model"] == model) & np.isclose(cycle["friction_coefficient"], mu)]
        if rows.empty:
            raise NotEvaluable(f"no stall period of {model} actuators with μ = {mu:g}")
        force[model, mu] = float(rows["generated_force_mN"].iloc[0])
    friction = force["rigid", 0.3] - force["rigid", 0.2]
    actuators = force["rigid", 0.2] - force["flexible", 0.2]
    return {"lhs": np.array([friction, actuators]), "rhs": np.zeros(2)}


@evidence("study-fig7-friction-and-actuators-lower-force")
def _causes_evidence(results) -> list:
    lhs = _causes(results)["lhs"]
    return [f"μ 0.3 → 0.2 with rigid actuators lowers F_gen by {lhs[0]:.4g} mN; rigid → flexible actuators "
            f"at μ = 0.2 lowers it by {lhs[1]:.4g} mN (together {lhs.sum():.4g} mN; 202 nm, 0.8 N, R = 1 mm)"]
