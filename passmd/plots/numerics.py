"""Plots of the numerics section: time-step convergence and the rigid Coulomb limit."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from passmd.time_steps import CONVERGED_ACCURACY

__all__ = ["CONVERGED_STEP_NM", "plot_convergence", "plot_coulomb_limit"]

#: Position error drawn as the convergence target (:data:`passmd.time_steps.CONVERGED_ACCURACY`) (nm).
CONVERGED_STEP_NM = CONVERGED_ACCURACY * 1e9


def plot_convergence(df: pd.DataFrame):
    """|position error| after the run against the step refinement, per configuration and step control."""
    fig, ax = plt.subplots(figsize=(6.4, 4))
    for (label, control), g in df.groupby(["configuration", "step_control"], sort=False):
        g = g[g["error_m"] != 0]
        ax.loglog(g["resolution"], np.abs(g["error_m"]) * 1e9, "o-", label=f"{label} ({control} step)")
    r = np.array(sorted(df["resolution"].unique()))
    ax.loglog(r, 0.02 * r**-2.0, "k:", label="slope −2")
    ax.axhline(CONVERGED_STEP_NM, color="grey", lw=0.8, ls="--")
    ax.set_xlabel("step refinement (1 = default)")
    ax.set_ylabel("|position error| after 3 periods (nm)")
    ax.legend(fontsize=7)
    return fig


def plot_coulomb_limit(df: pd.DataFrame):
    """|simulated − Coulomb step| against the factor on the contact moduli, with the expected slope."""
    fig, ax = plt.subplots(figsize=(6.4, 4))
    for label, g in df.groupby("configuration", sort=False):
        ax.loglog(
            g["scale"],
            np.abs(g["difference_m"]) * 1e9,
            "o-",
            label=f"{label} (rate {float(g['rate'].iloc[0]):.2f})",
        )
    k = np.array(sorted(df["scale"].unique()))
    first = df[df["scale"] == k[0]]
    ref = float(np.abs(first["difference_m"]).max() * 1e9)
    expected = float(df["expected_rate"].iloc[0])
    ax.loglog(
        k,
        ref * (k / k[0]) ** -expected,
        "k:",
        label=f"slope −{expected:.2f} (presliding $\\propto k^{{-2/3}}$)",
    )
    ax.set_xlabel("factor k on the contact moduli E*, G*")
    ax.set_ylabel("|simulated step − Coulomb step| (nm)")
    ax.legend(fontsize=7)
    return fig
