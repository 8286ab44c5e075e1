"""The picture of a design map: a curve over one axis, a heat map with contours over two.

A map shows a value only where it is one: cells with no value (Eq. 15 gives no waveform, no onset
up to the full stroke), cells whose run is not steady and cells below the value's resolution are
drawn apart (hatched or masked) and named in the legend, never coloured as if they were values. A
quantity with negative values is drawn on a scale symmetric about zero (diverging: blue below,
red above, a tiny value of either sign near white), and contours are drawn only through resolved,
steady cells.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from matplotlib import colors, ticker
from matplotlib.collections import PatchCollection
from matplotlib.figure import Figure
from matplotlib.patches import Patch, Rectangle

from passmd.protocols.velocity import STEADY_DRIFT_LIMIT
from passmd.runtime.units import from_si

__all__ = ["COLOR_SCALES", "LOG_SPAN", "CellMarks", "MapAxis", "cell_marks", "map_figure", "plain_log_ticks"]

#: A heat map's colour scales (:func:`map_figure`).
COLOR_SCALES = ("auto", "linear", "log")
#: Largest/smallest value beyond which ``"auto"`` colours a map of positive values on a log scale: two
#: decades, where a linear scale leaves the lowest decade one colour.
LOG_SPAN = 100.0


@dataclass(frozen=True)
class MapAxis:
    """One axis of a map: its column (SI), its label, the unit it is shown in, log spacing.

    ``scale``: the SI value of one ``unit`` (e.g. 1e-3 for mm/s); None: the unit's own factor
    (:func:`passmd.runtime.units.from_si`).
    """

    column: str
    label: str
    unit: str
    log: bool = False
    scale: float | None = None

    def shown(self, values) -> np.ndarray:
        values = np.asarray(values, dtype=float)
        if self.scale is not None:
            return values / self.scale
        return from_si(values, self.unit) if self.unit else values

    @property
    def title(self) -> str:
        return f"{self.label} [{self.unit}]" if self.unit else self.label


@dataclass(frozen=True)
class CellMarks:
    """Which points of a map are not plain values, each with the legend text that says why.

    ``missing``: no value; ``unsteady``: the run's velocity still drifts; ``unresolved``: the
    value is below its resolution (no measurable step). Boolean arrays in the table's order.
    """

    missing: np.ndarray
    unsteady: np.ndarray
    unresolved: np.ndarray
    missing_label: str = "no value"
    unsteady_label: str = (f"not steady: velocity drifts > {STEADY_DRIFT_LIMIT:.0%} between the run's last "
                           "quarters")
    unresolved_label: str = "below the resolution"

    @property
    def plain(self) -> np.ndarray:
        """Points that are values to colour and contour."""
        return ~(self.missing | self.unsteady | self.unresolved)


def _values(table, axis: MapAxis) -> np.ndarray:
    """A result column as floats in the axis' unit; missing values (None) are NaN."""
    return axis.shown([np.nan if v is None else float(v) for v in table[axis.column]])


def cell_marks(table, value: MapAxis, resolution=None, *, missing_label: str = "no value",
               resolution_label: str = "below the resolution") -> CellMarks:
    """The :class:`CellMarks` of ``table``'s ``value`` column.

    ``resolution``: each point's resolution (SI, as the column), e.g. the measurable step δ for a
    step and δ·f for a velocity; a value whose magnitude is below it is unresolved. A table with a
    ``velocity_drift`` column (the steady-velocity protocol) marks points whose |drift| exceeds
    :data:`passmd.protocols.velocity.STEADY_DRIFT_LIMIT` as not steady.
    """
    raw = np.array([np.nan if v is None else float(v) for v in table[value.column]])
    missing = ~np.isfinite(raw)
    unresolved = np.zeros(raw.size, dtype=bool)
    if resolution is not None:  # first: the relative drift of a velocity below its resolution is noise
        unresolved = ~missing & (np.abs(np.nan_to_num(raw)) < np.asarray(resolution, dtype=float))
    unsteady = np.zeros(raw.size, dtype=bool)
    if "velocity_drift" in table:
        drift = np.array([np.nan if v is None else float(v) for v in table["velocity_drift"]])
        unsteady = ~missing & ~unresolved & np.isfinite(drift) & (np.abs(drift) > STEADY_DRIFT_LIMIT)
    return CellMarks(missing, unsteady, unresolved, missing_label=missing_label,
                     unresolved_label=resolution_label)


