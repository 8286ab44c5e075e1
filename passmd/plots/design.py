"""Figures of the chapter "Design your own drive" (data from
:mod:`passmd.experiments.design_your_drive.figures`).

The maps are drawn by :func:`passmd.plots.sweep_map.map_figure`, as ``passmd sweep`` draws them
(:func:`design_map`); here also are the figures a map does not cover.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from passmd.model.defaults import PROTOCOL
from passmd.plots.sweep_map import MapAxis, cell_marks, map_figure, plain_log_ticks
from passmd.protocols.maps import MAP_QUANTITIES

__all__ = ["critical_amplitude_figure", "design_map", "gain_map_figure", "heldback_figure", "ringing_figure",
           "stall_force_figure", "step_map_figure", "velocity_map_figure"]

#: The maps' axes: frequency (log) and amplitude, as ``passmd sweep --vary frequency=...:log --vary
#: amplitude=...`` draws them.
MAP_AXES = (MapAxis("frequency_Hz", "frequency", "kHz", log=True), MapAxis("amplitude_m", "amplitude", "nm"))


def design_map(table, quantity: str, title: str) -> Figure:
    """A frequency × amplitude map of ``quantity`` (a ``passmd sweep`` quantity) with the cells that
    are no value, not steady or below the measurable step marked
    (:func:`passmd.plots.sweep_map.cell_marks`)."""
    spec = MAP_QUANTITIES[quantity]
    value = MapAxis(spec.column, spec.label, spec.unit, scale=spec.scale)
    delta = PROTOCOL.step_threshold
    resolution = [delta * (1.0 if spec.unit == "nm" else float(f)) for f in table["frequency_Hz"]]
    what = "difference" if quantity == "gain" else "motion"
    marks = cell_marks(table, value, resolution,
                       missing_label="no value: Eq. 15 gives no waveform or does not fit the period",
                       resolution_label=f"|value| below the measurable step ({delta * 1e9:g} nm"
                                        f"{'' if spec.unit == 'nm' else ' × f'}): no measurable {what}")
    return map_figure(table, list(MAP_AXES), value, title, marks=marks)


def step_map_figure(table) -> Figure:
    """The saw-tooth's steady step over the map grid (a ``velocity`` map, :func:`design_map`)."""
    return design_map(table, "step", "example drive: step of the saw-tooth over frequency × amplitude")


def velocity_map_figure(table) -> Figure:
    """The saw-tooth's steady velocity over the map grid (a ``velocity`` map, :func:`design_map`)."""
    return design_map(table, "velocity",
                      "example drive: velocity of the saw-tooth over frequency × amplitude")


def gain_map_figure(table) -> Figure:
    """Eq. 15's steady velocity minus the saw-tooth's over the grid (a ``gain`` map, :func:`design_map`)."""
    return design_map(table, "gain", "example drive: Eq. 15 waveform minus saw-tooth")


def ringing_figure(table) -> Figure:
    """The runner's swing after a fly-back against the time since (log axes), the measurable step,
    and where the next fly-back comes at each frequency of ``attrs["next_flyback_Hz"]``
    (:func:`passmd.experiments.design_your_drive.figures.ringing_frame`)."""
    fig = Figure(figsize=(6.4, 4.0), layout="constrained")
    ax = fig.add_subplot()
    t_ms = table["swing_times_s"].to_numpy(float) * 1e3
    ax.loglog(t_ms, table["swing_amplitudes_m"].to_numpy(float) * 1e9, "-", lw=1.2,
              label=f"runner swing after the fly-back ({table.attrs['ringing_frequency_Hz'] / 1e3:.3g} kHz)")
    measurable = table.attrs["measurable_m"]
    ax.axhline(measurable * 1e9, color="grey", ls="--", lw=0.8,
               label=f"measurable step ({measurable * 1e9:g} nm)")
    for k, f in enumerate(table.attrs["next_flyback_Hz"]):
        delay = (1.0 / f - table.attrs["flyback_time_s"]) * 1e3
        ax.axvline(delay, color=f"C{k + 1}", ls=":", lw=1.0, label=f"next fly-back at {f:g} Hz")
    ax.set_xlabel("time after the fly-back [ms]")
    ax.set_ylabel("swing of the runner [nm]")
    plain_log_ticks(ax.xaxis)
    plain_log_ticks(ax.yaxis)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    return fig

