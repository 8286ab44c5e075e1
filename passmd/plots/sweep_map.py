"""The picture of a design map: a curve over one axis, a heat map with contours over two."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from matplotlib import colors
from matplotlib.figure import Figure

from passmd.runtime.units import from_si

__all__ = ["MapAxis", "map_figure"]


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


def _values(table, axis: MapAxis) -> np.ndarray:
    """A result column as floats in the axis' unit; missing values (None) are NaN, masked when drawn."""
    return axis.shown([np.nan if v is None else float(v) for v in table[axis.column]])


def _edges(centers: np.ndarray, log: bool) -> np.ndarray:
    """Cell edges around grid values: midway between neighbours (geometrically on a log axis)."""
    c = np.log(centers) if log else np.asarray(centers, dtype=float)
    if c.size == 1:
        edges = np.array([c[0] - 0.5, c[0] + 0.5]) if not log else np.array([c[0] - 0.1, c[0] + 0.1])
    else:
        mid = 0.5 * (c[1:] + c[:-1])
        edges = np.concatenate([[2 * c[0] - mid[0]], mid, [2 * c[-1] - mid[-1]]])
    return np.exp(edges) if log else edges


def map_figure(table, axes: Sequence[MapAxis], value: MapAxis, title: str,
               also: Sequence[MapAxis] = ()) -> Figure:
    """The map of ``value`` over one or two ``axes`` of ``table`` (grid order, last axis fastest).

    One axis: ``value`` (and the ``also`` columns, dashed) against it. Two axes: a heat map of
    ``value`` over the first (x) and second (y) axis with labelled contour lines; a quantity
    that changes sign is drawn on a diverging scale centred on zero.
    """
    if len(axes) not in (1, 2):
        raise ValueError(f"axes = {len(axes)} axes: a map draws one or two")
    fig = Figure(figsize=(7, 4.8), layout="constrained")
    ax = fig.add_subplot()
    z = _values(table, value)
    if len(axes) == 1:
        (axis,) = axes
        x = axis.shown(table[axis.column])
        ax.plot(x, z, "o-", ms=3, label=value.label)
        for other in also:
            ax.plot(x, _values(table, other), "--", label=other.label)
        if also:
            ax.legend(fontsize=8)
        ax.set_xlabel(axis.title)
        ax.set_ylabel(value.title)
        if axis.log:
            ax.set_xscale("log")
        ax.grid(alpha=0.3)
    else:
        first, second = axes
        xs = first.shown(table[first.column]).reshape(-1)
        ys = second.shown(table[second.column]).reshape(-1)
        nx = np.unique(xs).size
        ny = xs.size // nx
        x = xs.reshape(nx, ny)[:, 0]
        y = ys.reshape(nx, ny)[0, :]
        grid = np.ma.masked_invalid(z.reshape(nx, ny).T)
        norm = None
        if grid.count() and grid.min() < 0 < grid.max():
            norm = colors.TwoSlopeNorm(vcenter=0.0, vmin=float(grid.min()), vmax=float(grid.max()))
        mesh = ax.pcolormesh(_edges(x, first.log), _edges(y, second.log), grid, shading="flat",
                             cmap="RdBu_r" if norm else "viridis", norm=norm)
        fig.colorbar(mesh, ax=ax, label=value.title)
        if grid.count() > 3 and min(nx, ny) >= 2 and float(grid.max()) > float(grid.min()):
            lines = ax.contour(x, y, grid, levels=8, colors="k", linewidths=0.6)
            ax.clabel(lines, fontsize=7, fmt="%.3g")
        ax.set_xlabel(first.title)
        ax.set_ylabel(second.title)
        if first.log:
            ax.set_xscale("log")
        if second.log:
            ax.set_yscale("log")
    ax.set_title(title, fontsize=9)
    return fig
