"""Claim extractors of Section 4.1, one contact: the critical amplitude A_c of Figs. 5a and 5b.

Decides the ledger's one-contact rows of Section 4.1 (``passmd/data/reference/claims.csv``): no
measurable step below the critical amplitude in Fig. 5a (a threshold over the amplitude grid, its
switch where the step crosses the measurable step) and a step growing with the amplitude above it; the
simulated A_c against the closed forms Eq. 7 and Eq. 8 (Fig. 5b), each a value check of the curve
A_c(F_p); flexible above rigid (Fig. 5b) as an ordering, two A_c within the search's final bracket
tied (:data:`AC_RESOLUTION_NM`). The helpers reading an A_c curve at a
reading (:func:`ac_curve`, :func:`against_closed_form`, :func:`on_paper_grid`) serve the six-contact
claims too (:mod:`passmd.experiments.critical_amplitude_six.claims`).

Each extractor reads the ledger's readings of Figs. 5 and 6
(:func:`~passmd.experiments.critical_amplitude_one.figures.ac_readings`,
:func:`~passmd.experiments.critical_amplitude_one.figures.fig5a_readings`: every run at every point of
the fly-back rule, the A_c protocol, the drive frequency, μ and, for flexible actuators, ζ)
through :func:`~passmd.experiments.critical_amplitude_one.figures.primary`, and compares with the
closed forms at the reading's μ (Eqs. 7–14 are evaluated at the μ of the runs they are compared
with). On a coarser grid than the paper's (the quick profile's preloads and amplitudes) a check
holding there is inconclusive and only a pointwise failure decides (the coarse-grid rule of
:mod:`passmd.ledger.rules`, :class:`passmd.ledger.checks.Subset`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd.experiments.critical_amplitude_one.figures import AC_PANELS, PROFILE_SETTINGS, primary
from passmd.ledger.checks import (
    ClaimFails,
    NoRun,
    NotEvaluable,
    Subset,
    extractor,
    reference_table,
)
from passmd.ledger.reference import REFERENCE_FRICTION_COEFFICIENT
from passmd.model.tables import PRELOAD_GRIDS

__all__ = ["AC_RESOLUTION_NM", "FLEXIBLE_AXES", "RIGID_AXES", "ac_curve", "against_closed_form",
           "on_paper_grid"]

#: Axes of passmd.ledger.readings the A_c curves depend on (rigid actuators: no ζ).
RIGID_AXES = ("flyback", "ac_protocol", "drive_frequency_s4", "friction_coefficient")
FLEXIBLE_AXES = ("flyback", "ac_protocol", "drive_frequency_s4", "damping_ratio", "friction_coefficient")
#: What two critical amplitudes must differ by to be ordered (nm): the final bracket of the A_c search,
#: which every profile searches to (:mod:`passmd.experiments.critical_amplitude_one.figures`).
AC_RESOLUTION_NM = PROFILE_SETTINGS["paper"].tolerance * 1e9


def on_paper_grid(ours, key: str, preloads, failures_decide: bool = True):
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


def ac_curve(results, key: str, actuator_model: str, reading) -> dict:
    """A_c of one panel's readings at a reading: ``{"x": preloads (N), "y": A_c (nm)}``."""
    rows = primary(results[f"{key}_readings"], actuator_model, reading)
    return {"x": rows["preload_N"].to_numpy(), "y": rows["critical_amplitude_nm"].to_numpy(), "x_unit": "N"}


def against_closed_form(results, key: str, actuator_model: str, reading, column: str) -> dict:
    """A_c of one panel at a reading, with the closed form ``column`` at the reading's μ (the committed
    reference file at the reference μ)."""
    curve = ac_curve(results, key, actuator_model, reading)
    mu = float(reading["friction_coefficient"])
    if not np.isclose(mu, REFERENCE_FRICTION_COEFFICIENT, rtol=1e-12, atol=0):
        table = reference_table(f"{key}_closed_form", mu)
        curve["reference"] = np.interp(curve["x"], table["preload_N"], table[column])
    return on_paper_grid(curve, key, curve["x"])


