"""Plots of Section 5's chapters (Figs. 8–10 and the studies beyond the paper).

Each function takes the tidy DataFrame of a figure of :mod:`passmd.experiments.driving_waveform.figures`
(Figs. 8, 9a), :mod:`passmd.experiments.waveform_velocity.figures` (Figs. 9b, 10) or
:mod:`passmd.experiments.waveform_optimum.figures` (the studies) and returns a matplotlib Figure; axes in nm,
µs/ms, kHz and mm/s.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from passmd.model.defaults import PROTOCOL

#: The saw-tooth frequency of Figs. 8, 9a and the settling scan, as the titles show it.
_STEP_HZ = f"{PROTOCOL.drive_frequency:g} Hz"

_STATUS_COLOURS = {"full slip": "#d62728", "partial slip": "#ffbb78"}
_VARIANT_STYLE = {
    "sawtooth": {"color": "black", "linestyle": "--", "label": "saw-tooth"},
    "optimized": {"color": "tab:green", "linestyle": "-", "label": "optimized (Eq. 15; t_s cut when short)"},
    "optimized_skip": {"color": "tab:blue", "linestyle": ":", "label": "optimized (t_s skipped when short)"},
}


def _shade_status(ax, view) -> None:
    """Shade the time spans of partial and full slip (µs axis)."""
    t = view["time_us"].to_numpy()
    status = view["contact_status"].to_numpy()
    for name, colour in _STATUS_COLOURS.items():
        on = status == name
        edges = np.flatnonzero(np.diff(np.concatenate([[0], on.astype(int), [0]])))
        for start, stop in zip(edges[::2], edges[1::2], strict=True):
            ax.axvspan(t[start], t[min(stop, t.size - 1)], color=colour, alpha=0.25, lw=0,
                       label=name if start == edges[0] else None)


#: Offsets (points) of the numbered labels of Fig. 8's points, in turn: points a fraction of a
#: microsecond apart (4 and 5, the ends of t_s and t_a) get labels on opposite sides.
_LABEL_OFFSETS = ((-9, 11), (9, 11), (-9, -13), (9, -13))


def _points(ax, points, y="runner_position_nm") -> None:
    """Mark the numbered points of Section 5.1 (small dots) with their numbers beside them."""
    for k, (_, row) in enumerate(points.sort_values("time_us").iterrows()):
        ax.plot(row["time_us"], row[y], "o", ms=4, mfc="white", mec="black", zorder=5)
        ax.annotate(row["point"], (row["time_us"], row[y]), xytext=_LABEL_OFFSETS[k % len(_LABEL_OFFSETS)],
                    textcoords="offset points", ha="center", va="center", fontsize=8, zorder=6,
                    bbox={"boxstyle": "circle,pad=0.15", "fc": "white", "ec": "black", "lw": 0.6},
                    arrowprops={"arrowstyle": "-", "lw": 0.5, "shrinkA": 0, "shrinkB": 2})


def _response(df, title: str):
    full, zoom, points = (df[df["view"] == v] for v in ("full", "zoom", "point"))
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8), constrained_layout=True)
    ax = axes[0]
    ax.plot(full["time_ms"], full["piezo_position_nm"], "k--", lw=1, label="x_p (hemispheres)")
    ax.plot(full["time_ms"], full["runner_position_nm"], color="tab:green", lw=1.2, label="x_r (runner)")
    ax.set(xlabel="time (ms)", ylabel="position (nm)", title=title)
    ax.legend(fontsize=8)
    ax = axes[1]
    _shade_status(ax, zoom)
    ax.plot(zoom["time_us"], zoom["piezo_position_nm"], "k--", lw=1)
    ax.plot(zoom["time_us"], zoom["runner_position_nm"], color="tab:green", lw=1.2)
    _points(ax, points)
    ax.set(xlabel="time (µs)", ylabel="position (nm)", title="first slip and micro-vibration")
    ax.legend(fontsize=7, loc="lower right")
    ax = axes[2]
    _shade_status(ax, zoom)
    ax.plot(zoom["time_us"], zoom["slip_share_1"], color="tab:purple", label="side 1 (2 contacts, F_N1)")
    ax.plot(zoom["time_us"], zoom["slip_share_2"], color="tab:orange", label="side 2 (4 contacts, F_N2)")
    _points(ax, points, y="slip_share_2")
    ax.set(xlabel="time (µs)", ylabel="slipping share of the contact", ylim=(-0.05, 1.1),
           title="contact status")
    ax.legend(fontsize=7, loc="center right")
    return fig


def plot_fig8a(df):
    """Fig. 8a: saw-tooth response, zoom on the first slip with points 1–4 and contact status."""
    return _response(df, f"saw-tooth, {_STEP_HZ}")


def plot_fig8b(df):
    """Fig. 8b: the optimized waveform with t_s, t_a, Δ_a marked, and the runner's response."""
    fig = _response(df, f"optimized waveform, {_STEP_HZ}")
    ax = fig.axes[1]
    points = df[df["view"] == "point"].set_index("point")
    row = df.iloc[0]
    t4, t5 = points.loc["4", "time_us"], points.loc["5", "time_us"]
    t1 = t4 - row["settling_time_s"] * 1e6
    y = points.loc["5", "piezo_position_nm"]
    ax.annotate("", (t1, -8), (t4, -8), arrowprops={"arrowstyle": "<->"})
    ax.text(0.5 * (t1 + t4), -6, f"t_s = {row['settling_time_s'] * 1e6:.1f} µs", ha="center", fontsize=8)
    ax.annotate(f"Δ_a = {row['acceleration_amplitude_m'] * 1e9:.1f} nm in t_a = "
                f"{row['acceleration_time_s'] * 1e6:.2f} µs", (t5, y), (t5 + 5, y + 25), fontsize=8,
                arrowprops={"arrowstyle": "->"})
    return fig


