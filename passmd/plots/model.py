"""Plots of the model chapter (Sections 2–3): the saw-tooth, the two schematics of Fig. 3 and
one MDR contact (Fig. 4). Each takes the DataFrame of a row of :mod:`passmd.experiments.figure_table`."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib import patches

from passmd.runtime.units import from_si

__all__ = ["plot_cross_section", "plot_free_body", "plot_mdr_loop", "plot_sawtooth"]


def plot_sawtooth(df: pd.DataFrame):
    """x_p(t) over the periods of the data, annotated, with an inset on the first fly-back."""
    t = df["time_s"].to_numpy()
    x = df["x_p_m"].to_numpy()
    amplitude = float(df["amplitude_m"].iloc[0])
    ramp_end = float(df["ramp_end_s"].iloc[0])
    fig, ax = plt.subplots(figsize=(8, 3.2))
    ax.plot(df["time_ms"], df["x_p_nm"], color="C0")
    ax.set_xlabel("time $t$ (ms)")
    ax.set_ylabel("piezo position $x_p$ (nm)")
    ax.set_ylim(-20, from_si(amplitude, "nm") * 1.25)
    ax.annotate("stick phase: slow ramp",
                xy=(from_si(0.45 * ramp_end, "ms"), from_si(0.45 * amplitude, "nm")), xytext=(0.5, 215),
                arrowprops={"arrowstyle": "->"}, fontsize=9)
    ax.annotate("slip phase: fly-back", xy=(from_si(ramp_end, "ms"), from_si(0.6 * amplitude, "nm")),
                xytext=(12.5, 215), arrowprops={"arrowstyle": "->"}, fontsize=9)
    # Zoom on the first fly-back, which lasts microseconds in a period of milliseconds.
    inset = ax.inset_axes([0.72, 0.2, 0.25, 0.5])
    zoom = (t > ramp_end - 3e-6) & (t < ramp_end + 5e-6)
    t_zoom = np.concatenate([[ramp_end - 3e-6], t[zoom], [ramp_end + 5e-6]])
    inset.plot(from_si(t_zoom - ramp_end, "us"), from_si(np.interp(t_zoom, t, x), "nm"))
    inset.set_xlabel("$t - t_{ramp}$ (µs)", fontsize=8)
    inset.tick_params(labelsize=7)
    inset.set_title("fly-back", fontsize=8)
    return fig


def _spring(ax, x0, x1, y, coils=6, height=0.18):
    """Zig-zag spring from (x0, y) to (x1, y)."""
    xs = np.linspace(x0, x1, 2 * coils + 3)
    ys = np.full_like(xs, y)
    ys[2:-2:2] += height
    ys[3:-2:2] -= height
    ax.plot(xs, ys, color="k", lw=1.2)


def _damper(ax, x0, x1, y, width=0.22):
    """Dash-pot from (x0, y) to (x1, y)."""
    xm = 0.5 * (x0 + x1)
    ax.plot([x0, xm - 0.05], [y, y], color="k", lw=1.2)
    ax.plot([xm - 0.05, xm - 0.05], [y - width, y + width], color="k", lw=1.2)
    ax.plot([xm - 0.25, xm + 0.25, xm + 0.25, xm - 0.25],
            [y - 1.4 * width, y - 1.4 * width, y + 1.4 * width, y + 1.4 * width], color="k", lw=1.2)
    ax.plot([xm + 0.25, x1], [y, y], color="k", lw=1.2)


def _ground(ax, x, y0, y1):
    """Hatched wall at x between y0 and y1."""
    ax.add_patch(patches.Rectangle((x - 0.25, y0), 0.25, y1 - y0, hatch="////", fill=False, lw=0))
    ax.plot([x, x], [y0, y1], color="k", lw=1.5)


def _coordinate(ax, x, y, label):
    """Arrow marking a coordinate's positive direction."""
    ax.annotate("", xy=(x + 0.8, y), xytext=(x, y), arrowprops={"arrowstyle": "->", "lw": 1})
    ax.plot([x, x], [y - 0.1, y + 0.1], color="k", lw=1)
    ax.text(x + 0.85, y, label, va="center", fontsize=10)


