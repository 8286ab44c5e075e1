"""Plots of the force-generation figures (Fig. 7 and the chapter's panels beyond it).

Each function takes the tidy DataFrame of :mod:`passmd.experiments.force_generation.figures` and
returns a matplotlib Figure: amplitudes in nm, forces in mN, preloads in N, time in µs/ms.
Runs that did not stall (``converged`` False) are drawn as red crosses, never on a curve.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

#: Line style of each (actuator model, μ): this paper's model solid, the earlier one dashed.
STYLES = {
    ("rigid", 0.3): {"ls": "--", "marker": "s"},
    ("flexible", 0.2): {"ls": "-", "marker": "o"},
    ("rigid", 0.2): {"ls": ":", "marker": "^"},
    ("flexible", 0.3): {"ls": "-.", "marker": "v"},
}
#: Colour of each combination in the stall-cycle figure.
CYCLE_COLOURS = {
    ("rigid", 0.3): "tab:red",
    ("rigid", 0.2): "tab:orange",
    ("flexible", 0.3): "tab:purple",
    ("flexible", 0.2): "black",
}


def _key(rows: pd.DataFrame) -> tuple:
    return (str(rows["actuator_model"].iloc[0]), round(float(rows["friction_coefficient"].iloc[0]), 6))


def _label(model: tuple) -> str:
    return f"{model[0]}, μ = {model[1]:g}"


def _select(df: pd.DataFrame, model: tuple) -> pd.DataFrame:
    return df[(df["actuator_model"] == model[0]) & np.isclose(df["friction_coefficient"], model[1])]


def _groups(df: pd.DataFrame, keys: list[str]):
    yield from df.groupby(keys, sort=True)


def _curve(ax, rows: pd.DataFrame, colour, label: str | None, onset: bool = True) -> None:
    """One F_gen(A) curve: stalled points, non-stalled crosses, the onset on the axis.

    Where the onset was found, the line starts there and joins only the amplitudes above it; the
    amplitudes below it (no step: the runner only follows the piezo) are small dots, never joined
    across the onset, which the line would otherwise cut as a straight chord.
    """
    rows = rows.sort_values("amplitude_nm")
    style = STYLES.get(_key(rows), {"ls": "-", "marker": "o"})
    good = rows[rows["converged"]]
    found = "onset_nm" in rows and np.isfinite(rows["onset_nm"].iloc[0])
    if found:
        a_c = float(rows["onset_nm"].iloc[0])
        below, above = good[good["amplitude_nm"] <= a_c], good[good["amplitude_nm"] > a_c]
        ax.plot(np.r_[a_c, above["amplitude_nm"]], np.r_[0.0, above["generated_force_mN"]], color=colour,
                ls=style["ls"], label=label)
        ax.plot(above["amplitude_nm"], above["generated_force_mN"], color=colour, ms=4, ls="none",
                marker=style["marker"])
        ax.plot(below["amplitude_nm"], below["generated_force_mN"], color=colour, ms=3, ls="none", marker=".")
    else:
        ax.plot(good["amplitude_nm"], good["generated_force_mN"], color=colour, ms=4, label=label, **style)
    bad = rows[~rows["converged"]]
    if len(bad):
        ax.plot(bad["amplitude_nm"], bad["generated_force_mN"], "x", color="red", ms=8, mew=2,
                label="did not stall")
    if onset and found:
        ax.plot([rows["onset_nm"].iloc[0]], [0.0], marker=style["marker"], color=colour, mfc="white",
                ms=6, ls="none", clip_on=False, zorder=5)


def plot_panel(df: pd.DataFrame):
    """Fig. 7a/7b layout: F_gen [mN] against A [nm] for two preloads, both models.

    Open markers on the amplitude axis are the onsets (critical amplitude with the load cell).
    """
    fig, ax = plt.subplots(figsize=(6.4, 4.6), layout="constrained")
    colours = plt.get_cmap("tab10")
    for i, (preload, rows) in enumerate(_groups(df, ["preload_N"])):
        preload = preload[0] if isinstance(preload, tuple) else preload
        for _, curve in _groups(rows, ["actuator_model", "friction_coefficient"]):
            _curve(ax, curve, colours(i), f"{_label(_key(curve))}, F_p = {preload:g} N")
    radius = float(df["radius_mm"].iloc[0])
    ax.set_xlabel("actuation amplitude A [nm]")
    ax.set_ylabel("generated force F_gen [mN]")
    ax.set_title(f"R = {radius:g} mm, f = {float(df['frequency_Hz'].iloc[0]):g} Hz")
    ax.set_xlim(0, float(df["amplitude_nm"].max()) * 1.02)
    ax.set_ylim(bottom=0)
    handles, labels = ax.get_legend_handles_labels()
    unique = dict(zip(labels, handles, strict=True))
    ax.legend(unique.values(), unique.keys(), fontsize=8)
    ax.grid(alpha=0.3)
    return fig


def plot_grid(df: pd.DataFrame):
    """Every preload of both radii: F_gen(A) families per model, F_gen(A_max) and onsets vs preload."""
    radii = sorted(df["radius_mm"].unique(), reverse=True)
    models = [m for m in STYLES if len(_select(df, m))]
    fig, axes = plt.subplots(len(radii), len(models) + 2, figsize=(4.0 * (len(models) + 2), 3.6 * len(radii)),
                             layout="constrained", squeeze=False)
    cmap = plt.get_cmap("viridis")
    for r_i, radius in enumerate(radii):
        at_r = df[np.isclose(df["radius_mm"], radius)]
        preloads = np.sort(at_r["preload_N"].unique())
        norm = plt.Normalize(preloads.min(), preloads.max() if preloads.size > 1 else preloads.min() + 1)
        for m_i, model in enumerate(models):
            ax = axes[r_i, m_i]
            rows = _select(at_r, model)
            for preload, curve in rows.groupby("preload_N"):
                _curve(ax, curve, cmap(norm(preload)), None)
            ax.set_title(f"R = {radius:g} mm, {_label(model)}", fontsize=9)
            ax.set_xlabel("A [nm]")
            ax.set_ylabel("F_gen [mN]")
            ax.set_ylim(bottom=0)
            ax.grid(alpha=0.3)
        fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=axes[r_i, len(models) - 1],
                     label="preload F_p [N]")
        full = at_r[np.isclose(at_r["amplitude_fraction"], at_r["amplitude_fraction"].max())]
        ax_f, ax_o = axes[r_i, len(models)], axes[r_i, len(models) + 1]
        for model in models:
            rows = _select(full, model)
            rows = rows.sort_values("preload_N")
            style = STYLES[model]
            good = rows[rows["converged"]]
            ax_f.plot(good["preload_N"], good["generated_force_mN"], color="k", ms=4, label=_label(model),
                      **style)
            bad = rows[~rows["converged"]]
            if len(bad):
                ax_f.plot(bad["preload_N"], bad["generated_force_mN"], "x", color="red", ms=8, mew=2)
            onsets = rows.drop_duplicates("preload_N")
            ax_o.plot(onsets["preload_N"], onsets["onset_nm"], color="k", ms=4,
                      label=f"{_label(model)}, simulated", **style)
            ax_o.plot(onsets["preload_N"], onsets["analytic_onset_nm"], color="tab:red", lw=1, ls=style["ls"],
                      label=f"{_label(model)}, Eq. {'12' if model[0] == 'flexible' else '11'}")
        amplitude = float(full["amplitude_nm"].max())
        ax_f.set_title(f"R = {radius:g} mm, F_gen at A = {amplitude:.3g} nm", fontsize=9)
        ax_f.set_xlabel("preload F_p [N]")
        ax_f.set_ylabel("F_gen [mN]")
        ax_f.legend(fontsize=7)
        ax_f.grid(alpha=0.3)
        ax_o.set_title(f"R = {radius:g} mm, onset of force generation", fontsize=9)
        ax_o.set_xlabel("preload F_p [N]")
        ax_o.set_ylabel("onset A_c [nm]")
        ax_o.legend(fontsize=7)
        ax_o.grid(alpha=0.3)
    return fig


def plot_frequency(df: pd.DataFrame):
    """F_gen at full amplitude against the drive frequency (log axis), per radius, both models."""
    radii = sorted(df["radius_mm"].unique(), reverse=True)
    fig, axes = plt.subplots(1, len(radii), figsize=(5.2 * len(radii), 3.8), layout="constrained",
                             squeeze=False)
    for ax, radius in zip(axes[0], radii, strict=True):
        at_r = df[np.isclose(df["radius_mm"], radius)]
        for _, rows in _groups(at_r, ["actuator_model", "friction_coefficient"]):
            rows = rows.sort_values("frequency_Hz")
            model = _key(rows)
            good = rows[rows["converged"]]
            ax.plot(good["frequency_Hz"], good["generated_force_mN"], color="k", ms=4, label=_label(model),
                    **STYLES.get(model, {}))
            bad = rows[~rows["converged"]]
            if len(bad):
                ax.plot(bad["frequency_Hz"], bad["generated_force_mN"], "x", color="red", ms=8, mew=2,
                        label="did not stall")
        ax.set_xscale("log")
        ax.set_xlabel("drive frequency f [Hz]")
        ax.set_ylabel("F_gen [mN]")
        ax.set_title(f"R = {radius:g} mm, F_p = {float(at_r['preload_N'].iloc[0]):g} N, "
                     f"A = {float(at_r['amplitude_nm'].iloc[0]):.3g} nm", fontsize=9)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    return fig


def plot_cycle(df: pd.DataFrame, zoom_us: float = 400.0):
    """One period at stall: runner, forces, actuator deflection and slip share.

    Left column: the fly-back and the first ``zoom_us`` µs after it; right: the whole period.
    Side 1 (two contacts at F_N1) solid, side 2 (four at F_N2) dashed.
    """
    fig, axes = plt.subplots(4, 2, figsize=(11, 10), layout="constrained", sharex="col")
    for _, rows in _groups(df, ["actuator_model", "friction_coefficient"]):
        model = _key(rows)
        colour = CYCLE_COLOURS.get(model, "grey")
        label = f"{_label(model)}: F_gen = {float(rows['generated_force_mN'].iloc[0]):.0f} mN"
        for col, (sel, scale) in enumerate(((rows["time_us"] <= zoom_us, 1.0), (slice(None), 1e-3))):
            part = rows[sel]
            t = part["time_us"] * scale
            axes[0, col].plot(t, part["runner_nm"], color=colour, lw=0.8, label=label)
            axes[1, col].plot(t, part["friction_mN"], color=colour, lw=0.8)
            axes[1, col].plot(t, part["load_cell_mN"], color=colour, lw=1.5, ls=":")
            for side, ls in (("side1", "-"), ("side2", "--")):
                axes[2, col].plot(t, part[f"deflection_{side}_nm"], color=colour, lw=0.8, ls=ls)
                axes[3, col].plot(t, part[f"slip_share_{side}"], color=colour, lw=0.8, ls=ls)
    axes[0, 0].set_ylabel("runner x_r − x̄_r [nm]")
    axes[1, 0].set_ylabel("friction on runner [mN]\n(dotted: load cell k·x_r)")
    axes[2, 0].set_ylabel("actuator deflection\nx_p − x_a [nm]")
    axes[3, 0].set_ylabel("slip share")
    axes[3, 0].set_xlabel("time since the fly-back [µs]")
    axes[3, 1].set_xlabel("time since the fly-back [ms]")
    axes[0, 0].legend(fontsize=7)
    for ax in axes.ravel():
        ax.grid(alpha=0.3)
    spacing = float(df["sample_spacing_us"].iloc[0])
    fig.suptitle(f"One period at stall (samples every {spacing:.2g} µs)", fontsize=10)
    return fig


def plot_fig7_difference(df: pd.DataFrame):
    """F_gen(rigid, μ = 0.3) − F_gen(flexible, μ = 0.2) against A, one axes per panel.

    ``df`` is :func:`passmd.experiments.force_generation.figures.fig7_difference`: one curve per preload,
    the amplitudes between the two models' onsets shaded.
    """
    names = list(dict.fromkeys(df["panel"]))
    fig, axes = plt.subplots(1, len(names), figsize=(5.2 * len(names), 3.8), layout="constrained",
                             squeeze=False)
    colours = plt.get_cmap("tab10")
    for ax, name in zip(axes[0], names, strict=True):
        panel = df[df["panel"] == name]
        for i, (preload, diff) in enumerate(panel.groupby("preload_N", sort=True)):
            ax.plot(diff["amplitude_nm"], diff["difference_mN"], "o-", color=colours(i), ms=4,
                    label=f"F_p = {preload:g} N")
            ax.axvspan(float(diff["onset_low_nm"].iloc[0]), float(diff["onset_high_nm"].iloc[0]),
                       color=colours(i), alpha=0.12, lw=0)
        ax.axhline(0.0, color="k", lw=0.8)
        ax.set_xlabel("actuation amplitude A [nm]")
        ax.set_ylabel("F_gen(rigid, μ = 0.3) − F_gen(flexible, μ = 0.2) [mN]")
        ax.set_title(f"{name}: R = {float(panel['radius_mm'].iloc[0]):g} mm (shaded: between the onsets)",
                     fontsize=9)
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    return fig


def stall_trace_figure(result, title: str, generated_force: float | None, coulomb_bound: float):
    """``passmd force --plot``: the stall run as forces. Above, the force the runner presses on the
    load cell, k·x_r (N), with the generated force (the period mean at stall) and the Coulomb bound
    ±μΣF_N; below, the piezo and runner positions (nm) that make it."""
    from matplotlib.figure import Figure

    k = result.drive.effective_load_cell_stiffness
    t_ms = result.time * 1e3
    fig = Figure(figsize=(7, 5.6), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=(3, 2))
    top.plot(t_ms, k * result.runner_position, lw=0.8, color="C1", label="load-cell force k·x_r")
    if generated_force is not None:
        top.axhline(generated_force, color="k", lw=1.0, ls="--",
                    label=f"generated force {generated_force * 1e3:.4g} mN (period mean at stall)")
    for sign in (1, -1):
        top.axhline(sign * coulomb_bound, color="C3", lw=0.8, ls=":",
                    label=f"Coulomb bound ±μΣF_N = ±{coulomb_bound * 1e3:.4g} mN" if sign > 0 else None)
    top.set_ylabel("force [N]")
    top.grid(alpha=0.3)
    top.legend(fontsize=8)
    top.set_title(title, fontsize=9)
    bottom.plot(t_ms, result.piezo_position * 1e9, lw=0.8, label="piezo x_p (the waveform)")
    bottom.plot(t_ms, result.runner_position * 1e9, lw=0.8, label="runner x_r")
    bottom.set_xlabel("time [ms]")
    bottom.set_ylabel("position [nm]")
    bottom.grid(alpha=0.3)
    bottom.legend(fontsize=8)
    return fig
