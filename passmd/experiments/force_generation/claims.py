"""Claim extractors of Section 4.2: the generated force of Fig. 7.

Decides the ledger's Section 4.2 rows (``passmd/data/reference/claims.csv``): the 115 mN
difference between the earlier model of [12] (rigid actuators, μ = 0.3) and this paper's
(flexible actuators, μ = 0.2) at the full stroke and 0.8 N (a value, at the ledger's reading of
the force-run frequency), the growth of that difference with the amplitude in Figs. 7a and 7b
(trends, above both models' onsets), the earlier model above this paper's at every preload of
both grids (an ordering), the onsets of force generation of both models compared with each other
over the four preloads of Figs. 7a and 7b (a model-against-model row), F_gen growing with the
amplitude above its onset and with the preload (trends), and the split of the difference into
its friction and actuator parts from one stall period (``fig7cycle``; with its evidence). The
statements about the experiment of [12] are inconclusive: its data are not in the paper's text.

Each extractor reads the figure tables of :mod:`passmd.experiments.force_generation.figures` (stalled
runs only, through :func:`~passmd.experiments.force_generation.figures.force_difference` and
:func:`~passmd.experiments.force_generation.figures.model_rows`) and returns what :mod:`passmd.ledger.checks`
compares with the paper.
"""

from __future__ import annotations

import numpy as np

from passmd.experiments.force_generation.figures import (
    EARLIER,
    FORCE_FREQUENCY,
    PANELS,
    PANELS_FULL_STROKE_NM,
    THIS,
    force_difference,
    model_rows,
    panel_at,
)
from passmd.ledger.checks import ClaimFails, NotEvaluable, check_trend, evidence, extractor, no_measured_data
from passmd.ledger.claims import load_claims
from passmd.model.tables import PRELOAD_GRIDS


@extractor("fig7a-force-difference-115mn", depends_on=("force_frequency", "flyback"))
def _fig7a_difference(results, reading) -> float:
    frequency = float(reading["force_frequency"])
    if np.isclose(frequency, FORCE_FREQUENCY):
        diff = force_difference(panel_at(results, "fig7a", reading), 0.8)
    elif reading["flyback"] != "slew":
        raise NotEvaluable(f"the frequency runs (fig7freq) use the slew-rate fly-back only, not at "
                           f"{frequency:g} Hz with the {reading['flyback']} one")
    else:  # the frequency panel holds the full-stroke runs at the other frequencies
        if "fig7freq" not in results:
            raise NotEvaluable("needs results: fig7freq")
        table = results["fig7freq"]
        rows = table[np.isclose(table["frequency_Hz"], frequency) & np.isclose(table["radius_mm"], 1.0)]
        diff = force_difference(rows.assign(amplitude_fraction=1.0), 0.8)
    full = diff[np.isclose(diff["amplitude_nm"], PANELS_FULL_STROKE_NM["fig7a"])]
    if full.empty:
        raise NotEvaluable(f"no stalled pair of runs at 202 nm and 0.8 N at {frequency:g} Hz")
    return float(full["difference_mN"].iloc[0])


@extractor("sec4-2-friction-and-actuator-dynamics-cause-discrepancy")
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


@evidence("sec4-2-friction-and-actuator-dynamics-cause-discrepancy")
def _causes_evidence(results) -> list:
    lhs = _causes(results)["lhs"]
    return [f"μ 0.3 → 0.2 with rigid actuators lowers F_gen by {lhs[0]:.4g} mN; rigid → flexible actuators "
            f"at μ = 0.2 lowers it by {lhs[1]:.4g} mN (together {lhs.sum():.4g} mN; 202 nm, 0.8 N, R = 1 mm)"]


@extractor("sec4-2-other-preloads-same-trend")
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
    lhs, rhs = np.array(earlier), np.array(this)
    # 'other preload levels' means every preload: a pass needs all of them, a failure needs one
    computed = {(round(r, 9), round(p, 9)) for r, p in zip(full["radius_mm"], full["preload_N"], strict=True)}
    missing = [(r * 1e3, p) for r, grid in PRELOAD_GRIDS.items() for p in grid
               if (round(r * 1e3, 9), round(float(p), 9)) not in computed]
    if missing and np.all(lhs > rhs):
        raise NotEvaluable(f"holds at the {len(lhs)} preloads computed on this profile; "
                           f"{len(missing)} preloads of the grids are not computed, e.g. "
                           f"{missing[0][1]:g} N at R = {missing[0][0]:g} mm")
    return {"lhs": lhs, "rhs": rhs}


def _onset(table, model, preload: float, name: str) -> float:
    rows = model_rows(table, model, preload)
    if rows.empty:
        raise NotEvaluable(f"{name}: no runs for {model} at {preload:g} N")
    return float(rows["onset_nm"].iloc[0])


def _trend(results, name: str, reading) -> dict:
    # The discrepancy in the *level* of generated force: only amplitudes at which both models
    # generate force (above both onsets); between the onsets only one model does.
    table = panel_at(results, name, reading)
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