def plot_fig8b_window(df):
    """Fig. 8b's fly-back and acceleration resolved in time: runner velocity and contact slip shares."""
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6), constrained_layout=True)
    t = df["time_us"]
    row = df.iloc[0]
    for ax in axes:
        ax.axvspan(row["flyback_start_s"] * 1e6, row["flyback_end_s"] * 1e6, color="grey", alpha=0.2,
                   lw=0, label="fly-back")
        ax.axvspan(row["acceleration_start_s"] * 1e6, row["acceleration_end_s"] * 1e6, color="tab:green",
                   alpha=0.3, lw=0, label="t_a")
        ax.set_xlabel("time (µs)")
    axes[0].plot(t, df["runner_velocity_m_per_s"] * 1e3, color="tab:green", lw=1)
    axes[0].set(ylabel="runner velocity (mm/s)", title="runner")
    axes[1].plot(t, df["slip_share_1"], color="tab:purple", label="side 1 (2 contacts)")
    axes[1].plot(t, df["slip_share_2"], color="tab:orange", label="side 2 (4 contacts)")
    axes[1].set(ylabel="slipping share of the contact", ylim=(-0.05, 1.1), title="contact status")
    axes[1].legend(fontsize=7)
    return fig


def plot_fig9a(df):
    """Fig. 9a: runner position x_r and hemisphere position x_p over three 100 Hz periods, both waveforms.

    Only the runs the data marks ``section5_friction`` (Section 5's μ) are drawn; the others are
    the ledger's alternative readings of μ.
    """
    if "section5_friction" in df:
        df = df[df["section5_friction"].astype(bool)]
    fig, ax = plt.subplots(figsize=(6.5, 4), constrained_layout=True)
    colours = {"sawtooth": "black", "optimized": "tab:green"}
    for waveform, part in df.groupby("waveform", sort=False):
        full, per = part[part["view"] == "full"], part[part["view"] == "period"]
        ax.plot(full["time_ms"], full["runner_position_nm"], color=colours[waveform], lw=1.2,
                label=f"{waveform}: x_r")
        ax.plot(per["time_ms"], per["settled_position_nm"], "o", color=colours[waveform], ms=5)
        last = per.iloc[-1]
        highest = df.loc[df["view"] == "period", "settled_position_nm"].max()
        offset = (-40, 8) if last["settled_position_nm"] >= highest else (-40, -14)  # the lower one below
        ax.annotate(f"{last['settled_position_nm']:.0f} nm", (last["time_ms"], last["settled_position_nm"]),
                    offset, textcoords="offset points", fontsize=8, color=colours[waveform])
    for waveform, part in df[df["view"] == "full"].groupby("waveform", sort=False):  # both waveforms' x_p
        ax.plot(part["time_ms"], part["piezo_position_nm"], ":", color=colours[waveform], lw=0.8, alpha=0.8,
                label=f"{waveform}: x_p (hemispheres)")
    ax.set(xlabel="time (ms)", ylabel="position (nm)", title=f"three periods at {_STEP_HZ}")
    ax.legend(fontsize=8)
    return fig


