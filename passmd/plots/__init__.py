"""Plotting, separate from computing: each function takes a figure's tidy DataFrame and
returns a matplotlib Figure in the paper's layout (nm, N, mN, kHz, mm/s on the axes)."""
