"""Claim extractors of Section 4.1, six contacts: the critical amplitude A_c of Figs. 6a–c.

Decides the ledger's six-contact rows of Section 4.1 (``passmd/data/reference/claims.csv``): the
simulated A_c against the closed forms Eq. 11 (Fig. 6a) and Eq. 12 (Figs. 6b, 6c), each a value check
of the curve A_c(F_p); A_c closer to Eq. 11's u_x,max,e than to either form of Eq. 10 (Fig. 6a) and to
Eq. 12 than to either form of Eq. 13 (Figs. 6b, 6c; deviations from
:func:`passmd.ledger.checks.curve_deviation`), and the actuators' interaction changing A_c (six
contacts against each side's own contact alone, at the same normal force) as orderings. Fig. 6b's
agreement with the experiment is a claim about the experiment (:mod:`passmd.ledger.rules`). The
readings, the coarse-grid rule and the closed forms at the reading's μ are those of
:mod:`passmd.experiments.critical_amplitude_one.claims`.
"""

from __future__ import annotations

import numpy as np

from passmd.experiments.critical_amplitude_one.claims import (
    FLEXIBLE_AXES,
    RIGID_AXES,
    ac_curve,
    against_closed_form,
    on_paper_grid,
)
from passmd.ledger.checks import NotEvaluable, curve_deviation, experiment_claim, extractor
from passmd.model.theory import normal_forces
from passmd.protocols.diagnosis import AGREEMENT

__all__ = ["INTERACTION_PERCENT", "side_alone"]


@extractor("fig6a-rigid-ac-matches-eq11", depends_on=RIGID_AXES)
def _fig6a_eq11(results, reading) -> dict:
    return against_closed_form(results, "fig6a", "rigid", reading, "u_x_max_e_nm")


@extractor("fig6a-rigid-ac-not-eq10", depends_on=RIGID_AXES)
def _fig6a_not_eq10(results, reading) -> dict:
    c = ac_curve(results, "fig6a", "rigid", reading)
    mu = float(reading["friction_coefficient"])
    own = curve_deviation(c["x"], c["y"], "fig6a_closed_form", "u_x_max_e_nm", mu)
    sides = min(curve_deviation(c["x"], c["y"], "fig6a_closed_form", column, mu)
                for column in ("u_x_max_1_nm", "u_x_max_2_nm"))
    # deviations over the whole curve: on part of the grid neither order decides
    return on_paper_grid({"lhs": own, "rhs": sides}, "fig6a", c["x"], failures_decide=False)


@extractor("fig6b-flexible-r1-ac-matches-eq12", depends_on=FLEXIBLE_AXES)
def _fig6b_eq12(results, reading) -> dict:
    return against_closed_form(results, "fig6b", "flexible", reading, "u_x_max_e_star_nm")


@extractor("fig6c-flexible-r025-ac-matches-eq12", depends_on=FLEXIBLE_AXES)
def _fig6c_eq12(results, reading) -> dict:
    return against_closed_form(results, "fig6c", "flexible", reading, "u_x_max_e_star_nm")


def _not_single_side(results, key: str, reading) -> dict:
    c = ac_curve(results, key, "flexible", reading)
    table, mu = f"{key}_closed_form", float(reading["friction_coefficient"])
    own = curve_deviation(c["x"], c["y"], table, "u_x_max_e_star_nm", mu)
    sides = min(curve_deviation(c["x"], c["y"], table, column, mu)
                for column in ("u_x_max_1_star_nm", "u_x_max_2_star_nm"))
    return on_paper_grid({"lhs": own, "rhs": sides}, key, c["x"], failures_decide=False)


@extractor("fig6b-flexible-r1-ac-not-eq13", depends_on=FLEXIBLE_AXES)
def _fig6b_not_eq13(results, reading) -> dict:
    return _not_single_side(results, "fig6b", reading)


@extractor("fig6c-flexible-r025-ac-not-eq13", depends_on=FLEXIBLE_AXES)
def _fig6c_not_eq13(results, reading) -> dict:
    return _not_single_side(results, "fig6c", reading)


#: The smallest change of A_c the actuators' interaction must make to be a 'strong influence' (%):
#: the band within which the claims call A_c and a closed form in agreement (Fig. 6,
#: :data:`passmd.protocols.diagnosis.AGREEMENT`).
INTERACTION_PERCENT = 100.0 * AGREEMENT


def side_alone(results, reading) -> dict:
    """Six flexible contacts (Fig. 6b) against each side's contact alone at its own normal force.

    Eq. 1 gives the six-contact drive different normal forces on its two sides, F_N1 = 0.707 F_p
    and F_N2 = 0.354 F_p; without interaction among the actuators its A_c would be that of the side
    that slides alone. The one-contact A_c (Fig. 5b, F_N = F_p, same reading) is interpolated
    linearly at F_N1 and F_N2 (inside its preload grid only; the interpolation error of a
    (F_N)^(2/3) curve on those grids is a few % at most, below the 10 % the claim needs).

    Returns ``preload_N``, ``six_nm`` and ``alone_nm`` (each side's one-contact A_c, two columns).
    """
    six = ac_curve(results, "fig6b", "flexible", reading)
    one = ac_curve(results, "fig5b", "flexible", reading)
    f1, f2 = normal_forces(six["x"], contacts=6)
    low, high = one["x"].min(), one["x"].max()
    inside = (f1 >= low) & (f1 <= high) & (f2 >= low) & (f2 <= high)
    if not inside.any():
        raise NotEvaluable("no six-contact preload whose two normal forces (Eq. 1) lie on the one-contact "
                           "preload grid")
    alone = np.column_stack([np.interp(f[inside], one["x"], one["y"]) for f in (f1, f2)])
    return {"preload_N": six["x"][inside], "six_nm": six["y"][inside], "alone_nm": alone}


@extractor("sec4-1-interaction-changes-ac", depends_on=FLEXIBLE_AXES)
def _interaction(results, reading) -> dict:
    # the change the interaction makes: against the nearer of the two sides alone, at every preload
    sides = side_alone(results, reading)
    change = 100.0 * np.min(np.abs(sides["six_nm"][:, None] / sides["alone_nm"] - 1.0), axis=1)
    ours = {"lhs": change, "rhs": np.full(change.size, INTERACTION_PERCENT), "at": sides["preload_N"],
            "at_unit": "N"}
    # each side's A_c is interpolated on the one-contact grid: on part of the two grids, a failure is
    # not the paper grids' either
    grids = np.intersect1d(*(np.round(ac_curve(results, key, "flexible", reading)["x"], 9)
                             for key in ("fig5b", "fig6b")))
    return on_paper_grid(ours, "fig6b", grids, failures_decide=False)


_FIG6B_EXPERIMENT = experiment_claim(
    "fig6b-experiment-agreement",
    "the critical amplitudes measured in [12] (ten measurements per preload) are shown only in Fig. 6b's "
    "plot")
