"""Experiments: one package per book chapter that computes something, ``experiments/<book-stem>/``.

Every chapter package has the same modules: ``figures.py`` (the chapter's compute functions, run
configuration → tidy DataFrame, and its rows of the figure table: a tuple ``FIGURES`` of
:class:`FigureSpec`, one per figure the chapter shows, and, where the ledger reads runs beyond the
figures', ``READING_TABLES`` of :class:`ReadingTable`; the ledger computes only the tables its claims
require, so a row no claim reads costs it nothing), ``facts.py`` (the numbers and short texts the
chapter's prose quotes) and, where the chapter judges claims of the paper, ``claims.py`` (the ledger's
claim extractors), and no other module. Code several chapters or the command line share lives in
:mod:`passmd.protocols`.
:mod:`passmd.experiments.figure_table` assembles the figure table from the chapters in
:data:`~passmd.experiments.figure_table.CHAPTERS` (the book's order) and finds the claim modules;
nothing here imports ``passmd.plots``.

Profiles (:data:`passmd.runtime.config.PROFILES`): ``quick`` (CI regression tests, minutes for
everything) and ``paper`` (the paper's grids; the book's default). Each chapter defines what a
profile means for it.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import NamedTuple

__all__ = ["FigureSpec", "ReadingTable"]


class FigureSpec(NamedTuple):
    """One figure panel of the book."""

    name: str  #: paper name, e.g. "fig5b"
    title: str  #: one line: what the panel shows
    chapter: str  #: book chapter file stem that shows it
    compute: Callable  #: run configuration -> tidy data (pandas.DataFrame)
    #: ``"module:function"`` of ``passmd.plots`` drawing the data (a matplotlib Figure); named,
    #: not imported, so that computing a figure's data (the ledger, the sweeps) loads no matplotlib
    plot: str

    def plot_function(self) -> Callable:
        """The plot function of :attr:`plot`, imported on first use."""
        module, _, name = self.plot.partition(":")
        return getattr(importlib.import_module(f"passmd.plots.{module}"), name)


class ReadingTable(NamedTuple):
    """A table of the ledger's readings: every run some claims read, at every point of the axes of
    :mod:`passmd.ledger.readings` that change it (the defaults are the figures' own runs)."""

    key: str  #: result key, e.g. "fig5b_readings"
    title: str  #: one line: what it holds
    figures: tuple[str, ...]  #: the figures whose claims read it (a chapter's ledger rows)
    compute: Callable  #: run configuration -> tidy data (pandas.DataFrame)