@extractor("fig7a-discrepancy-grows-with-amplitude", depends_on=("flyback",))
def _fig7a_trend(results, reading) -> dict:
    return _trend(results, "fig7a", reading)


@extractor("fig7b-discrepancy-grows-with-amplitude", depends_on=("flyback",))
def _fig7b_trend(results, reading) -> dict:
    return _trend(results, "fig7b", reading)


@extractor("fig7-critical-amplitude-both-models")
def _fig7_onsets_experiment(results):
    no_measured_data("the critical amplitudes measured in [12] are shown only in Fig. 7's plot")


@extractor("fig7-flexible-covers-experiment")
def _fig7_flexible_experiment(results):
    no_measured_data("the forces and critical amplitudes measured in [12] are shown only in Fig. 7's plot")


@extractor("abstract-agreement-with-experiment")
def _abstract_experiment(results):
    no_measured_data("the experimental data of [12] are shown only in the plots of Figs. 6b and 7")


@extractor("fig7-rigid-mu03-flexible-mu02-onsets-agree", depends_on=("flyback",))
def _fig7_onsets(results, reading) -> dict:
    lhs, rhs = [], []
    for name in ("fig7a", "fig7b"):
        table = panel_at(results, name, reading)
        for preload in PANELS[name][1]:
            onset = {}
            for model in (EARLIER, THIS):
                rows = model_rows(table, model, preload)
                if rows.empty:
                    raise NotEvaluable(f"{name}: no runs for {model} at {preload:g} N")
                if not np.isfinite(rows["onset_nm"].iloc[0]):
                    raise ClaimFails(f"{name}: no force generation up to the full stroke for {model} at "
                                     f"{preload:g} N")
                onset[model] = float(rows["onset_nm"].iloc[0])
            lhs.append(onset[EARLIER])
            rhs.append(onset[THIS])
    return {"lhs": np.array(lhs), "rhs": np.array(rhs)}


@extractor("fig7-force-grows-with-amplitude-above-onset", depends_on=("flyback",))
def _force_grows_with_amplitude(results, reading) -> dict:
    # each model's F_gen over the stalled amplitudes above its own onset, at each panel preload
    out = {}
    for name in ("fig7a", "fig7b"):
        table = panel_at(results, name, reading)
        for preload in PANELS[name][1]:
            for model in (EARLIER, THIS):
                rows = model_rows(table, model, preload)
                onset = _onset(table, model, preload, name)
                if not np.isfinite(onset):
                    raise ClaimFails(f"{name}: no force generation up to the full stroke for {model} at "
                                     f"{preload:g} N")
                rows = rows[rows["converged"].astype(bool) & (rows["amplitude_nm"] > onset)]
                if len(rows) < 2:
                    raise NotEvaluable(f"{name}: fewer than two stalled amplitudes above the onset of "
                                       f"{model} at {preload:g} N")
                label = f"{name} {model[0]} μ {model[1]:g}, {preload:g} N"
                out[label] = {"x": rows["amplitude_nm"].to_numpy(),
                              "y": rows["generated_force_mN"].to_numpy()}
    return out


@extractor("fig7-force-grows-with-preload")
def _force_grows_with_preload(results) -> dict:
    # each model's full-stroke F_gen over the preload grid of each radius (stalled runs only)
    grid = results["fig7grid"]
    full = grid[np.isclose(grid["amplitude_fraction"], 1.0)]
    out = {}
    for (radius, model, mu), rows in full.groupby(["radius_mm", "actuator_model", "friction_coefficient"]):
        if (model, mu) not in (EARLIER, THIS):
            continue
        rows = rows[rows["converged"].astype(bool)].sort_values("preload_N")
        if len(rows) < 2:
            raise NotEvaluable(f"fewer than two stalled full-stroke runs for {model} μ {mu:g} at "
                               f"R = {radius:g} mm")
        out[f"R = {radius:g} mm, {model} μ {mu:g}"] = {"x": rows["preload_N"].to_numpy(),
                                                       "y": rows["generated_force_mN"].to_numpy()}
    if not out:
        raise NotEvaluable("no full-stroke runs on the preload grids")
    # 'grows with the preload' is over the whole grids: a pass needs all of them, a failure needs one
    computed = {(round(r, 9), round(p, 9)) for r, p in zip(full["radius_mm"], full["preload_N"], strict=True)}
    missing = [(r * 1e3, p) for r, grid_ in PRELOAD_GRIDS.items() for p in grid_
               if (round(r * 1e3, 9), round(float(p), 9)) not in computed]
    tolerance = float(load_claims().set_index("id").at["fig7-force-grows-with-preload", "tolerance_num"])
    if missing and check_trend(out, "increasing", tolerance, "rel").passed:
        raise NotEvaluable(f"grows over the {len(computed)} preloads computed on this profile; "
                           f"{len(missing)} preloads of the grids are not computed, e.g. "
                           f"{missing[0][1]:g} N at R = {missing[0][0]:g} mm")
    return out
