"""Figures of the MDR-validation chapter: the contact model against Hertz, Cattaneo–Mindlin and
Masing, its convergence in the number of springs and its cost.

The computations are :mod:`passmd.mdr_validation` (protocol level); each function here is a
row of :mod:`passmd.figures`: it takes a :class:`~passmd.config.RunConfig` (the figures are
the same on every profile), uses one contact of side 1 of the default drive
(:func:`validation_contact`) and adds the scalar columns its plot needs.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd import mdr_validation as mv
from passmd.config import RunConfig
from passmd.contact import MDRContact
from passmd.experiments.numerics import benchmark_results
from passmd.parameters import Drive

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
#: Names of the turning points 1–4 of :func:`passmd.mdr_validation.hysteresis_path`.
HYSTERESIS_TURNS = ("A", "−A", "B", "C")


def validation_contact(springs: int | None = None) -> MDRContact:
    """The chapter's contact: side 1 of the default drive (exact, or ``springs`` discrete springs)."""
    return MDRContact.for_drive(Drive(), side=0, springs=springs)


def mdr_springs(config: RunConfig) -> pd.DataFrame:
    """:func:`passmd.mdr_validation.spring_picture` plus the exact contact's indentation (m),
    the hemisphere radius (m) and μ."""
    drive, exact = Drive(), validation_contact()
    df = mv.spring_picture(drive)
    df["indentation_m"] = exact.indentation
    df["hemisphere_radius_m"] = drive.hemisphere_radius
    df["friction_coefficient"] = drive.friction_coefficient
    return df


def mdr_normal(config: RunConfig) -> pd.DataFrame:
    """:func:`passmd.mdr_validation.normal_validation` for :data:`VALIDATION_SPRINGS`."""
    return mv.normal_validation(Drive(), springs=VALIDATION_SPRINGS)


def mdr_virgin(config: RunConfig) -> pd.DataFrame:
    """:func:`passmd.mdr_validation.virgin_validation` plus ``sliding_force_N`` (μF_N)."""
    df = mv.virgin_validation(Drive(), springs=VALIDATION_SPRINGS)
    df["sliding_force_N"] = validation_contact().sliding_force
    return df


def mdr_hysteresis(config: RunConfig) -> pd.DataFrame:
    """:func:`passmd.mdr_validation.hysteresis_validation` plus ``turn``: the name of each
    turning point (:data:`HYSTERESIS_TURNS`) on the first row that reaches it, else ``""``."""
    df = mv.hysteresis_validation(Drive(), springs=HYSTERESIS_SPRINGS)
    u_max = validation_contact().presliding
    _, _, turns = mv.hysteresis_path()
    df["turn"] = ""
    for name, t in zip(HYSTERESIS_TURNS, turns[1:5], strict=True):
        first = df.index[np.isclose(df["u_m"], t * u_max, rtol=1e-12, atol=0)][0]
        df.loc[first, "turn"] = name
    return df


def mdr_convergence(config: RunConfig) -> pd.DataFrame:
    """:func:`passmd.mdr_validation.convergence_validation` plus the fitted order and its line.

    ``fitted_order`` is :func:`passmd.mdr_validation.fitted_order` (N ≥ 100); ``fit_rel`` the
    least-squares power law of ``max_error_rel`` over those N (NaN below).
    """
    df = mv.convergence_validation(Drive())
    fit = df["springs"] >= 100
    coef = np.polyfit(np.log(df.loc[fit, "springs"]), np.log(df.loc[fit, "max_error_rel"]), 1)
    df["fit_rel"] = np.where(fit, np.exp(np.polyval(coef, np.log(df["springs"]))), np.nan)
    df["fitted_order"] = mv.fitted_order(df)
    return df


def mdr_cost(config: RunConfig) -> pd.DataFrame:
    """Cost per contact update from ``benchmarks/bench_contact.py``'s results file, with the
    ``repeats`` and ``numba`` version it was measured with."""
    bench = benchmark_results("contact")
    df = pd.DataFrame(bench["rows"])
    df["repeats"] = bench["meta"]["repeats"]
    df["numba"] = bench["meta"]["numba"]
    return df
