"""Plots of a calibration (:func:`passmd.protocols.fit.estimator.fit`), drawn from the tables of its
:class:`~passmd.protocols.fit.result.FitResult`: measurements against the fitted model, and a profile.

One column per measured quantity: above, the measurements (with their standard deviations
where given) and the fitted model's value at each, against the amplitude (the preload for
critical amplitudes), one series per measured condition — preload and frequency (frequency alone
for critical amplitudes) — each in its own colour and marker, its model line joining only its own
points; below, the residuals over their σ, in the series' colours.
"""

from __future__ import annotations

import math
import textwrap

import numpy as np
from matplotlib import ticker
from matplotlib.figure import Figure

from passmd.plots.sweep_map import plain_log_ticks

__all__ = ["fit_figure", "profile_figure"]

_LABELS = {"step_nm": "step", "velocity_mm_per_s": "velocity", "critical_amplitude_nm": "critical amplitude",
           "force_N": "generated force", "position_nm": "position after three periods"}


def fit_figure(table) -> Figure:
    """Data against the fitted model, with normalised residuals: a fit's
    :meth:`~passmd.protocols.fit.result.FitResult.residual_table` (its ``attrs``: the estimates, the
    goodness of fit and, optionally, a ``title`` that replaces the estimates' line)."""
    columns = list(dict.fromkeys(table["quantity"]))
    fig = Figure(figsize=(4.8 * len(columns), 5.6), layout="constrained")
    axes = fig.subplots(2, len(columns), squeeze=False, sharex="col", height_ratios=(3, 1.3))
    for c, column in enumerate(columns):
        rows = table[table["quantity"] == column]
        by_preload = rows["kind"].iloc[0] == "critical_amplitude"
        top, bottom = axes[0, c], axes[1, c]
        keys = ["frequency_Hz"] if by_preload else ["preload_N", "frequency_Hz"]
        series = list(rows.groupby(keys, sort=True))
        for k, (condition, sel) in enumerate(series):
            condition = condition if isinstance(condition, tuple) else (condition,)
            xs = (sel["preload_N"] if by_preload else sel["amplitude_nm"]).to_numpy(float)
            order = np.argsort(xs)
            colour, marker = f"C{k % 10}", "osD^v<>ph*"[k % 10]
            err = sel["sd"] if table["sd"].notna().all() else None
            top.errorbar(xs, sel["measured"], yerr=err, fmt=marker, ms=4, color=colour,
                         label=_condition(keys, condition))
            top.plot(xs[order], sel["predicted"].to_numpy(float)[order], "-", marker="x", ms=4, lw=1.0,
                     color=colour, alpha=0.8)
            bottom.plot(xs, sel["normalized_residual"], marker, ms=4, color=colour)
        top.plot([], [], "-", marker="x", color="0.4", label="fitted model (× at each measurement)")
        top.set_ylabel(f"{_LABELS[column]} [{rows['unit'].iloc[0]}]")
        top.legend(fontsize="x-small", ncols=2 if len(series) > 6 else 1)
        bottom.axhline(0.0, color="grey", lw=0.8)
        bottom.set_ylabel("residual / σ")
        bottom.set_xlabel("preload [N]" if by_preload else "amplitude [nm]")
    names = ", ".join(f"{n} = {v:.4g}" for n, v in table.attrs["estimates"].items())
    gof = table.attrs.get("goodness_of_fit") or {}
    test = (f"; χ² = {gof['chi2']:.3g} on {gof['dof']} dof, p = {gof['p_value']:.2g}"
            + (" (model rejected)" if gof.get("rejected") else "") if gof.get("testable") else "")
    title = table.attrs.get("title") or f"fitted {names}{test}"
    fig.suptitle(textwrap.fill(title, 64 * len(columns)), fontsize="medium")  # within the figure's width
    return fig