def plot_free_body(df: pd.DataFrame):
    """Free-body diagram of Eqs. 2–3 (Fig. 3a, schematic): runner, load cell, one actuator per side."""
    fig, ax = plt.subplots(figsize=(8.5, 4.6))
    ax.set_aspect("equal")
    ax.axis("off")
    # Runner and load cell (Eq. 2).
    ax.add_patch(patches.Rectangle((4.0, -0.6), 4.0, 1.2, fc="#d9e4f2", ec="k"))
    ax.text(4.9, 0.0, "runner\n$m_r$", ha="center", va="center", fontsize=10)
    _ground(ax, 1.0, -0.6, 0.6)
    _spring(ax, 1.0, 4.0, 0.0)
    ax.text(2.5, -0.45, "load cell $k$", ha="center", va="top", fontsize=9)
    _coordinate(ax, 8.15, 0.0, "$x_r$")
    # One actuator per side (Eq. 3): damper to ground, mass, spring to the piezo position x_p;
    # a hemisphere on the mass touches the runner.
    for y, label, count in [(1.4, "1", 2), (-1.4, "2", 4)]:
        sgn = 1 if y > 0 else -1
        _ground(ax, 2.2, y - 0.55, y + 0.55)
        _damper(ax, 2.2, 5.2, y)
        ax.text(3.7, y + sgn * 0.4, "$c_p$", ha="center", va="center", fontsize=10)
        ax.add_patch(patches.Rectangle((5.2, y - 0.45), 1.6, 0.9, fc="#f2e0c9", ec="k"))
        ax.text(6.0, y, f"$m_a$ (×{count})", ha="center", va="center", fontsize=9)
        _spring(ax, 6.8, 9.2, y)
        ax.text(8.0, y + sgn * 0.4, "$k_p$", ha="center", va="center", fontsize=10)
        ax.add_patch(patches.Rectangle((9.2, y - 0.35), 0.5, 0.7, fc="#cccccc", ec="k"))
        ax.text(9.8, y, "$x_p(t)$", va="center", fontsize=10)
        yc = y - sgn * 0.45  # hemisphere centre on the mass's runner-side face
        ax.add_patch(
            patches.Wedge(
                (6.0, yc), 0.35, 180 if sgn > 0 else 0, 360 if sgn > 0 else 180, fc="#c0392b", ec="k"
            )
        )
        # friction force on the runner (all contacts of this side)
        yf = sgn * 0.35
        ax.annotate(
            "", xy=(7.2, yf), xytext=(6.2, yf), arrowprops={"arrowstyle": "->", "color": "C3", "lw": 1.5}
        )
        ax.text(7.25, yf, f"${count}F_{{f{label}}}$", color="C3", va="center", fontsize=10)
        # normal force pressing the hemisphere onto the runner
        top = y + sgn * 0.45
        ax.annotate("", xy=(6.6, top), xytext=(6.6, top + sgn * 0.7),
                    arrowprops={"arrowstyle": "->", "color": "C2", "lw": 1.2})
        ax.text(6.7, top + sgn * 0.45, f"$F_{{N{label}}}$", color="C2", va="center", fontsize=10)
        _coordinate(ax, 5.2, top + sgn * 0.3, f"$x_{{a{label}}}$")
    ax.set_xlim(0.4, 10.8)
    ax.set_ylim(-2.8, 2.8)
    return fig