def _velocity_axes(ax, df, key=None, labels=None, variants=("sawtooth", "optimized", "optimized_skip")):
    groups = [(None, df)] if key is None else list(df.groupby(key, sort=False))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, (value, part) in enumerate(groups):
        for variant in variants:
            sel = part[part["variant"] == variant].sort_values("frequency")
            style = dict(_VARIANT_STYLE[variant])
            label = style.pop("label")
            if key is not None:
                style["color"] = colours[i % len(colours)]
                label = f"{labels(value)}, {label}"
            ax.plot(sel["frequency_kHz"], sel["velocity_mm_per_s"], marker=".", ms=4, label=label, **style)
    ax.axhline(0.0, color="grey", lw=0.5)
    ax.set(xlabel="driving frequency (kHz)", ylabel="steady velocity (mm/s)")


def plot_fig9b(df):
    """Fig. 9b: steady velocity against frequency for the saw-tooth and the optimized waveform."""
    fig, ax = plt.subplots(figsize=(6.5, 4.2), constrained_layout=True)
    _velocity_axes(ax, df)
    if "eq15_highest_frequency_Hz" in df:  # one design per drive: one limit
        limit = float(df["eq15_highest_frequency_Hz"].iloc[0]) / 1e3
        ax.axvline(limit, color="tab:green", lw=0.8, alpha=0.6)
        ax.annotate(f"Eq. 15 fits up to {limit:.4g} kHz", (limit, ax.get_ylim()[1]),
                    (5, -12), textcoords="offset points", fontsize=8, color="tab:green")
    ax.legend(fontsize=8)
    ax.set_title("Section 5 drive: R = 1 mm, 0.4 N, 202 nm, rigid")
    return fig


def _fig10(df, key, labels, title):
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.2), sharey=True, constrained_layout=True)
    for ax, variant in zip(axes, ("optimized", "optimized_skip"), strict=True):
        _velocity_axes(ax, df, key, labels, variants=("sawtooth", variant))
        ax.set_title(f"{title}: {_VARIANT_STYLE[variant]['label']}", fontsize=9)
        ax.legend(fontsize=7)
    return fig


def plot_fig10a(df):
    """Fig. 10a: velocity against frequency for preloads 0.1, 0.4, 1 N."""
    return _fig10(df, "preload", lambda p: f"F_p = {p:g} N", "preload")


def plot_fig10b(df):
    """Fig. 10b: velocity against frequency for R = 1 mm and 0.25 mm."""
    return _fig10(df, "radius_mm", lambda r: f"R = {r:g} mm", "hemisphere radius")


def plot_fig10c(df):
    """Fig. 10c: velocity against frequency for a steel and a molybdenum runner."""
    return _fig10(df, "runner", str, "runner material")


# --------------------------------------------------------------------------------------
# Beyond the paper (passmd.experiments.waveform_optimum.figures)
# --------------------------------------------------------------------------------------


def plot_startup(df):
    """Velocity period by period from rest at a kHz frequency (steady-velocity protocol)."""
    fig, ax = plt.subplots(figsize=(6.5, 3.8), constrained_layout=True)
    for variant, part in df.groupby("variant", sort=False):
        style = dict(_VARIANT_STYLE[variant])
        ax.plot(part["time_ms"], part["velocity_mm_per_s"], **style)
    end = df["time_ms"].max()
    ax.axvspan(0.5 * end, end, color="0.9", zorder=0, label="averaged (second half)")
    ax.set(xlabel="time from rest (ms)", ylabel="velocity over one period (mm/s)",
           title=f"start-up at {1e-3 / (df['time_s'].iloc[1] - df['time_s'].iloc[0]):.0f} kHz")
    ax.legend(fontsize=8)
    return fig


