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
    "CHAPTERS", "CLAIM_MODULES", "FIGURES", "GRIDS", "READING_TABLES", "FigureSpec", "ReadingTable",
    "chapter_modules", "figure_data", "figure_names", "figure_plot", "figure_spec", "figures_read",
    "grid_shortfall",
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

#: Every figure whose grid depends on the profile, by name: profile -> {axis: values}, the ``GRIDS`` of
#: each chapter's ``figures.py``, built from the same settings as the figure's compute function. A
#: figure computed alike on every profile has no entry.
GRIDS: dict = {name: grid for module in chapter_modules("figures")
               for name, grid in getattr(module, "GRIDS", {}).items()}

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


def figures_read(keys) -> list[str]:
    """The figures behind result keys (figure names, or reading tables and the figures they read), in
    the book's order; keys that are neither (e.g. ``closed_forms``) name no figure."""
    names = set()
    for key in keys:
        if key in READING_TABLES:
            names.update(READING_TABLES[key].figures)
        elif key in _BY_NAME:
            names.add(key)
    return [name for name in figure_names() if name in names]


def _key(value):
    """A grid value as a comparable key: numbers to 6 significant digits, tuples element by element."""
    if isinstance(value, tuple):
        return tuple(_key(v) for v in value)
    return value if isinstance(value, str) else f"{value:.6g}"


def _points(grid: dict) -> set:
    """The grid points of one figure on one profile: the product of its axes (:func:`_key` of each value)."""
    import itertools

    return set(itertools.product(*([_key(v) for v in values] for values in grid.values())))


def grid_shortfall(names, profile: str, reference: str = "paper") -> pd.DataFrame:
    """How much of ``reference``'s grids the ``profile`` lacks for the figures ``names``: one row per
    figure with a profile-dependent grid (:data:`GRIDS`): ``figure``, ``axes`` (their names),
    ``points`` (on ``profile``), ``reference_points`` and ``missing`` (points of ``reference`` that
    ``profile`` does not compute)."""
    rows = []
    for name in names:
        if name not in GRIDS:
            continue
        here, there = _points(GRIDS[name](profile)), _points(GRIDS[name](reference))
        rows.append({"figure": name, "axes": " × ".join(GRIDS[name](reference)), "points": len(here),
                     "reference_points": len(there), "missing": len(there - here)})
    return pd.DataFrame(rows, columns=["figure", "axes", "points", "reference_points", "missing"])
