"""Claim extractors of Section 4.1: the critical amplitude A_c of Figs. 5 and 6.

Decides the ledger's Section 4.1 rows (``passmd/data/reference/claims.csv``): no measurable
step below the critical amplitude in Fig. 5a (a threshold over the amplitude grid); the
simulated A_c against the closed forms Eq. 7 and Eq. 8 (Fig. 5b, one contact), Eq. 11 (Fig. 6a)
and Eq. 12 (Figs. 6b, 6c, six contacts), each a value check of the curve A_c(F_p); flexible
above rigid (Fig. 5b), A_c closer to Eq. 11's u_x,max,e than to either form of Eq. 10 (Fig. 6a)
and to Eq. 12 than to either form of Eq. 13 (Figs. 6b, 6c; deviations from
:func:`passmd.ledger.checks.curve_deviation`), and the actuators' interaction changing A_c (six
contacts against each side's own contact alone, at the same normal force) as orderings. Fig. 6b's
agreement with the experiment is a claim about the experiment (:mod:`passmd.ledger.rules`).

Each extractor reads the ledger's readings of Figs. 5 and 6
(:func:`~passmd.experiments.critical_amplitude.figures.ac_readings`,
:func:`~passmd.experiments.critical_amplitude.figures.fig5a_readings`: every run at every point of
the fly-back rule, the A_c protocol, the drive frequency, μ and, for flexible actuators, ζ)
through :func:`~passmd.experiments.critical_amplitude.figures.primary`, and compares with the
closed forms at the reading's μ (Eqs. 7–14 are evaluated at the μ of the runs they are compared
with). On a coarser grid than the paper's (the quick profile's preloads and amplitudes) a check
holding there is inconclusive and only a pointwise failure decides (the coarse-grid rule of
:mod:`passmd.ledger.rules`, :class:`passmd.ledger.checks.Subset`).
"""

from __future__ import annotations

import numpy as np

from passmd.experiments.critical_amplitude.figures import AC_PANELS, PROFILE_SETTINGS, primary
from passmd.ledger.checks import (
    NoRun,
    NotEvaluable,
    Subset,
    curve_deviation,
    experiment_claim,
    extractor,
    reference_table,
)
from passmd.ledger.reference import REFERENCE_FRICTION_COEFFICIENT
from passmd.model.tables import PRELOAD_GRIDS
from passmd.model.theory import normal_forces

__all__ = ["INTERACTION_PERCENT", "side_alone"]

#: Axes of passmd.ledger.readings the A_c curves depend on (rigid actuators: no ζ).
_RIGID_AXES = ("flyback", "ac_protocol", "drive_frequency_s4", "friction_coefficient")
_FLEXIBLE_AXES = ("flyback", "ac_protocol", "drive_frequency_s4", "damping_ratio", "friction_coefficient")


def _on_paper_grid(ours, key: str, preloads, failures_decide: bool = True):
    """``ours`` as it is when ``preloads`` hold every preload of the paper's grid of panel ``key``,
    else a :class:`~passmd.ledger.checks.Subset` naming the missing ones: a check over every preload
    that holds on part of the grid is undecided; one that fails is decided when ``failures_decide``
    (the failing preload is on the paper's grid and its A_c computed alike, the search bracket being
    the same on every profile)."""
    paper = np.round(PRELOAD_GRIDS[AC_PANELS[key][1]], 9)
    missing = paper[~np.isin(paper, np.round(np.asarray(preloads, dtype=float), 9))]
    if missing.size == 0:
        return ours
    return Subset(ours, "the paper's preloads " + ", ".join(f"{p:g}" for p in missing) + " N",
                  failures_decide)


def _curve(results, key: str, actuator_model: str, reading) -> dict:
    rows = primary(results[f"{key}_readings"], actuator_model, reading)
    return {"x": rows["preload_N"].to_numpy(), "y": rows["critical_amplitude_nm"].to_numpy()}


