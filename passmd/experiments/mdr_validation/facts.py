"""Facts the MDR-validation chapter quotes (glue names → numbers), each from its figure's data
(:mod:`passmd.experiments.mdr_validation.figures`)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd.experiments.mdr_validation.figures import (
    HYSTERESIS_SPRINGS,
    VALIDATION_SPRINGS,
    convergence_validation,
    validation_contact,
)
from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import Drive
from passmd.runtime.units import from_si


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
    """Largest and full-depth |F_MDR/F_Hertz − 1| (%) per spring count of
    :func:`~passmd.experiments.mdr_validation.figures.mdr_normal`,
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
    """Largest |T − T_CM| / μF_N of the exact contact and (in %) of each discrete one
    (:func:`~passmd.experiments.mdr_validation.figures.mdr_virgin`)."""
    sliding = virgin["sliding_force_N"].iloc[0]

    def largest(column):
        return (np.abs(virgin[column] - virgin["cattaneo_mindlin_N"]) / sliding).max()

    facts = {"virgin_err_exact": largest("exact_N")}
    facts.update({f"virgin_err_{n}": largest(f"discrete_{n}_N") * 100 for n in VALIDATION_SPRINGS})
    return facts


def hysteresis_facts(loop: pd.DataFrame) -> dict:
    """Largest deviation from Masing relative to μF_N: exact contact, and discrete in %
    (:func:`~passmd.experiments.mdr_validation.figures.mdr_hysteresis`)."""
    sliding = validation_contact().sliding_force
    return {
        "loop_err_exact": (np.abs(loop["exact_N"] - loop["masing_N"]) / sliding).max(),
        "loop_err_1000": (np.abs(loop[f"discrete_{HYSTERESIS_SPRINGS}_N"] - loop["masing_N"]) / sliding).max()
        * 100,
    }


def convergence_facts(conv: pd.DataFrame, default_springs: int = PROTOCOL.springs) -> dict:
    """Fitted order, the largest deviation (%) at 1000 springs and at ``default_springs`` (the
    discrete contact's default number of springs, ``PROTOCOL.springs``)."""
    validation = convergence_validation(Drive(), springs=(default_springs,))
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