def _edges(centers: np.ndarray, log: bool) -> np.ndarray:
    """Cell edges around grid values: midway between neighbours (geometrically on a log axis)."""
    c = np.log(centers) if log else np.asarray(centers, dtype=float)
    if c.size == 1:
        edges = np.array([c[0] - 0.5, c[0] + 0.5]) if not log else np.array([c[0] - 0.1, c[0] + 0.1])
    else:
        mid = 0.5 * (c[1:] + c[:-1])
        edges = np.concatenate([[2 * c[0] - mid[0]], mid, [2 * c[-1] - mid[-1]]])
    return np.exp(edges) if log else edges


#: How each kind of marked point is drawn: hatch, face colour, curve marker.
_STYLE = {"missing": ("xx", "0.82", "x"), "unsteady": ("//", "0.92", "o"), "unresolved": ("..", "white", "s")}


def map_figure(table, axes: Sequence[MapAxis], value: MapAxis, title: str,
               also: Sequence[MapAxis] = (), *, marks: CellMarks | None = None, notes: Sequence[str] = (),
               color_scale: str = "auto", band: tuple[str, str, str] | None = None) -> Figure:
    """The map of ``value`` over one or two ``axes`` of ``table`` (grid order, last axis fastest).

    One axis: ``value`` (and the ``also`` columns, dashed) against it; marked points are drawn
    apart (open markers, crosses for missing values at the axis' foot). Two axes: a heat map over
    the first (x) and second (y) axis; marked cells are hatched over a neutral face and left out
    of the colour scale and of the labelled contours. ``marks`` default: missing values only.
    ``notes``: lines the legend ends with (e.g. what makes a curve turn). ``color_scale``: a heat
    map's colour scale, ``"linear"``, ``"log"`` (values > 0 only; a map with a value <= 0 is refused)
    or ``"auto"`` (log where every value is > 0 and they span more than :data:`LOG_SPAN`).
    ``band``: (low column, high column, label) of a band shaded about a curve (one axis only).
    """
    if color_scale not in COLOR_SCALES:
        raise ValueError(f"color_scale = {color_scale!r} is not allowed: must be one of "
                         f"{', '.join(COLOR_SCALES)}")
    if len(axes) not in (1, 2):
        raise ValueError(f"axes = {len(axes)} axes: a map draws one or two")
    z = _values(table, value)
    if marks is None:
        marks = cell_marks(table, value)
    fig = Figure(figsize=(7, 4.8), layout="constrained")
    ax = fig.add_subplot()
    handles = _curve(ax, table, axes[0], value, z, marks, also) if len(axes) == 1 else \
        _heat_map(fig, ax, table, axes, value, z, marks, color_scale)
    if band is not None and len(axes) == 1:
        low, high = (_values(table, MapAxis(c, "", value.unit, scale=value.scale)) for c in band[:2])
        handles.append(ax.fill_between(axes[0].shown(table[axes[0].column]), low, high, color="C0", alpha=0.2,
                                       lw=0, label=band[2]))
    handles += [Patch(visible=False, label=note) for note in notes]
    if handles:
        ax.legend(handles=handles, fontsize=7, loc="upper left", bbox_to_anchor=(0.0, -0.14), ncols=1,
                  frameon=False)
    ax.set_title(title, fontsize=9)
    return fig


def _curve(ax, table, axis: MapAxis, value: MapAxis, z, marks: CellMarks, also) -> list:
    x = axis.shown(table[axis.column])
    plain = marks.plain
    ax.plot(x, np.where(marks.missing, np.nan, z), "-", color="C0", lw=1, alpha=0.5)
    handles = [ax.plot(x[plain], z[plain], "o", ms=4, color="C0", label=value.label)[0]]
    for kind, label in (("unsteady", marks.unsteady_label), ("unresolved", marks.unresolved_label)):
        chosen = getattr(marks, kind)
        if chosen.any():
            handles.append(ax.plot(x[chosen], z[chosen], _STYLE[kind][2], ms=6, mfc="none", color="C3",
                                   label=label)[0])
    for k, other in enumerate(also):
        handles.append(ax.plot(x, _values(table, other), "--", color=f"C{k + 1}", label=other.label)[0])
    if marks.missing.any():
        handles.append(ax.plot(x[marks.missing], np.zeros(int(marks.missing.sum())), "x", color="0.4", ms=7,
                               transform=ax.get_xaxis_transform(), clip_on=False,
                               label=marks.missing_label)[0])
    ax.set_xlabel(axis.title)
    ax.set_ylabel(value.title)
    if axis.log:
        ax.set_xscale("log")
        plain_log_ticks(ax.xaxis)
    ax.grid(alpha=0.3)
    return handles


