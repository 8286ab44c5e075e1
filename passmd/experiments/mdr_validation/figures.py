"""Figures of the MDR-validation chapter: the contact model against Hertz, Cattaneo–Mindlin and
Masing, its convergence in the number of springs and its cost.

The computations are :mod:`passmd.experiments.mdr_validation.closed_forms` (protocol level); each
function here is a
row of :mod:`passmd.experiments.figure_table`: it takes a :class:`~passmd.runtime.config.RunConfig` (the
figures are
the same on every profile), uses one contact of side 1 of the default drive
(:func:`validation_contact`) and adds the scalar columns its plot needs.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd.experiments.mdr_validation import closed_forms
from passmd.experiments.numerics.benchmarks import benchmark_results
from passmd.model.defaults import PROTOCOL
from passmd.model.mdr_contact import MDRContact
from passmd.model.parameters import Drive
from passmd.runtime.config import RunConfig
from passmd.runtime.units import from_si

__all__ = [
    "HYSTERESIS_SPRINGS",
    "HYSTERESIS_TURNS",
    "VALIDATION_SPRINGS",
    "mdr_convergence",
    "mdr_cost",
    "mdr_hysteresis",
    "mdr_normal",
    "mdr_springs",
    "mdr_virgin",
    "validation_contact",
]

#: Spring counts of the normal and virgin-loading comparisons.
VALIDATION_SPRINGS = (20, 100, 1000)
#: Spring count of the discrete contact in the hysteresis comparison.
HYSTERESIS_SPRINGS = 1000
#: Names of the turning points 1–4 of :func:`passmd.experiments.mdr_validation.closed_forms.hysteresis_path`.
HYSTERESIS_TURNS = ("A", "−A", "B", "C")


def validation_contact(springs: int | None = None) -> MDRContact:
    """The chapter's contact: side 1 of the default drive (exact, or ``springs`` discrete springs)."""
    return MDRContact.for_drive(Drive(), side=0, springs=springs)


def mdr_springs(config: RunConfig) -> pd.DataFrame:
    """:func:`passmd.experiments.mdr_validation.closed_forms.spring_picture` plus the exact contact's
    indentation (m),
    the hemisphere radius (m) and μ."""
    drive, exact = Drive(), validation_contact()
    df = closed_forms.spring_picture(drive)
    df["indentation_m"] = exact.indentation
    df["hemisphere_radius_m"] = drive.hemisphere_radius
    df["friction_coefficient"] = drive.friction_coefficient
    return df


def mdr_normal(config: RunConfig) -> pd.DataFrame:
    """:func:`passmd.experiments.mdr_validation.closed_forms.normal_validation` for
    :data:`VALIDATION_SPRINGS`."""
    return closed_forms.normal_validation(Drive(), springs=VALIDATION_SPRINGS)


def mdr_virgin(config: RunConfig) -> pd.DataFrame:
    """:func:`passmd.experiments.mdr_validation.closed_forms.virgin_validation` plus ``sliding_force_N``
    (μF_N)."""
    df = closed_forms.virgin_validation(Drive(), springs=VALIDATION_SPRINGS)
    df["sliding_force_N"] = validation_contact().sliding_force
    return df


def mdr_hysteresis(config: RunConfig) -> pd.DataFrame:
    """:func:`passmd.experiments.mdr_validation.closed_forms.hysteresis_validation` plus ``turn``: the
    name of each
    turning point (:data:`HYSTERESIS_TURNS`) on the first row that reaches it, else ``""``."""
    df = closed_forms.hysteresis_validation(Drive(), springs=HYSTERESIS_SPRINGS)
    u_max = validation_contact().presliding
    _, _, turns = closed_forms.hysteresis_path()
    df["turn"] = ""
    for name, t in zip(HYSTERESIS_TURNS, turns[1:5], strict=True):
        first = df.index[np.isclose(df["u_m"], t * u_max, rtol=1e-12, atol=0)][0]
        df.loc[first, "turn"] = name
    return df


def mdr_convergence(config: RunConfig) -> pd.DataFrame:
    """:func:`passmd.experiments.mdr_validation.closed_forms.convergence_validation` plus the fitted
    order and its line.

    ``fitted_order`` is :func:`passmd.experiments.mdr_validation.closed_forms.fitted_order` (N ≥ 100);
    ``fit_rel`` the
    least-squares power law of ``max_error_rel`` over those N (NaN below).
    """
    df = closed_forms.convergence_validation(Drive())
    fit = df["springs"] >= 100
    coef = np.polyfit(np.log(df.loc[fit, "springs"]), np.log(df.loc[fit, "max_error_rel"]), 1)
    df["fit_rel"] = np.where(fit, np.exp(np.polyval(coef, np.log(df["springs"]))), np.nan)
    df["fitted_order"] = closed_forms.fitted_order(df)
    return df