def _against(results, key: str, actuator_model: str, reading, column: str) -> dict:
    """A_c of one panel at a reading, with the closed form ``column`` at the reading's μ (the committed
    reference file at the reference μ)."""
    curve = _curve(results, key, actuator_model, reading)
    mu = float(reading["friction_coefficient"])
    if not np.isclose(mu, REFERENCE_FRICTION_COEFFICIENT, rtol=1e-12, atol=0):
        table = reference_table(f"{key}_closed_form", mu)
        curve["reference"] = np.interp(curve["x"], table["preload_N"], table[column])
    return _on_paper_grid(curve, key, curve["x"])


@extractor("fig5a-no-step-below-50nm", depends_on=_FLEXIBLE_AXES)
def _fig5a_no_step(results, reading) -> dict:
    # Fig. 5a's step read as A_c is read: the first step (first fly-back) or the last (steady state)
    table = results["fig5a_readings"]
    rows = table[(table["flyback"] == reading["flyback"])
                 & np.isclose(table["frequency_Hz"], float(reading["drive_frequency_s4"]))
                 & np.isclose(table["damping_ratio"], float(reading["damping_ratio"]), rtol=1e-9, atol=0)
                 & np.isclose(table["friction_coefficient"], float(reading["friction_coefficient"]),
                              rtol=1e-9, atol=0)].sort_values("amplitude_nm")
    if rows.empty:
        raise NoRun(f"no Fig. 5a runs at {reading}")
    column = "first_step_nm" if reading["ac_protocol"] == "first" else "steady_step_nm"
    step = rows[column].to_numpy(dtype=float)
    holds = np.where(np.isfinite(step), step <= rows["threshold_nm"].to_numpy(dtype=float), np.nan)
    ours = {"x": rows["amplitude_nm"].to_numpy(), "holds": holds}
    spacing, paper = float(np.diff(ours["x"]).max()), PROFILE_SETTINGS["paper"].readings_amplitude_step * 1e9
    if spacing > paper * (1 + 1e-9):  # a coarser grid: a step could hide between its amplitudes
        return Subset(ours, f"the amplitudes between its {spacing:g} nm steps (the paper profile's "
                            f"grid: {paper:g} nm)")
    return ours


@extractor("fig5b-rigid-ac-matches-eq7", depends_on=_RIGID_AXES)
def _fig5b_rigid(results, reading) -> dict:
    return _against(results, "fig5b", "rigid", reading, "u_x_max_nm")


@extractor("fig5b-flexible-ac-matches-eq8", depends_on=_FLEXIBLE_AXES)
def _fig5b_flexible(results, reading) -> dict:
    return _against(results, "fig5b", "flexible", reading, "u_x_max_plus_u_x_a_nm")


@extractor("fig5b-flexible-above-rigid", depends_on=_FLEXIBLE_AXES)
def _fig5b_order(results, reading) -> dict:
    rigid = _curve(results, "fig5b", "rigid", reading)
    flexible = _curve(results, "fig5b", "flexible", reading)
    if not np.array_equal(rigid["x"], flexible["x"]):
        raise NotEvaluable("rigid and flexible A_c are not on the same preloads")
    return _on_paper_grid({"lhs": flexible["y"], "rhs": rigid["y"]}, "fig5b", rigid["x"])


@extractor("fig6a-rigid-ac-matches-eq11", depends_on=_RIGID_AXES)
def _fig6a_eq11(results, reading) -> dict:
    return _against(results, "fig6a", "rigid", reading, "u_x_max_e_nm")


@extractor("fig6a-rigid-ac-not-eq10", depends_on=_RIGID_AXES)
def _fig6a_not_eq10(results, reading) -> dict:
    c = _curve(results, "fig6a", "rigid", reading)
    mu = float(reading["friction_coefficient"])
    own = curve_deviation(c["x"], c["y"], "fig6a_closed_form", "u_x_max_e_nm", mu)
    sides = min(curve_deviation(c["x"], c["y"], "fig6a_closed_form", column, mu)
                for column in ("u_x_max_1_nm", "u_x_max_2_nm"))
    # deviations over the whole curve: on part of the grid neither order decides
    return _on_paper_grid({"lhs": own, "rhs": sides}, "fig6a", c["x"], failures_decide=False)


@extractor("fig6b-flexible-r1-ac-matches-eq12", depends_on=_FLEXIBLE_AXES)
def _fig6b_eq12(results, reading) -> dict:
    return _against(results, "fig6b", "flexible", reading, "u_x_max_e_star_nm")