def _log_colors(shown, color_scale: str) -> bool:
    """Whether the heat map's colours go on a log scale (:func:`map_figure`)."""
    if color_scale == "linear" or not shown.count():
        return False
    positive = float(shown.min()) > 0
    if color_scale == "log" and not positive:
        raise ValueError(f"color_scale = 'log' needs values > 0: this map has {float(shown.min()):.4g}")
    return positive and (color_scale == "log" or float(shown.max()) / float(shown.min()) > LOG_SPAN)


def plain_log_ticks(axis) -> None:
    """Tick labels of a log axis as plain numbers (``6``, ``200``), not ``6×10⁰``."""
    label = ticker.FuncFormatter(lambda v, _: f"{v:g}")
    axis.set_major_formatter(label)
    axis.set_minor_formatter(ticker.FuncFormatter(
        lambda v, _: f"{v:g}" if f"{v:.1e}"[0] in "25" else ""))


def _heat_map(fig, ax, table, axes, value: MapAxis, z, marks: CellMarks, color_scale: str = "auto") -> list:
    first, second = axes
    xs = first.shown(table[first.column]).reshape(-1)
    ys = second.shown(table[second.column]).reshape(-1)
    nx = np.unique(xs).size
    ny = xs.size // nx
    x = xs.reshape(nx, ny)[:, 0]
    y = ys.reshape(nx, ny)[0, :]

    def grid(values):
        return np.asarray(values).reshape(nx, ny).T

    plain = grid(marks.plain)
    shown = np.ma.masked_array(grid(z), mask=~plain)
    norm, cmap = None, "viridis"
    log = _log_colors(shown, color_scale)
    if log:
        norm = colors.LogNorm(vmin=float(shown.min()), vmax=float(shown.max()))
    elif shown.count() and shown.min() < 0:  # a signed value: diverging, symmetric, zero white
        top = float(np.abs(shown).max())
        norm, cmap = colors.Normalize(vmin=-top, vmax=top), "RdBu_r"
    x_edges, y_edges = _edges(x, first.log), _edges(y, second.log)
    mesh = ax.pcolormesh(x_edges, y_edges, shown, shading="flat", cmap=cmap, norm=norm)
    bar = fig.colorbar(mesh, ax=ax, label=value.title + (" (log scale)" if log else ""))
    if log:
        plain_log_ticks(bar.ax.yaxis)
    elif norm is not None:
        bar.locator = ticker.MaxNLocator(nbins=8, symmetric=True)
        bar.update_ticks()
    handles = []
    for kind in ("missing", "unsteady", "unresolved"):
        chosen = grid(getattr(marks, kind))
        if not chosen.any():
            continue
        hatch, face, _ = _STYLE[kind]
        cells = [Rectangle((x_edges[i], y_edges[j]), x_edges[i + 1] - x_edges[i], y_edges[j + 1] - y_edges[j])
                 for j, i in zip(*np.nonzero(chosen), strict=True)]
        ax.add_collection(PatchCollection(cells, facecolor=face, edgecolor="0.45", hatch=hatch, lw=0.0))
        handles.append(Patch(facecolor=face, edgecolor="0.45", hatch=hatch,
                             label=getattr(marks, f"{kind}_label")))
    if shown.count() > 3 and min(nx, ny) >= 2 and float(shown.max()) > float(shown.min()):
        locator = ticker.LogLocator(subs=(1.0, 2.0, 5.0)) if log else ticker.MaxNLocator(nbins=8)
        levels = locator.tick_values(float(shown.min()), float(shown.max()))
        levels = [v for v in levels if float(shown.min()) < v < float(shown.max())]
        if levels:
            lines = ax.contour(x, y, shown, levels=levels, colors="k", linewidths=0.6)
            ax.clabel(lines, fontsize=7, fmt="%.3g")
    ax.set_xlabel(first.title)
    ax.set_ylabel(second.title)
    if first.log:
        ax.set_xscale("log")
        plain_log_ticks(ax.xaxis)
    if second.log:
        ax.set_yscale("log")
        plain_log_ticks(ax.yaxis)
    return handles