def plot_cross_section(df: pd.DataFrame):
    """The runner's cross-section (Fig. 3b, schematic): four faces at 90°, Eq. 1's normal forces.

    A schematic: the arrows mark the directions of F_N1 and F_N2; their values are in ``df``.
    """
    fig, ax = plt.subplots(figsize=(6.5, 4.6))
    ax.set_aspect("equal")
    ax.axis("off")
    half = 1.0  # half diagonal of the runner's square cross-section
    ax.add_patch(patches.Polygon([(0, half), (half, 0), (0, -half), (-half, 0)], fc="#d9e4f2", ec="k"))
    ax.text(0, 0, "runner", ha="center", va="center", fontsize=10)
    faces = {  # face centre, outward normal, side, contacts on this face
        "upper right": ((0.5, 0.5), (1, 1), 1, 1),
        "lower right": ((0.5, -0.5), (1, -1), 1, 1),
        "upper left": ((-0.5, 0.5), (-1, 1), 2, 2),
        "lower left": ((-0.5, -0.5), (-1, -1), 2, 2),
    }
    for (cx, cy), (nx, ny), side, n in faces.values():
        nx, ny = nx / np.sqrt(2), ny / np.sqrt(2)
        r = 0.16
        ax.add_patch(patches.Circle((cx + r * nx, cy + r * ny), r, fc="#c0392b", ec="k"))
        # actuator block behind the hemisphere, oriented along the normal
        bx, by = cx + 2 * r * nx, cy + 2 * r * ny
        ax.add_patch(
            patches.Rectangle((bx - 0.25, by - 0.12), 0.5, 0.24, angle=np.degrees(np.arctan2(ny, nx)) + 90,
                              rotation_point=(bx, by), fc="#f2e0c9", ec="k")
        )
        tip = (cx + 0.02 * nx, cy + 0.02 * ny)
        tail = (cx + 1.1 * nx, cy + 1.1 * ny)
        ax.annotate("", xy=tip, xytext=tail, arrowprops={"arrowstyle": "->", "color": "C2", "lw": 1.5})
        label = f"$F_{{N{side}}}$" + (" (×2 along the runner)" if n == 2 else "")
        ax.text(tail[0] + 0.05 * np.sign(nx), tail[1] + 0.08 * np.sign(ny), label, color="C2",
                ha="left" if nx > 0 else "right", va="center", fontsize=9)
    ax.annotate("", xy=(-1.55, 0), xytext=(-2.4, 0), arrowprops={"arrowstyle": "-|>", "lw": 2})
    ax.text(-2.4, 0.15, "preload $F_p$\n(left holder on\nlinear bearing)", fontsize=9, va="bottom")
    ax.plot([2.0, 2.0], [-1.3, 1.3], color="k", lw=2)
    ax.add_patch(patches.Rectangle((2.0, -1.3), 0.2, 2.6, hatch="////", fill=False, lw=0))
    ax.text(2.3, 0, "fixed\nright\nholder", va="center", fontsize=9)
    ax.set_xlim(-2.6, 2.9)
    ax.set_ylim(-1.7, 1.7)
    return fig


def plot_mdr_loop(df: pd.DataFrame):
    """Left: the 1-D MDR contact (Fig. 4b); right: its force along the loading loop, exact and discrete."""
    first = df.iloc[0]
    a, d, radius = first["contact_radius_m"], first["indentation_m"], first["hemisphere_radius_m"]
    springs = int(first["springs"])
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.8))
    # (a) the MDR picture: parabola g(x) - d over a row of springs.
    x = np.linspace(-1.6 * a, 1.6 * a, 400)
    ax1.plot(from_si(x, "um"), from_si(x**2 / radius - d, "nm"), color="C3", lw=2,
             label="profile $g(x) - d$, $R_1 = R/2$")
    base = -1.6 * d
    for xi in np.linspace(-1.5 * a, 1.5 * a, 31):
        top = min(0.0, xi**2 / radius - d)
        ax1.plot(from_si(np.array([xi, xi]), "um"), from_si(np.array([base, top]), "nm"),
                 color="C0" if top < 0 else "0.6", lw=1.2)
    ax1.axhline(0, color="0.6", lw=0.8, ls=":")
    ax1.annotate("", xy=(from_si(a, "um"), from_si(-1.15 * d, "nm")),
                 xytext=(from_si(-a, "um"), from_si(-1.15 * d, "nm")), arrowprops={"arrowstyle": "<->"})
    ax1.text(0, from_si(-1.3 * d, "nm"), "$2a$", ha="center", va="top")
    ax1.set_xlabel("$x$ (µm)")
    ax1.set_ylabel("height (nm)")
    ax1.set_title("MDR contact: springs in contact in blue", fontsize=10)
    ax1.legend(loc="upper center", fontsize=8)
    # (b) what Eqs. 4-6 give: virgin loading, unloading and reloading (discrete springs vs exact).
    ax2.plot(
        df["u_nm"], df["force_exact_mN"], color="C0", lw=2, label="exact limit (Cattaneo–Mindlin, Masing)"
    )
    ax2.plot(df["u_nm"], df[f"force_{springs}_springs_mN"], color="C1", lw=1, ls="--",
             label=f"{springs} springs (Eqs. 4–6)")
    limit = first["sliding_force_N"]
    for sgn in (1, -1):
        ax2.axhline(from_si(sgn * limit, "mN"), color="0.5", ls=":", lw=1)
    ax2.text(df["u_nm"].min(), from_si(0.9 * limit, "mN"), r"$\pm\mu F_N$", fontsize=9)
    ax2.set_xlabel("tangential displacement $u = x_a - x_r$ (nm)")
    ax2.set_ylabel("friction force on the runner (mN)")
    ax2.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    return fig