@extractor("fig6c-flexible-r025-ac-matches-eq12", depends_on=_FLEXIBLE_AXES)
def _fig6c_eq12(results, reading) -> dict:
    return _against(results, "fig6c", "flexible", reading, "u_x_max_e_star_nm")


def _not_single_side(results, key: str, reading) -> dict:
    c = _curve(results, key, "flexible", reading)
    table, mu = f"{key}_closed_form", float(reading["friction_coefficient"])
    own = curve_deviation(c["x"], c["y"], table, "u_x_max_e_star_nm", mu)
    sides = min(curve_deviation(c["x"], c["y"], table, column, mu)
                for column in ("u_x_max_1_star_nm", "u_x_max_2_star_nm"))
    return _on_paper_grid({"lhs": own, "rhs": sides}, key, c["x"], failures_decide=False)


@extractor("fig6b-flexible-r1-ac-not-eq13", depends_on=_FLEXIBLE_AXES)
def _fig6b_not_eq13(results, reading) -> dict:
    return _not_single_side(results, "fig6b", reading)


@extractor("fig6c-flexible-r025-ac-not-eq13", depends_on=_FLEXIBLE_AXES)
def _fig6c_not_eq13(results, reading) -> dict:
    return _not_single_side(results, "fig6c", reading)


#: The smallest change of A_c the actuators' interaction must make to be a 'strong influence' (%):
#: the 10 % band within which the claims call A_c and a closed form in agreement (Fig. 6).
INTERACTION_PERCENT = 10.0


def side_alone(results, reading) -> dict:
    """Six flexible contacts (Fig. 6b) against each side's contact alone at its own normal force.

    Eq. 1 gives the six-contact drive different normal forces on its two sides, F_N1 = 0.707 F_p
    and F_N2 = 0.354 F_p; without interaction among the actuators its A_c would be that of the side
    that slides alone. The one-contact A_c (Fig. 5b, F_N = F_p, same reading) is interpolated
    linearly at F_N1 and F_N2 (inside its preload grid only; the interpolation error of a
    (F_N)^(2/3) curve on those grids is a few % at most, below the 10 % the claim needs).

    Returns ``preload_N``, ``six_nm`` and ``alone_nm`` (each side's one-contact A_c, two columns).
    """
    six = _curve(results, "fig6b", "flexible", reading)
    one = _curve(results, "fig5b", "flexible", reading)
    f1, f2 = normal_forces(six["x"], contacts=6)
    low, high = one["x"].min(), one["x"].max()
    inside = (f1 >= low) & (f1 <= high) & (f2 >= low) & (f2 <= high)
    if not inside.any():
        raise NotEvaluable("no six-contact preload whose two normal forces (Eq. 1) lie on the one-contact "
                           "preload grid")
    alone = np.column_stack([np.interp(f[inside], one["x"], one["y"]) for f in (f1, f2)])
    return {"preload_N": six["x"][inside], "six_nm": six["y"][inside], "alone_nm": alone}


@extractor("sec4-1-interaction-changes-ac", depends_on=_FLEXIBLE_AXES)
def _interaction(results, reading) -> dict:
    # the change the interaction makes: against the nearer of the two sides alone, at every preload
    sides = side_alone(results, reading)
    change = 100.0 * np.min(np.abs(sides["six_nm"][:, None] / sides["alone_nm"] - 1.0), axis=1)
    ours = {"lhs": change, "rhs": np.full(change.size, INTERACTION_PERCENT)}
    # each side's A_c is interpolated on the one-contact grid: on part of the two grids, a failure is
    # not the paper grids' either
    grids = np.intersect1d(*(np.round(_curve(results, key, "flexible", reading)["x"], 9)
                             for key in ("fig5b", "fig6b")))
    return _on_paper_grid(ours, "fig6b", grids, failures_decide=False)


_FIG6B_EXPERIMENT = experiment_claim(
    "fig6b-experiment-agreement",
    "the critical amplitudes measured in [12] (ten measurements per preload) are shown only in Fig. 6b's "
    "plot")
