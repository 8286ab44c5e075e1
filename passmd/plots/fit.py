"""Plot of a calibration (:func:`passmd.protocols.fit.estimator.fit`): measurements against the fitted model.

One column per measured quantity: above, the measurements (with their standard deviations
where given) and the fitted model's value at each, against the amplitude (the preload for
critical amplitudes), one colour per preload; below, the residuals over their σ.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

__all__ = ["fit_figure", "profile_figure"]

_LABELS = {"step_nm": "step", "velocity_mm_per_s": "velocity", "critical_amplitude_nm": "critical amplitude",
           "force_N": "generated force", "position_nm": "position after three periods"}


def fit_figure(result) -> Figure:
    """Data against the fitted model, with normalised residuals, of a ``FitResult``."""
    data = result.data
    columns = list(dict.fromkeys(data.column))
    fig = Figure(figsize=(4.8 * len(columns), 5.6), layout="constrained")
    axes = fig.subplots(2, len(columns), squeeze=False, sharex="col", height_ratios=(3, 1.3))
    residuals = result.residuals
    preload = np.where(np.isfinite(data.preload), data.preload, result.base.preload)
    colours = {p: f"C{k}" for k, p in enumerate(sorted(set(preload.tolist())))}
    for c, column in enumerate(columns):
        rows = np.array([i for i in range(len(data)) if data.column[i] == column])
        scale, unit = data.display(int(rows[0]))
        by_preload = data.kind[rows[0]] == "critical_amplitude"
        top, bottom = axes[0, c], axes[1, c]
        for p, colour in colours.items():
            sel = rows[np.isclose(preload[rows], p)] if not by_preload else rows
            if sel.size == 0:
                continue
            xs = preload[sel] if by_preload else data.amplitude[sel] * 1e9
            order = np.argsort(xs)
            label = None if by_preload else f"F_p = {p:g} N"
            err = data.sd[sel] / scale if data.known_sd else None
            shown = "measured" if label is None else f"measured, {label}"
            top.errorbar(xs, data.value[sel] / scale, yerr=err, fmt="o", ms=4,
                         color="black" if by_preload else colour, label=shown)
            top.plot(xs[order], result.predicted[sel][order] / scale, "-", marker="x",
                     color="tab:red" if by_preload else colour,
                     label="fitted model" if by_preload or p == min(colours) else None)
            bottom.plot(xs, residuals[sel], "o", ms=4, color="black" if by_preload else colour)
            if by_preload:
                break
        top.set_ylabel(f"{_LABELS[column]} [{unit}]")
        top.legend(fontsize="small")
        bottom.axhline(0.0, color="grey", lw=0.8)
        bottom.set_ylabel("residual / σ")
        bottom.set_xlabel("preload [N]" if by_preload else "amplitude [nm]")
    names = ", ".join(f"{n} = {result.estimates[n]['value']:.4g}" for n in result.names)
    gof = getattr(result, "goodness_of_fit", {}) or {}
    test = (f"; χ² = {gof['chi2']:.3g} on {gof['dof']} dof, p = {gof['p_value']:.2g}"
            + (" (model rejected)" if gof.get("rejected") else "") if gof.get("testable") else "")
    fig.suptitle(f"fitted {names}{test}", fontsize="medium")
    return fig


_AXIS = {"friction_coefficient": ("friction coefficient μ", 1.0, ""),
         "actuator.stiffness": ("actuator stiffness k_p", 1.0, "N/m"),
         "actuator.mass": ("actuator mass m_a", 1.0, "kg"),
         "actuator.viscosity": ("actuator viscosity c_p", 1.0, "kg/s"),
         "actuator.damping_ratio": ("damping ratio ζ", 1.0, ""),
         "runner_mass": ("runner mass m_r", 1e3, "g"),
         "amplifier.slew_rate": ("slew rate SR", 1e-6, "V/µs"),
         "flyback_time": ("full-stroke fly-back time", 1e6, "µs"),
         "contact_stiffness_scale": ("contact stiffness scale s_E", 1.0, "")}


def profile_figure(result, name: str, truth: float | None = None, zoom: float = 1.3) -> Figure:
    """The profile of one fitted parameter over its whole bounds (left) and around its 95 % region (right):
    the rise of the least-squares cost above the minimum in units of s², the 95 % level, the region's
    pieces shaded, the basins marked and, when given, the value that made the data."""
    est = result.estimates[name]
    label, scale, unit = _AXIS.get(name, (name, 1.0, est["unit"]))
    x = np.asarray(est["profile"]["value"]) * scale
    rise = (np.asarray(est["profile"]["cost"]) - result.cost) / result.scale ** 2
    fig = Figure(figsize=(10.5, 4.4), layout="constrained")
    axes = fig.subplots(1, 2)
    low, high = (v * scale for v in est["interval"])
    for ax, (left, right) in zip(axes, ((x.min(), x.max()), (low / zoom, high * zoom)), strict=True):
        inside = (x >= left) & (x <= right)
        ax.plot(x[inside], rise[inside], ".-", ms=3, lw=0.8, color="C0", label="profile (cost − minimum)")
        ax.axhline(result.level, color="C3", lw=1.0, ls="--", label=f"95 % level ({result.level:.2f})")
        for k, (a, b) in enumerate(est["intervals"]):
            ax.axvspan(a * scale, b * scale, color="C2", alpha=0.3, label="95 % region" if k == 0 else None)
        basins = [b["value"] * scale for b in est["basins"] if left <= b["value"] * scale <= right]
        if basins:
            ax.plot(basins, np.interp(basins, x, rise), "v", color="C1", ms=6, label="basins")
        if truth is not None and left <= truth * scale <= right:
            ax.axvline(truth * scale, color="black", lw=1.0, label="value that made the data")
        ax.set_xscale("log")
        ax.set_yscale("symlog", linthresh=max(result.level, 1.0))
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
