"""Plot of a calibration (:func:`passmd.protocols.fit.estimator.fit`): measurements against the fitted model.

One column per measured quantity: above, the measurements (with their standard deviations
where given) and the fitted model's value at each, against the amplitude (the preload for
critical amplitudes), one colour per preload; below, the residuals over their σ.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

__all__ = ["fit_figure"]

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
    fig.suptitle(f"fit: {names}", fontsize="medium")
    return fig
