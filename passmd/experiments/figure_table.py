"""The figure table: every figure the book shows, by name, in the book's chapter order.

Each row (:class:`~passmd.experiments.FigureSpec`) names a panel, says in one line what it shows and
which chapter shows it, and gives its compute function (run configuration → tidy DataFrame, SI
columns plus display columns) and its plot function (DataFrame → matplotlib Figure). The book,
``passmd figure`` and the ledger all go through :func:`figure_data` and :func:`figure_plot`, so one
code path produces every figure. Every figure a chapter shows is a row; the ledger computes only the
rows and reading tables its claims require (``requires`` in claims.csv, and the reading tables' figures).

The rows are each chapter's own: :data:`FIGURES` and :data:`READING_TABLES` join the ``FIGURES`` and
``READING_TABLES`` tuples of the ``figures.py`` of every chapter in :data:`CHAPTERS` (the book's
order, ``book/_toc.yml``); :data:`CLAIM_MODULES` holds every chapter's ``claims.py``.
"""

from __future__ import annotations

import importlib
from pathlib import Path
from types import ModuleType

import pandas as pd

from passmd.experiments import FigureSpec, ReadingTable
from passmd.runtime.config import RunConfig

__all__ = [
    "CHAPTERS", "CLAIM_MODULES", "FIGURES", "READING_TABLES", "FigureSpec", "ReadingTable", "chapter_modules",
    "figure_data", "figure_names", "figure_plot", "figure_spec",
]

#: The book chapters that compute something, in the book's order (``book/_toc.yml``): each is a
#: package ``passmd.experiments.<chapter>`` of the same modules.
CHAPTERS = ("model", "model_numerics", "mdr_validation", "critical_amplitude_one", "critical_amplitude_six",
            "force_generation", "driving_waveform", "waveform_velocity", "waveform_optimum",
            "design_your_drive", "calibration")


def chapter_modules(role: str) -> tuple[ModuleType, ...]:
    """The module ``<role>.py`` of every chapter of :data:`CHAPTERS` that has one, in the book's
    order (``role``: ``"figures"``, ``"facts"`` or ``"claims"``)."""
    chapters = Path(__file__).parent
    return tuple(importlib.import_module(f"passmd.experiments.{chapter}.{role}")
                 for chapter in CHAPTERS if (chapters / chapter / f"{role}.py").is_file())


#: Every figure of the book, in the book's chapter order: the ``FIGURES`` of each chapter's
#: ``figures.py``.
FIGURES: tuple[FigureSpec, ...] = tuple(
    spec for module in chapter_modules("figures") for spec in getattr(module, "FIGURES", ()))

#: Every table of the ledger's readings, by result key: the ``READING_TABLES`` of each chapter's
#: ``figures.py``.
READING_TABLES: dict[str, ReadingTable] = {
    spec.key: spec for module in chapter_modules("figures") for spec in getattr(module, "READING_TABLES", ())}

#: The experiment modules whose functions carry claim extractors (Sections 4.1, 4.2, 5): every
#: chapter's ``claims.py``.
CLAIM_MODULES: tuple[ModuleType, ...] = chapter_modules("claims")

_BY_NAME = {spec.name: spec for spec in FIGURES}


def figure_names() -> list[str]:
    """Names of every figure panel, in the book's chapter order."""
    return [spec.name for spec in FIGURES]


def figure_spec(name: str) -> FigureSpec:
    """The table row of a figure; ``ValueError`` naming the known figures otherwise."""
    if name not in _BY_NAME:
        raise ValueError(f"figure = {name!r} is not available: must be one of {', '.join(_BY_NAME)}")
    return _BY_NAME[name]


def figure_data(name: str, config: RunConfig) -> pd.DataFrame:
    """Compute (or fetch from the sweep cache) the data of one figure panel."""
    if not isinstance(config, RunConfig):
        raise ValueError(f"config = {config!r} is not a RunConfig: "
                         "pass passmd.runtime.config.RunConfig(profile=...)")
    return figure_spec(name).compute(config)


def figure_plot(name: str, data: pd.DataFrame):
    """Draw one figure panel from its data; returns a matplotlib Figure."""
    return figure_spec(name).plot_function()(data)