def mdr_cost(config: RunConfig) -> pd.DataFrame:
    """Cost per contact update from ``benchmarks/bench_contact.py``'s results file, with the
    ``repeats`` and ``numba`` version it was measured with."""
    bench = benchmark_results("contact")
    df = pd.DataFrame(bench["rows"])
    df["repeats"] = bench["meta"]["repeats"]
    df["numba"] = bench["meta"]["numba"]
    return df


# --------------------------------------------------------------------------------------
# Facts the chapter quotes (glue names -> numbers), each from its figure's data
# --------------------------------------------------------------------------------------


def contact_facts() -> dict:
    """F_N1 (N), μF_N (mN), u_max (nm), Hertz radius a (µm) and 2aG* (MN/m) of the chapter's contact."""
    exact = validation_contact()
    return {
        "normal_force_N": exact.normal_force,
        "sliding_force_mN": exact.sliding_force * 1e3,
        "u_max_nm": from_si(exact.presliding, "nm"),
        "contact_radius_um": from_si(exact.contact_radius, "um"),
        "stiffness_MN_per_m": exact.stiffness / 1e6,
    }


def normal_facts(normal: pd.DataFrame) -> dict:
    """Largest and full-depth |F_MDR/F_Hertz − 1| (%) per spring count of :func:`mdr_normal`,
    and the deviation (%) of the 1000-spring contact's own indentation from Hertz'."""
    facts = {}
    for n in VALIDATION_SPRINGS:
        facts[f"normal_err_{n}"] = normal[f"rel_error_{n}"].abs().max() * 100
        facts[f"normal_err_end_{n}"] = normal[f"rel_error_{n}"].abs().iloc[-1] * 100
    facts["indent_err_1000"] = (
        abs(validation_contact(1000).indentation / validation_contact().indentation - 1) * 100
    )
    return facts


def virgin_facts(virgin: pd.DataFrame) -> dict:
    """Largest |T − T_CM| / μF_N of the exact contact and (in %) of each discrete one (:func:`mdr_virgin`)."""
    sliding = virgin["sliding_force_N"].iloc[0]

    def largest(column):
        return (np.abs(virgin[column] - virgin["cattaneo_mindlin_N"]) / sliding).max()

    facts = {"virgin_err_exact": largest("exact_N")}
    facts.update({f"virgin_err_{n}": largest(f"discrete_{n}_N") * 100 for n in VALIDATION_SPRINGS})
    return facts


def hysteresis_facts(loop: pd.DataFrame) -> dict:
    """Largest deviation from Masing relative to μF_N: exact contact, and discrete in %
    (:func:`mdr_hysteresis`)."""
    sliding = validation_contact().sliding_force
    return {
        "loop_err_exact": (np.abs(loop["exact_N"] - loop["masing_N"]) / sliding).max(),
        "loop_err_1000": (np.abs(loop[f"discrete_{HYSTERESIS_SPRINGS}_N"] - loop["masing_N"]) / sliding).max()
        * 100,
    }


def convergence_facts(conv: pd.DataFrame, default_springs: int = PROTOCOL.springs) -> dict:
    """Fitted order, the largest deviation (%) at 1000 springs and at ``default_springs`` (the
    discrete contact's default number of springs, ``PROTOCOL.springs``)."""
    validation = closed_forms.convergence_validation(Drive(), springs=(default_springs,))
    at_default = validation["max_error_rel"].iloc[0]
    return {
        "conv_order": conv["fitted_order"].iloc[0],
        "conv_err_1000": conv.loc[conv["springs"] == 1000, "max_error_rel"].iloc[0] * 100,
        "default_springs": default_springs,
        "conv_err_default": at_default * 100,
    }


def cost_facts(cost: pd.DataFrame) -> dict:
    """Cost of the exact contact on both paths (ns), its ring-down depth, the discrete contact's cost at
    200 springs, per spring (ns, linear fit) and its ratio to the exact contact at 1000 springs."""
    disc = cost[cost["model"] == "discrete"]
    exact = cost[(cost["model"] == "exact") & (cost["kernel"] == "contact_update")]
    exact_ns = exact.loc[exact["path"] == "oscillation", "ns_per_call_median"].iloc[0]
    return {
        "cost_exact_ns": exact_ns,
        "cost_exact_ring_ns": exact.loc[exact["path"] == "ring-down", "ns_per_call_median"].iloc[0],
        "ring_depth": int(exact.loc[exact["path"] == "ring-down", "max_depth"].iloc[0]),
        "cost_200_ns": disc.loc[disc["springs"] == PROTOCOL.springs, "ns_per_call_median"].iloc[0],
        "cost_ratio_1000": disc.loc[disc["springs"] == 1000, "ns_per_call_median"].iloc[0] / exact_ns,
        "per_spring_ns": np.polyfit(disc["springs"], disc["ns_per_call_median"], 1)[0],
    }