def _condition(keys, values) -> str:
    """A series' condition as a reader writes it: ``F_p = 0.4 N, f = 100 Hz``."""
    parts = []
    for key, value in zip(keys, values, strict=True):
        if key == "preload_N":
            parts.append(f"F_p = {value:g} N")
        elif math.isfinite(value):
            parts.append(f"f = {value:g} Hz" if value < 1e3 else f"f = {value / 1e3:g} kHz")
    return "measured, " + ", ".join(parts) if parts else "measured"


_AXIS = {"friction_coefficient": ("friction coefficient μ", 1.0, ""),
         "actuator.stiffness": ("actuator stiffness k_p", 1.0, "N/m"),
         "actuator.mass": ("actuator mass m_a", 1.0, "kg"),
         "actuator.viscosity": ("actuator viscosity c_p", 1.0, "kg/s"),
         "actuator.damping_ratio": ("damping ratio ζ", 1.0, ""),
         "runner_mass": ("runner mass m_r", 1e3, "g"),
         "amplifier.slew_rate": ("slew rate SR", 1e-6, "V/µs"),
         "flyback_time": ("full-stroke fly-back time", 1e6, "µs"),
         "contact_stiffness_scale": ("contact stiffness scale s_E", 1.0, "")}


def profile_figure(table, zoom: float = 1.3) -> Figure:
    """The profile of one fitted parameter over its whole bounds (left) and around its 95 % region (right):
    a fit's :meth:`~passmd.protocols.fit.result.FitResult.profile_table`, the rise of the cost above the
    minimum in units of s², the 95 % level, the region's pieces shaded, the basins marked and, when its
    ``attrs`` give a ``truth``, the value that made the data."""
    name, level, truth = table.attrs["parameter"], table.attrs["level"], table.attrs.get("truth")
    label, scale, unit = _AXIS.get(name, (name, 1.0, table.attrs["unit"]))
    x = table["value"].to_numpy(float) * scale
    rise = table["rise"].to_numpy(float)
    fig = Figure(figsize=(10.5, 4.4), layout="constrained")
    axes = fig.subplots(1, 2)
    pieces = table.attrs["intervals"]
    low, high = min(a for a, _ in pieces) * scale, max(b for _, b in pieces) * scale
    for ax, (left, right) in zip(axes, ((x.min(), x.max()), (low / zoom, high * zoom)), strict=True):
        inside = (x >= left) & (x <= right)
        ax.plot(x[inside], rise[inside], ".-", ms=3, lw=0.8, color="C0", label="profile (cost − minimum)")
        ax.axhline(level, color="C3", lw=1.0, ls="--", label=f"95 % level ({level:.2f})")
        for k, (a, b) in enumerate(pieces):
            ax.axvspan(a * scale, b * scale, color="C2", alpha=0.3, label="95 % region" if k == 0 else None)
        basins = [v * scale for v in table.attrs["basins"] if left <= v * scale <= right]
        if basins:
            ax.plot(basins, np.interp(basins, x, rise), "v", color="C1", ms=6, label="basins")
        if truth is not None and left <= truth * scale <= right:
            ax.axvline(truth * scale, color="black", lw=1.0, label="value that made the data")
        ax.set_xscale("log")
        ax.set_yscale("symlog", linthresh=max(level, 1.0))
        plain_log_ticks(ax.xaxis)
        ax.yaxis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
        ax.set_ylim(bottom=0.0)
        ax.set_xlim(left, right)
        ax.set_xlabel(f"{label} [{unit}]" if unit else label)
        ax.set_ylabel("cost rise over the minimum / s²")
    axes[0].set_title("whole bounds", fontsize="medium")
    axes[1].set_title("around the 95 % region", fontsize="medium")
    handles, labels = axes[1].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=len(labels), fontsize="small")
    fig.suptitle(f"profile of {name}: the cost with {label} fixed, the other free parameters re-fitted",
                 fontsize="medium")
    return fig