_READINGS = (("closed_form_nm", "closed form (Eqs. 7–8, 11–12)", "--"),
             ("first_nm", "simulated, first fly-back", "s-"),
             ("steady_nm", "simulated, steady", "o-"))


def critical_amplitude_figure(table) -> Figure:
    """The three readings of A_c against preload, with the full stroke (``attrs["full_stroke_nm"]``) as
    a ceiling; steady points that the runner's ringing affects (a measurable swing left at the next
    fly-back) ringed."""
    full_stroke_nm = table.attrs["full_stroke_nm"]
    fig = Figure(figsize=(6.4, 4.4), layout="constrained")
    ax = fig.add_subplot()
    for column, label, style in _READINGS:
        ax.plot(table["preload_N"], table[column], style, ms=4, label=label)
    if "ringing_affects" in table and table["ringing_affects"].any():
        hit = table[table["ringing_affects"]]
        ax.plot(hit["preload_N"], hit["steady_nm"], "o", ms=10, mfc="none", color="C3",
                label="steady, runner still ringing at the next fly-back")
    ax.axhline(full_stroke_nm, color="grey", lw=0.8, ls=":")
    ax.annotate("full stroke", (float(table["preload_N"].min()), full_stroke_nm), textcoords="offset points",
                xytext=(2, -11), fontsize=8, color="grey")
    ax.set_xlabel("preload F_p [N]")
    ax.set_ylabel("critical amplitude A_c [nm]")
    ax.set_ylim(0, 1.08 * full_stroke_nm)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    return fig


def stall_force_figure(table) -> Figure:
    """Stall force against amplitude, one curve per preload, with each preload's Coulomb bound
    μ·ΣF_N (dotted); points that did not stall are red crosses."""
    fig = Figure(figsize=(6.4, 4.4), layout="constrained")
    ax = fig.add_subplot()
    for k, (preload, rows) in enumerate(table.groupby("preload_N", sort=True)):
        colour = f"C{k}"
        done = rows[rows["converged"]]
        ax.plot(done["amplitude_nm"], done["force_mN"], "o-", ms=4, color=colour,
                label=f"F_p = {preload:g} N")
        ax.axhline(float(rows["bound_mN"].iloc[0]), color=colour, lw=0.8, ls=":")
        open_ = rows[~rows["converged"]]
        if len(open_):
            ax.plot(open_["amplitude_nm"], open_["force_mN"], "x", color="red", ms=7)
    ax.set_xlabel("amplitude A [nm]")
    ax.set_ylabel("stall force F_gen [mN]")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, title="dotted: μ·ΣF_N", title_fontsize=8)
    return fig


def heldback_figure(table) -> Figure:
    """Held-back measurements (with ±1 σ) against each drive's prediction, one slot per point.

    ``attrs["labels"]``: prediction column stem (``<stem>_nm``) -> legend text.
    """
    labels = table.attrs["labels"]
    fig = Figure(figsize=(7.2, 4.2), layout="constrained")
    ax = fig.add_subplot()
    x = np.arange(len(table))
    ax.errorbar(x, table["measured_nm"], yerr=table["sd_nm"], fmt="o", color="black", ms=5,
                label="measured (held back)")
    for k, (stem, label) in enumerate(labels.items()):
        ax.plot(x + 0.12 * (k + 1), table[f"{stem}_nm"], ["x", "D"][k % 2], ms=6, color=f"C{k + 1}",
                label=label)
    ax.set_xticks(x, [f"{f / 1e3:g} kHz\n{p:g} N\n{a:.0f} nm" for f, p, a in
                      zip(table["frequency_Hz"], table["preload_N"], table["amplitude_nm"], strict=True)],
                  fontsize=7)
    ax.set_ylabel("step [nm]")
    ax.set_xlabel("held-back point: frequency, preload, amplitude")
    ax.grid(alpha=0.3, axis="y")
    ax.legend(fontsize=8)
    return fig
