"""Plots of the MDR-validation chapter: the springs of Fig. 4, normal force against Hertz,
virgin loading against Cattaneo–Mindlin, the hysteresis loop against Masing, convergence in
the number of springs and the cost per call. Forces in mN, lengths in nm and µm."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from passmd.runtime.units import from_si

__all__ = [
    "TARGET_ERROR_REL",
    "plot_convergence",
    "plot_cost",
    "plot_hysteresis",
    "plot_normal",
    "plot_springs",
    "plot_virgin",
]

#: Acceptance bound of the discrete contact's deviation, relative to μF_N (drawn as a line).
TARGET_ERROR_REL = 5e-3
_COLOURS = {"sticking": "tab:blue", "slipping": "tab:red"}


def plot_springs(df: pd.DataFrame):
    """Spring geometry (tangential deflections ×60) and spring forces with their stick limits."""
    first = df.iloc[0]
    x_um = from_si(df["position_m"].to_numpy(), "um")
    top_nm = -from_si(df["normal_deflection_m"].to_numpy(), "nm")  # head of each spring, below z = 0
    shift_um = from_si(df["tangential_deflection_m"].to_numpy(), "um") * 60.0  # exaggerated for display
    foot_nm = -1.6 * from_si(first["indentation_m"], "nm")
    status = np.where(df["slipping"], "slipping", "sticking")
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(7.5, 6.0), sharex=True, height_ratios=[3, 2])
    xx = np.linspace(x_um.min() * 1.25, x_um.max() * 1.25, 300)
    indenter = from_si(xx**2 * 1e-12 / first["hemisphere_radius_m"] - first["indentation_m"], "nm")
    ax.fill_between(xx, indenter, indenter.max() + 20, color="0.85", label="rigid 1-D profile $g(x) - d$")
    for xi, top, dx, st in zip(x_um, top_nm, shift_um, status, strict=True):
        ax.plot([xi, xi + dx], [foot_nm, top], color=_COLOURS[st], lw=1.5)
    for st, col in _COLOURS.items():
        ax.plot([], [], color=col, lw=1.5, label=f"spring {st}")
    ax.axhline(foot_nm, color="0.4", lw=3)
    ax.set_ylabel("z (nm)")
    ax.set_ylim(foot_nm - 45, indenter.max() * 0.2 + 10)
    ax.legend(loc="lower center", ncol=3, fontsize=8)
    ax.set_title(
        f"u = {from_si(first['displacement_m'], 'nm'):.1f} nm after turning at "
        f"{from_si(first['turn_m'], 'nm'):.1f} nm"
    )
    limit = from_si(first["friction_coefficient"] * df["normal_force_N"].to_numpy(), "mN")
    bx.fill_between(x_um, -limit, limit, color="0.9", label=r"stick range $\pm\mu f_{z,i}$")
    bx.scatter(x_um, from_si(df["tangential_force_N"].to_numpy(), "mN"), c=[_COLOURS[s] for s in status],
               s=18, zorder=3)
    bx.axhline(0, color="0.5", lw=0.5)
    bx.set_xlabel("spring position x (µm)")
    bx.set_ylabel("$f_{x,i}$ (mN)")
    bx.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    return fig


def _spring_counts(df: pd.DataFrame, prefix: str, suffix: str) -> list[int]:
    return [
        int(c[len(prefix) : -len(suffix)]) for c in df.columns if c.startswith(prefix) and c.endswith(suffix)
    ]


def plot_normal(df: pd.DataFrame):
    """Normal force against indentation (MDR grids and Hertz), and the relative deviation."""
    d_nm = from_si(df["indentation_m"].to_numpy(), "nm")
    counts = _spring_counts(df, "mdr_", "_N")
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(9, 3.6))
    ax.plot(d_nm, df["hertz_N"], "k-", label="Hertz")
    for n, mark in zip(counts[:2], ("o", "s"), strict=False):
        ax.plot(d_nm[::4], df[f"mdr_{n}_N"][::4], mark, ms=4, mfc="none", label=f"MDR, N = {n}")
    ax.set_xlabel("indentation d (nm)")
    ax.set_ylabel("normal force $F_N$ (N)")
    ax.legend()
    for n in counts:
        bx.semilogy(d_nm, df[f"rel_error_{n}"].abs(), label=f"N = {n}")
    bx.set_xlabel("indentation d (nm)")
    bx.set_ylabel(r"$|F_{MDR}/F_{Hertz} - 1|$")
    bx.legend()
    fig.tight_layout()
    return fig


def plot_virgin(df: pd.DataFrame):
    """Virgin loading: Cattaneo–Mindlin, exact and discrete MDR; deviations relative to μF_N."""
    u_nm = from_si(df["u_m"].to_numpy(), "nm")
    sliding = float(df["sliding_force_N"].iloc[0])
    counts = _spring_counts(df, "discrete_", "_N")
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(9, 3.6))
    ax.plot(u_nm, from_si(df["cattaneo_mindlin_N"], "mN"), "k-", lw=2.5, alpha=0.35, label="Cattaneo–Mindlin")
    ax.plot(u_nm, from_si(df["exact_N"], "mN"), "C0-", lw=1, label="exact MDR")
    ax.plot(u_nm[::4], from_si(df[f"discrete_{counts[0]}_N"][::4], "mN"), "C3o", ms=4, mfc="none",
            label=f"discrete, N = {counts[0]}")
    ax.set_xlabel("tangential displacement u (nm)")
    ax.set_ylabel("friction force T (mN)")
    ax.legend()
    for n in counts:
        err = np.abs(df[f"discrete_{n}_N"] - df["cattaneo_mindlin_N"]) / sliding
        bx.semilogy(u_nm, err.where(err > 0), label=f"N = {n}")  # exact zeros (full sliding) not drawn
    bx.set_xlabel("tangential displacement u (nm)")
    bx.set_ylabel(r"$|T - T_{CM}| / \mu F_N$")
    bx.legend()
    fig.tight_layout()
    return fig


def plot_hysteresis(df: pd.DataFrame):
    """The major loop with its nested minor loop: Masing reference, exact and discrete MDR."""
    u_nm = from_si(df["u_m"].to_numpy(), "nm")
    (n,) = _spring_counts(df, "discrete_", "_N")
    fig, ax = plt.subplots(figsize=(6.5, 4.6))
    ax.plot(u_nm, from_si(df["masing_N"], "mN"), "k-", lw=3, alpha=0.3, label="Masing / Mindlin–Deresiewicz")
    ax.plot(u_nm, from_si(df["exact_N"], "mN"), "C0-", lw=1, label="exact MDR")
    ax.plot(u_nm[::5], from_si(df[f"discrete_{n}_N"][::5], "mN"), "C3.", ms=4, label=f"discrete, N = {n}")
    for row in df[df["turn"] != ""].itertuples():
        ax.annotate(row.turn, (from_si(row.u_m, "nm"), from_si(row.exact_N, "mN")),
                    textcoords="offset points", xytext=(6, -4))
    ax.set_xlabel("tangential displacement u (nm)")
    ax.set_ylabel("friction force T (mN)")
    ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    return fig


def plot_convergence(df: pd.DataFrame):
    """Largest and rms deviation of the discrete contact from the exact one against N, with the fit."""
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.loglog(df["springs"], df["max_error_rel"], "o", label="max error")
    ax.loglog(df["springs"], df["rms_error_rel"], "s", mfc="none", label="rms error")
    fit = df[df["fit_rel"].notna()]
    ax.loglog(
        fit["springs"], fit["fit_rel"], "k--", label=f"fit: order {float(df['fitted_order'].iloc[0]):.2f}"
    )
    ax.axhline(TARGET_ERROR_REL, color="C3", lw=0.8, ls=":", label=r"0.5 % of $\mu F_N$")
    ax.set_xlabel("springs N")
    ax.set_ylabel(r"$|T_N - T_\infty| / \mu F_N$")
    ax.legend()
    fig.tight_layout()
    return fig


def plot_cost(df: pd.DataFrame):
    """Cost per contact update: discrete MDR against N, the exact contact on both benchmark paths."""
    disc = df[df["model"] == "discrete"]
    exact = df[(df["model"] == "exact") & (df["kernel"] == "contact_update")]
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.loglog(disc["springs"], disc["ns_per_call_median"], "o-", label="discrete MDR, contact_update")
    for _, row in exact.iterrows():
        ax.axhline(row["ns_per_call_median"], ls="--" if row["path"] == "ring-down" else "-", color="C1",
                   label=f"exact MDR, {row['path']} path")
    ax.set_xlabel("springs N")
    ax.set_ylabel("cost per call (ns)")
    ax.legend()
    fig.tight_layout()
    return fig