def plot_settling_scan(scans: dict):
    """Step at 100 Hz against the settling time, one curve per (label → scan table)."""
    fig, ax = plt.subplots(figsize=(6.5, 4), constrained_layout=True)
    for label, df in scans.items():
        ax.plot(df["settling_cycles"], df["step_nm"], marker=".", label=label)
    first = next(iter(scans.values()))
    ax.axhline(first["sawtooth_step_nm"].iloc[0], color="black", ls="--", label="saw-tooth")
    ax.axvline(first["eq15_settling_cycles"].iloc[0], color="tab:green", lw=0.8, alpha=0.7)
    ax.annotate("Eq. 15: t_s = 1/(2 f_s)", (first["eq15_settling_cycles"].iloc[0], ax.get_ylim()[1]),
                (4, -12), textcoords="offset points", fontsize=8, color="tab:green")
    ax.set(xlabel="settling time t_s · f_s (vibration cycles)", ylabel="step per period, periods 2–3 (nm)",
           title=f"step at {_STEP_HZ} against the settling time")
    ax.legend(fontsize=8)
    return fig


def plot_settling_scans(df):
    """:func:`plot_settling_scan` of the tidy table of
    :func:`passmd.experiments.waveform_optimum.figures.settling_scans` (one curve per ``series``)."""
    return plot_settling_scan({label: part for label, part in df.groupby("series", sort=False)})


def plot_optimum(df):
    """Saw-tooth, Eq. 15 design and numerical optimum: velocity relative to the saw-tooth."""
    fig, ax = plt.subplots(figsize=(6.5, 4), constrained_layout=True)
    rigid = df[df["actuator_model"] == "rigid"].sort_values("frequency")
    x = np.arange(len(rigid))
    bars = (("velocity_eq15_mm_per_s", "Eq. 15 design", "tab:green"),
            ("velocity_optimum_mm_per_s", "numerical optimum", "tab:red"))
    for offset, (col, label, colour) in zip((-0.2, 0.2), bars, strict=True):
        ax.bar(x + offset, rigid[col] / rigid["velocity_sawtooth_mm_per_s"], width=0.4, color=colour,
               label=label)
    ax.axhline(1.0, color="black", ls="--", lw=1, label="saw-tooth")
    ax.axhline(0.0, color="grey", lw=0.5)
    ax.set_xticks(x, [f"{f:g}" for f in rigid["frequency_kHz"]])
    ax.set(xlabel="driving frequency (kHz)", ylabel="velocity / saw-tooth velocity",
           title="rigid actuators: Eq. 15 against the optimum of (t_s, V_a, Δ_a)")
    ax.legend(fontsize=8)
    return fig


def plot_flexible(df):
    """Velocity relative to each drive's own saw-tooth, rigid and flexible actuators."""
    fig, ax = plt.subplots(figsize=(6.5, 4), constrained_layout=True)
    saw = df[df["variant"] == "sawtooth"].set_index(["actuator_model", "frequency"])["velocity_m_per_s"]
    markers = {"optimized": "o", "optimized_skip": "s"}
    colours = {("rigid", "rigid"): "tab:blue", ("flexible", "flexible"): "tab:orange",
               ("flexible", "rigid"): "tab:purple"}
    for (model, source, variant), part in df[df["variant"] != "sawtooth"].groupby(
            ["actuator_model", "design_from", "variant"], sort=False):
        part = part.sort_values("frequency")
        ratio = part["velocity_m_per_s"].to_numpy() / saw.loc[model].reindex(part["frequency"]).to_numpy()
        ax.plot(part["frequency_kHz"], ratio, marker=markers[variant], color=colours[(model, source)],
                ls="-" if variant == "optimized" else ":",
                label=f"{model} actuators, design from {source}, {variant}")
    ax.axhline(1.0, color="black", ls="--", lw=1)
    ax.set_xscale("log")
    ax.set(xlabel="driving frequency (kHz)", ylabel="velocity / own saw-tooth velocity",
           title="Eq. 15 waveform with rigid and flexible actuators")
    ax.legend(fontsize=7)
    return fig
