"""Claim extractor of Section 3.2: the MDR's one-dimensional contact against the three-dimensional one.

Decides the ledger's Section 3.2 row (``passmd/data/reference/claims.csv``): the equivalent
one-dimensional contact of Eqs. 4–6 (springs of stiffness E*Δx and G*Δx under a profile of radius
R₁ = R/2) reproduces the three-dimensional Hertzian contact's normal force and the
Cattaneo–Mindlin tangential force, virgin loading and the Masing loops of unloading and reloading.
Ours is the largest deviation of the discrete contact (the chapter's finest spring grid,
:data:`~passmd.experiments.mdr_validation.figures.VALIDATION_SPRINGS`) from the closed forms over the
chapter's three comparisons (:func:`~passmd.experiments.mdr_validation.figures.mdr_normal`,
:func:`~passmd.experiments.mdr_validation.figures.mdr_virgin`,
:func:`~passmd.experiments.mdr_validation.figures.mdr_hysteresis`): the normal force relative to
Hertz, the tangential force relative to the sliding force μF_N. The spring grid of the normal
comparison is built here from Eqs. 4–5 without knowing the answer, so a wrong R₁ fails it.
"""

from __future__ import annotations

import numpy as np

from passmd.experiments.mdr_validation.figures import HYSTERESIS_SPRINGS, VALIDATION_SPRINGS
from passmd.ledger.checks import NotEvaluable, evidence, extractor

__all__ = ["mdr_deviations"]


def mdr_deviations(results) -> dict:
    """The largest deviation (%) of the discrete MDR contact from each closed form: ``normal`` (from Hertz,
    relative to it, the finest spring grid), ``virgin`` (from Cattaneo–Mindlin) and ``loops`` (from
    Masing), both relative to μF_N."""
    normal, virgin, loops = (results[k] for k in ("mdr_normal", "mdr_virgin", "mdr_hysteresis"))
    finest = max(VALIDATION_SPRINGS)
    if normal.empty or virgin.empty or loops.empty:
        raise NotEvaluable("an MDR comparison table is empty")
    sliding = float(virgin["sliding_force_N"].iloc[0])
    return {
        "normal": 100.0 * float(np.abs(normal[f"rel_error_{finest}"]).max()),
        "virgin": 100.0 * float(np.abs(virgin[f"discrete_{finest}_N"] - virgin["cattaneo_mindlin_N"]).max())
        / sliding,
        "loops": 100.0 * float(np.abs(loops[f"discrete_{HYSTERESIS_SPRINGS}_N"] - loops["masing_N"]).max())
        / sliding,
    }


@extractor("sec3-2-mdr-reproduces-3d-contact")
def _mdr_reproduces(results) -> float:
    return max(mdr_deviations(results).values())


@evidence("sec3-2-mdr-reproduces-3d-contact")
def _mdr_evidence(results) -> list:
    d = mdr_deviations(results)
    return [f"{max(VALIDATION_SPRINGS)} springs: normal force within {d['normal']:.3g} % of Hertz; "
            f"tangential force within {d['virgin']:.3g} % of μF_N of Cattaneo–Mindlin (virgin loading) and "
            f"{d['loops']:.3g} % of Masing (unloading and reloading)"]
