"""The replication report's map: every claim's state at the defaults, the joint reading and the
runner-up readings of the assumption space (:func:`passmd.ledger.joint.joint_map`)."""

from __future__ import annotations

import textwrap

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.colors import ListedColormap
from matplotlib.patches import Patch

__all__ = ["STATE_COLOURS", "plot_joint_map"]

#: Colour of each state in the map (the ledger's category colours, darker for legibility).
STATE_COLOURS = {"holds": "#5cb85c", "fails": "#d9534f", "inconclusive": "#bbbbbb", "—": "#ffffff"}


def plot_joint_map(table: pd.DataFrame):
    """Claims (rows) × readings (columns) coloured by state; column labels carry how many claims
    hold there. ``table`` is :func:`passmd.ledger.joint.joint_map`'s result."""
    states = list(STATE_COLOURS)
    codes = np.vectorize(lambda s: states.index(s) if s in states else states.index("—"))(
        table.to_numpy(dtype=object)) if table.size else np.zeros((0, 0))
    height = 1.2 + 0.22 * len(table)
    fig, ax = plt.subplots(figsize=(2.2 + 1.15 * max(len(table.columns), 1) + 3.2, height))
    ax.imshow(codes, cmap=ListedColormap([STATE_COLOURS[s] for s in states]), vmin=-0.5,
              vmax=len(states) - 0.5, aspect="auto", interpolation="nearest")
    holding = table.attrs.get("holding", {})
    labels = [textwrap.fill(f"{c} ({holding[c]} hold)" if c in holding else str(c), 22)
              for c in table.columns]
    ax.set_xticks(range(len(table.columns)), labels, fontsize=7, rotation=0)
    ax.xaxis.tick_top()
    ax.set_yticks(range(len(table)), list(table.index), fontsize=7)
    ax.set_xticks(np.arange(-0.5, len(table.columns)), minor=True)
    ax.set_yticks(np.arange(-0.5, len(table)), minor=True)
    ax.grid(which="minor", color="white", linewidth=1.0)
    ax.tick_params(which="minor", length=0)
    ax.legend(handles=[Patch(facecolor=STATE_COLOURS[s], edgecolor="0.6",
                             label="not reached" if s == "—" else s) for s in states],
              loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    fig.tight_layout()
    return fig
