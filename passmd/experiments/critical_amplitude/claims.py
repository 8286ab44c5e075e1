"""Claim extractors of Section 4.1: the critical amplitude A_c of Figs. 5 and 6.

Decides the ledger's Section 4.1 rows (``passmd/data/reference/claims.csv``): no measurable
steady step below the critical amplitude in Fig. 5a (a threshold over the amplitude grid); the
simulated A_c against the closed forms Eq. 7 and Eq. 8 (Fig. 5b, one contact), Eq. 11 (Fig. 6a)
and Eq. 12 (Figs. 6b, 6c, six contacts), each a value check of the curve A_c(F_p); flexible
above rigid (Fig. 5b), A_c closer to Eq. 11's u_x,max,e than to either form of Eq. 10 (Fig. 6a)
and to Eq. 12 than to either form of Eq. 13 (Figs. 6b, 6c; deviations from
:func:`passmd.ledger.checks.curve_deviation`), and the actuators' interaction changing A_c (six against
one contact at the same preload) as orderings. Fig. 6b's agreement with the experiment is
inconclusive: the measured data are not in the paper's text.

Each extractor reads the figure tables of :mod:`passmd.experiments.critical_amplitude.figures` at one
ledger reading (:mod:`passmd.ledger.readings`: the A_c protocol, the fly-back rule, the drive
frequency and the actuator damping ζ, the axes each curve depends on) through
:func:`~passmd.experiments.critical_amplitude.figures.primary`, and returns what
:mod:`passmd.ledger.checks` compares with the paper.
"""

from __future__ import annotations

import numpy as np

from passmd.experiments.critical_amplitude.figures import primary
from passmd.ledger.checks import NotEvaluable, curve_deviation, extractor, no_measured_data


def _curve(results, key: str, actuator_model: str, reading=None) -> dict:
    rows = primary(results[key], actuator_model, reading)
    return {"x": rows["preload_N"].to_numpy(), "y": rows["critical_amplitude_nm"].to_numpy()}


#: Axes of passmd.ledger.readings the A_c curves depend on (rigid actuators: neither the fly-back rule nor ζ).
_RIGID_AXES = ("ac_protocol", "drive_frequency_s4")
_FLEXIBLE_AXES = ("flyback", "ac_protocol", "drive_frequency_s4", "damping_ratio")


@extractor("fig5a-no-step-below-50nm", depends_on=("flyback",))
def _fig5a_no_step(results, reading) -> dict:
    table = results["fig5a"]
    rows = table[(table["actuator_model"] == "flexible") & (table["flyback"] == reading["flyback"])]
    rows = rows.sort_values("amplitude_nm")
    if rows.empty:
        raise NotEvaluable(f"no flexible runs with the {reading['flyback']} fly-back")
    step = rows["steady_step_nm"].to_numpy(dtype=float)
    holds = np.where(np.isfinite(step), step <= rows["threshold_nm"].to_numpy(dtype=float), np.nan)
    return {"x": rows["amplitude_nm"].to_numpy(), "holds": holds}


@extractor("fig5b-rigid-ac-matches-eq7", depends_on=_RIGID_AXES)
def _fig5b_rigid(results, reading) -> dict:
    return _curve(results, "fig5b", "rigid", reading)


@extractor("fig5b-flexible-ac-matches-eq8", depends_on=_FLEXIBLE_AXES)
def _fig5b_flexible(results, reading) -> dict:
    return _curve(results, "fig5b", "flexible", reading)


@extractor("fig5b-flexible-above-rigid", depends_on=_FLEXIBLE_AXES)
def _fig5b_order(results, reading) -> dict:
    rigid = _curve(results, "fig5b", "rigid", reading)
    flexible = _curve(results, "fig5b", "flexible", reading)
    if not np.array_equal(rigid["x"], flexible["x"]):
        raise NotEvaluable("rigid and flexible A_c are not on the same preloads")
    return {"lhs": flexible["y"], "rhs": rigid["y"]}


@extractor("fig6a-rigid-ac-matches-eq11", depends_on=_RIGID_AXES)
def _fig6a_eq11(results, reading) -> dict:
    return _curve(results, "fig6a", "rigid", reading)


@extractor("fig6a-rigid-ac-not-eq10", depends_on=_RIGID_AXES)
def _fig6a_not_eq10(results, reading) -> dict:
    c = _curve(results, "fig6a", "rigid", reading)
    own = curve_deviation(c["x"], c["y"], "fig6a_closed_form", "u_x_max_e_nm")
    sides = min(
        curve_deviation(c["x"], c["y"], "fig6a_closed_form", column)
        for column in ("u_x_max_1_nm", "u_x_max_2_nm")
    )
    return {"lhs": own, "rhs": sides}


@extractor("fig6b-flexible-r1-ac-matches-eq12", depends_on=_FLEXIBLE_AXES)
def _fig6b_eq12(results, reading) -> dict:
    return _curve(results, "fig6b", "flexible", reading)


@extractor("fig6c-flexible-r025-ac-matches-eq12", depends_on=_FLEXIBLE_AXES)
def _fig6c_eq12(results, reading) -> dict:
    return _curve(results, "fig6c", "flexible", reading)


def _not_single_side(results, key: str, reading) -> dict:
    c = _curve(results, key, "flexible", reading)
    table = f"{key}_closed_form"
    own = curve_deviation(c["x"], c["y"], table, "u_x_max_e_star_nm")
    sides = min(curve_deviation(c["x"], c["y"], table, column)
                for column in ("u_x_max_1_star_nm", "u_x_max_2_star_nm"))
    return {"lhs": own, "rhs": sides}


@extractor("fig6b-flexible-r1-ac-not-eq13", depends_on=_FLEXIBLE_AXES)
def _fig6b_not_eq13(results, reading) -> dict:
    return _not_single_side(results, "fig6b", reading)


@extractor("fig6c-flexible-r025-ac-not-eq13", depends_on=_FLEXIBLE_AXES)
def _fig6c_not_eq13(results, reading) -> dict:
    return _not_single_side(results, "fig6c", reading)


#: The smallest change of A_c the actuators' interaction must make to be a 'strong influence' (%):
#: the 10 % band within which the claims call A_c and a closed form in agreement (Fig. 6).
INTERACTION_PERCENT = 10.0


@extractor("sec4-1-interaction-changes-ac", depends_on=_FLEXIBLE_AXES)
def _interaction(results, reading) -> dict:
    # flexible actuators, R = 1 mm: six contacts (Fig. 6b) against one contact (Fig. 5b), same preload
    six = _curve(results, "fig6b", "flexible", reading)
    one = _curve(results, "fig5b", "flexible", reading)
    common, i6, i1 = np.intersect1d(np.round(six["x"], 9), np.round(one["x"], 9), return_indices=True)
    if common.size == 0:
        raise NotEvaluable("the one- and six-contact A_c share no preload")
    change = 100.0 * np.abs(six["y"][i6] / one["y"][i1] - 1.0)
    return {"lhs": change, "rhs": np.full(common.size, INTERACTION_PERCENT)}


@extractor("fig6b-experiment-agreement")
def _fig6b_experiment(results):
    no_measured_data("the critical amplitudes measured in [12] (ten measurements per preload) are shown only "
                     "in Fig. 6b's plot")