def _fig5a_steps(results, reading) -> pd.DataFrame:
    """Fig. 5a's runs at a reading, by amplitude, with ``step_nm``: the step read as A_c is read, the first
    (first fly-back) or the last (steady state)."""
    table = results["fig5a_readings"]
    rows = table[(table["flyback"] == reading["flyback"])
                 & np.isclose(table["frequency_Hz"], float(reading["drive_frequency_s4"]))
                 & np.isclose(table["damping_ratio"], float(reading["damping_ratio"]), rtol=1e-9, atol=0)
                 & np.isclose(table["friction_coefficient"], float(reading["friction_coefficient"]),
                              rtol=1e-9, atol=0)].sort_values("amplitude_nm")
    if rows.empty:
        raise NoRun(f"no Fig. 5a runs at {reading}")
    column = "first_step_nm" if reading["ac_protocol"] == "first" else "steady_step_nm"
    return rows.assign(step_nm=rows[column].to_numpy(dtype=float)).reset_index(drop=True)


def _on_amplitude_grid(ours, rows: pd.DataFrame, failures_decide: bool = True):
    """``ours`` on the paper profile's amplitude grid, else a :class:`~passmd.ledger.checks.Subset`: a
    step could hide between a coarser grid's amplitudes."""
    spacing = float(np.diff(rows["amplitude_nm"].to_numpy()).max())
    paper = PROFILE_SETTINGS["paper"].readings_amplitude_step * 1e9
    if spacing > paper * (1 + 1e-9):
        return Subset(ours, f"the amplitudes between its {spacing:g} nm steps (the paper profile's grid: "
                            f"{paper:g} nm)", failures_decide)
    return ours


@extractor("fig5a-no-step-below-50nm", depends_on=FLEXIBLE_AXES)
def _fig5a_no_step(results, reading) -> dict:
    rows = _fig5a_steps(results, reading)
    step, threshold = rows["step_nm"].to_numpy(), rows["threshold_nm"].to_numpy(dtype=float)
    holds = np.where(np.isfinite(step), step <= threshold, np.nan)
    # the measurable-step threshold less the step: where it crosses zero is the observed switch
    ours = {"x": rows["amplitude_nm"].to_numpy(), "holds": holds, "margin": threshold - step + 1e-12}
    return _on_amplitude_grid(ours, rows)


@extractor("fig5a-step-grows-above-ac", depends_on=FLEXIBLE_AXES)
def _fig5a_step_grows(results, reading) -> dict:
    # Fig. 5a above A_c: the step at every amplitude above the last one without a measurable step
    rows = _fig5a_steps(results, reading)
    still = np.flatnonzero(rows["step_nm"].to_numpy() <= rows["threshold_nm"].to_numpy(dtype=float))
    above = rows.iloc[(still.max() + 1) if still.size else 0:]
    if len(above) < 2:
        raise ClaimFails("fewer than two amplitudes with a measurable step up to the full stroke: the step "
                         "does not grow above A_c")
    ours = {"x": above["amplitude_nm"].to_numpy(), "y": above["step_nm"].to_numpy()}
    return _on_amplitude_grid(ours, rows, failures_decide=False)


@extractor("fig5b-rigid-ac-matches-eq7", depends_on=RIGID_AXES)
def _fig5b_rigid(results, reading) -> dict:
    return against_closed_form(results, "fig5b", "rigid", reading, "u_x_max_nm")


@extractor("fig5b-flexible-ac-matches-eq8", depends_on=FLEXIBLE_AXES)
def _fig5b_flexible(results, reading) -> dict:
    return against_closed_form(results, "fig5b", "flexible", reading, "u_x_max_plus_u_x_a_nm")


@extractor("fig5b-flexible-above-rigid", depends_on=FLEXIBLE_AXES)
def _fig5b_order(results, reading) -> dict:
    rigid = ac_curve(results, "fig5b", "rigid", reading)
    flexible = ac_curve(results, "fig5b", "flexible", reading)
    if not np.array_equal(rigid["x"], flexible["x"]):
        raise NotEvaluable("rigid and flexible A_c are not on the same preloads")
    return on_paper_grid({"lhs": flexible["y"], "rhs": rigid["y"], "at": rigid["x"], "at_unit": "N",
                          "resolution": AC_RESOLUTION_NM}, "fig5b", rigid["x"])
