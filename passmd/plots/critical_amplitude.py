"""Plots of the critical-amplitude figures (Figs. 5, 6 and the sensitivity panels).

Each function takes the tidy DataFrame of a Section 4.1 figure (:mod:`passmd.experiments.figure_table`)
and returns a matplotlib Figure: lengths in nm, forces in N, frequencies in Hz, the
paper's colours where it has them (Fig. 5b: rigid green, flexible black; Fig. 6:
u_x,max,e red).
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from passmd.model.defaults import PROTOCOL
from passmd.model.tables import ACTUATOR_DAMPING_RATIO

COLOURS = {"rigid": "tab:green", "flexible": "black"}
SIDE_COLOURS = {1: "tab:blue", 2: "tab:orange", "e": "tab:red"}


def _steady(rows: pd.DataFrame, flyback: str, primary: bool = True) -> pd.DataFrame:
    sel = rows[(rows["protocol"] == "steady") & (rows["flyback"] == flyback)]
    if primary:
        sel = sel[np.isclose(sel["frequency_Hz"], PROTOCOL.drive_frequency)]
    return sel.sort_values("preload_N")


def _first(rows: pd.DataFrame, flyback: str) -> pd.DataFrame:
    return rows[(rows["protocol"] == "first") & (rows["flyback"] == flyback)].sort_values("preload_N")


def _band(ax, rows: pd.DataFrame, colour: str, label: str) -> None:
    """Shade min–max of the steady-state A_c over the drive frequencies (slew-rate fly-back)."""
    steady = _steady(rows, "slew", primary=False)
    freqs = np.unique(steady["frequency_Hz"])
    if freqs.size < 2:
        return
    spread = steady.groupby("preload_N")["critical_amplitude_nm"].agg(["min", "max"])
    ax.fill_between(spread.index, spread["min"], spread["max"], color=colour, alpha=0.15, lw=0,
                    label=f"{label}, {freqs.min():g}–{freqs.max():g} Hz")


def _simulated(ax, rows: pd.DataFrame, colour: str, name: str, flexible: bool) -> None:
    """Draw the simulated A_c of one actuator model: primary, band, first fly-back, fixed fly-back.

    Only the rows at the default actuator damping ratio: the ledger's ζ readings are not drawn.
    """
    if "damping_ratio" in rows:
        rows = rows[np.isclose(rows["damping_ratio"], ACTUATOR_DAMPING_RATIO, rtol=1e-9, atol=0)]
    main = _steady(rows, "slew")
    ax.plot(main["preload_N"], main["critical_amplitude_nm"], "o-", color=colour, ms=4,
            label=f"{name}, steady state {PROTOCOL.drive_frequency:g} Hz")
    _band(ax, rows, colour, f"{name}, steady state")
    first = _first(rows, "slew")
    ax.plot(first["preload_N"], first["critical_amplitude_nm"], "s", mfc="none", color=colour, ms=5,
            label=f"{name}, first fly-back")
    if flexible:
        fixed = _steady(rows, "fixed")
        ax.plot(fixed["preload_N"], fixed["critical_amplitude_nm"], "^--", color=colour, ms=4, lw=0.8,
                label=f"{name}, steady state, 2 µs fly-back")
        first_fixed = _first(rows, "fixed")
        ax.plot(first_fixed["preload_N"], first_fixed["critical_amplitude_nm"], "x", color=colour, ms=5,
                label=f"{name}, first fly-back, 2 µs fly-back")


def _closed(ax, rows: pd.DataFrame, column: str, colour: str, label: str, style: str = "--") -> None:
    curve = rows.drop_duplicates("preload_N").sort_values("preload_N")
    ax.plot(curve["preload_N"], curve[column], style, color=colour, lw=1.5, label=label)


def _finish(fig, ax, title: str, xlabel: str = "preload $F_p$ (N)") -> None:
    ax.set_xlabel(xlabel)
    ax.set_ylabel("critical amplitude $A_c$ (nm)")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.set_ylim(bottom=0)
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()


def plot_fig5a(df: pd.DataFrame):
    """Fig. 5a: step size against actuation amplitude (one contact, 0.4 N, R = 1 mm).

    Left the paper's full range, right a zoom on the onset (0.5–1.6 × Eq. 8).
    """
    fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.4))
    styles = {
        ("rigid", "slew"): ("tab:green", "rigid"),
        ("flexible", "slew"): ("black", "flexible"),
        ("flexible", "fixed"): ("tab:gray", "flexible, 2 µs fly-back"),
    }
    first = df.iloc[0]
    for ax in axes:
        for (model, flyback), rows in df.groupby(["actuator_model", "flyback"], sort=False):
            colour, name = styles[(model, flyback)]
            rows = rows.sort_values("amplitude_nm")
            ax.plot(rows["amplitude_nm"], rows["steady_step_nm"], ".-", color=colour, lw=1.4, ms=4,
                    label=f"{name}: steady-state step")
            ax.plot(rows["amplitude_nm"], rows["first_step_nm"], ":", color=colour, lw=1.2,
                    label=f"{name}: first step")
        ax.axhline(first["threshold_nm"], color="tab:red", lw=0.8,
                   label=f"measurable step {first['threshold_nm']:g} nm")
        ax.axvline(first["u_x_max_nm"], color="tab:green", ls="--", lw=0.8, label="$u_{x,max}$ (Eq. 7)")
        ax.axvline(first["u_x_max_plus_u_x_a_nm"], color="black", ls="--", lw=0.8,
                   label="$u_{x,max} + u_{x,a}$ (Eq. 8)")
        ax.set_xlabel("actuation amplitude $A$ (nm)")
        ax.set_ylabel("step size (nm)")
        ax.grid(alpha=0.3)
    eq8 = first["u_x_max_plus_u_x_a_nm"]
    lo, hi = 0.5 * eq8, 1.6 * eq8
    near = df[(df["amplitude_nm"] >= lo) & (df["amplitude_nm"] <= hi)]
    top = max(near[["steady_step_nm", "first_step_nm"]].to_numpy().max(), 1.0) if len(near) else 1.0
    axes[1].set_xlim(lo, hi)
    axes[1].set_ylim(-0.1 * top, 1.1 * top)
    axes[0].set_title(
        f"One contact, $F_p$ = {first['preload_N']:g} N, R = 1 mm, {first['frequency_Hz']:g} Hz", fontsize=10
    )
    axes[1].set_title("near the onset", fontsize=10)
    axes[0].legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    return fig


def plot_fig5b(df: pd.DataFrame):
    """Fig. 5b: A_c against preload, one contact, rigid (green) and flexible (black), with Eqs. 7, 8."""
    fig, ax = plt.subplots(figsize=(7.2, 5.2))
    for model, name in (("rigid", "$A_c$ rigid"), ("flexible", "$A_c$ flexible")):
        rows = df[df["actuator_model"] == model]
        if len(rows):
            _simulated(ax, rows, COLOURS[model], name, model == "flexible")
    _closed(ax, df, "u_x_max_nm", COLOURS["rigid"], "$u_{x,max}$ (Eq. 7)")
    _closed(ax, df, "u_x_max_plus_u_x_a_nm", COLOURS["flexible"], "$u_{x,max} + u_{x,a}$ (Eq. 8)")
    _finish(fig, ax, "One contact, R = 1 mm")
    return fig


def plot_fig6(df: pd.DataFrame):
    """Fig. 6a/b/c: A_c against preload, six contacts, with Eqs. 10–14."""
    fig, ax = plt.subplots(figsize=(7.2, 5.2))
    model = df["actuator_model"].iloc[0]
    radius = df["radius_mm"].iloc[0]
    _simulated(ax, df, COLOURS[model], "$A_c$", model == "flexible")
    if model == "rigid":
        curves = [
            ("u_x_max_1_nm", 1, "$u_{x,max,1}$ (Eq. 10)"),
            ("u_x_max_2_nm", 2, "$u_{x,max,2}$ (Eq. 10)"),
            ("u_x_max_e_nm", "e", "$u_{x,max,e}$ (Eq. 11)"),
        ]
    else:
        curves = [
            ("u_x_max_1_star_nm", 1, "$u^*_{x,max,1}$ (Eq. 13)"),
            ("u_x_max_2_star_nm", 2, "$u^*_{x,max,2}$ (Eq. 13)"),
            ("u_x_max_e_star_nm", "e", "$u^*_{x,max,e}$ (Eq. 12)"),
        ]
    for column, key, label in curves:
        _closed(ax, df, column, SIDE_COLOURS[key], label)
    _finish(fig, ax, f"Six contacts, {model} actuators, R = {radius:g} mm")
    return fig


def _two_panels(df: pd.DataFrame):
    fig, axes = plt.subplots(1, 2, figsize=(9.6, 4.2), sharey=False)
    return fig, dict(zip((1, 6), axes, strict=True))


def plot_viscosity(df: pd.DataFrame):
    """A_c of flexible actuators against the actuator viscosity c_p (one and six contacts)."""
    fig, axes = _two_panels(df)
    f_primary = PROTOCOL.drive_frequency
    styles = {
        ("steady", "slew"): ("o-", "black", f"steady state {f_primary:g} Hz"),
        ("steady", "fixed"): ("^--", "tab:gray", f"steady state {f_primary:g} Hz, 2 µs fly-back"),
        ("first", "slew"): ("s:", "tab:purple", "first fly-back"),
        ("first", "fixed"): ("x:", "tab:brown", "first fly-back, 2 µs fly-back"),
    }
    for n, ax in axes.items():
        rows = df[df["contacts"] == n]
        for (protocol, flyback), (style, colour, label) in styles.items():
            sel = rows[(rows["protocol"] == protocol) & (rows["flyback"] == flyback)].sort_values(
                "actuator_viscosity_kg_per_s"
            )
            ax.plot(sel["actuator_viscosity_kg_per_s"], sel["critical_amplitude_nm"], style, color=colour,
                    ms=4, label=label)
        if len(rows):
            eq = "Eq. 8" if n == 1 else "Eq. 12"
            closed = rows["closed_form_nm"].iloc[0]
            ax.axhline(closed, color="tab:red", lw=1.2, ls="--", label=eq)
            default = rows.loc[
                np.isclose(rows["damping_ratio"], ACTUATOR_DAMPING_RATIO), "actuator_viscosity_kg_per_s"
            ]
            if len(default):
                ax.axvline(default.iloc[0], color="0.6", lw=0.8, ls=":", label="default $c_p$")
            ax.set_ylim(0, 1.12 * max(closed, rows["critical_amplitude_nm"].max()))
        ax.set_xscale("log")
        ax.set_xlabel("actuator viscosity $c_p$ (kg/s)")
        ax.set_ylabel("critical amplitude $A_c$ (nm)")
        ax.set_title(f"{'One contact' if n == 1 else 'Six contacts'}, flexible, 0.4 N, R = 1 mm", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    return fig


def plot_frequency(df: pd.DataFrame):
    """A_c against the drive frequency (one and six contacts, rigid and flexible, both protocols)."""
    fig, axes = _two_panels(df)
    band = PROTOCOL.critical_amplitude_band
    for n, ax in axes.items():
        rows = df[df["contacts"] == n]
        ax.axvspan(
            band[0], band[-1], color="0.92", lw=0, label=f"band of Figs. 5b, 6: {band[0]:g}–{band[-1]:g} Hz"
        )
        for model in ("rigid", "flexible"):
            sel = rows[rows["actuator_model"] == model].sort_values("frequency_Hz")
            if not len(sel):
                continue
            for protocol, style, label in (("steady", "o-", "steady state"),
                                           ("first", "s:", "first fly-back")):
                part = sel[sel["protocol"] == protocol]
                ax.plot(part["frequency_Hz"], part["critical_amplitude_nm"], style, color=COLOURS[model],
                        ms=4, mfc=COLOURS[model] if protocol == "steady" else "none",
                        label=f"$A_c$ {model}, {label}")
            eq = {
                (1, "rigid"): "Eq. 7",
                (1, "flexible"): "Eq. 8",
                (6, "rigid"): "Eq. 11",
                (6, "flexible"): "Eq. 12",
            }[(n, model)]
            ax.axhline(sel["closed_form_nm"].iloc[0], color=COLOURS[model], ls="--", lw=1.0, label=eq)
        ax.set_xscale("log")
        ax.set_xlabel("drive frequency $f$ (Hz)")
        ax.set_ylabel("critical amplitude $A_c$ (nm)")
        ax.set_title(
            f"{'One contact' if n == 1 else 'Six contacts'}, 0.4 N, R = 1 mm, slew-rate fly-back", fontsize=10
        )
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    return fig


def plot_flyback_steps(df: pd.DataFrame):
    """Step across each fly-back of a run from rest, one line per amplitude, with δ."""
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    for amplitude, rows in df.groupby("amplitude_nm", sort=False):
        ax.plot(rows["flyback"], rows["step_nm"], "o-", ms=4, label=f"A = {amplitude:.1f} nm")
    first = df.iloc[0]
    ax.axhline(first["threshold_nm"], color="tab:red", lw=0.8, label="measurable step δ")
    ax.set_xlabel("fly-back number")
    ax.set_ylabel("step across the fly-back (nm)")
    ax.set_title(f"Rigid actuator, one contact, 0.4 N: steady-state A_c = {first['steady_ac_nm']:.1f} nm, "
                 f"u_x,max = {first['u_x_max_nm']:.1f} nm", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig
