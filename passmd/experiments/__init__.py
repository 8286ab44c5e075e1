"""Experiments: the grids, figure data, claim extractors and chapter facts of each paper section.

Each topic module turns the protocols of :mod:`passmd.protocols` into the tidy DataFrames of
the paper's figures, one compute function ``compute(config: RunConfig) -> DataFrame`` per
panel, and the small tested functions whose results the chapters quote; the claim extractors
of a section sit beside its topic module in ``<topic>_claims`` (the modules
:data:`passmd.experiments.figure_table.CLAIM_MODULES` lists). The figure table that names every panel, its
chapter and its plot is :mod:`passmd.experiments.figure_table`; nothing here imports ``passmd.plots``.

Profiles (:data:`passmd.runtime.config.PROFILES`): ``quick`` (CI regression tests, minutes for
everything) and ``paper`` (the paper's grids; the book's default). Each topic module
defines what a profile means for it.
"""
