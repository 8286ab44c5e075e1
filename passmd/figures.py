"""The figure table: every figure the book shows, by name.

Name → compute function (run configuration → tidy DataFrame), plot function
(DataFrame → matplotlib Figure), book chapter and the claims its data decides. The book,
``passmd figure`` and the ledger all go through :func:`figure_data` and :func:`figure_plot`.
"""

from __future__ import annotations

from passmd.experiments import figure_data, figure_names, figure_plot, figure_spec

# In chapter order: importing a module registers its assumptions, which the book lists in that order.
# isort: off
from passmd.experiments import critical_amplitude, force_generation, driving_waveform
# isort: on

__all__ = ["CLAIM_MODULES", "figure_data", "figure_names", "figure_plot", "figure_spec"]

#: The modules holding the claim extractors of the figures (tagged with passmd.checks.extractor).
CLAIM_MODULES = (critical_amplitude, force_generation, driving_waveform)
