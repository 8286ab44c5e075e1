"""Plotting, separate from computing: each function takes a figure's tidy DataFrame and
returns a matplotlib Figure in the paper's layout (nm, N, mN, kHz, mm/s on the axes).

Plots import only core modules (constants from :mod:`passmd.model.defaults` and
:mod:`passmd.model.tables`), never :mod:`passmd.experiments`: the figure table
:mod:`passmd.experiments.figure_table` joins each compute function to its plot."""
