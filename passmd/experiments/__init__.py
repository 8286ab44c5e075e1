"""Experiments: one function per paper figure panel, each returning a tidy DataFrame.

Every panel is registered here under the paper's name (``fig5a`` … ``fig10c``) with the
function that computes its data for a resolution profile and the function that draws it.
The book, the ``passmd figure`` command and the ledger all go through :func:`figure_data`
and :func:`figure_plot`, so one code path produces every figure.

Profiles: ``quick`` (CI regression tests, minutes for everything) and ``paper`` (the
paper's grids; the book's default). Each topic module defines what a profile means for it.

Topic modules (import order = chapter order):

* :mod:`passmd.experiments.critical_amplitude` — Figs. 5 and 6 (Section 4.1)
* :mod:`passmd.experiments.force_generation` — Fig. 7 (Section 4.2)
* :mod:`passmd.experiments.driving_waveform` — Figs. 8–10 (Section 5)
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass

import pandas as pd

from passmd._validation import check_choice

PROFILES = ("quick", "paper")

#: Topic modules that register figures: one per chapter of the paper's Sections 3-5.
TOPIC_MODULES: tuple[str, ...] = ("critical_amplitude", "force_generation", "driving_waveform")
#: The book's figure chapters in reading order (book/_toc.yml), which is the paper's order:
#: a study panel such as ``fig56_frequency`` follows the panels of its chapter.
CHAPTERS: tuple[str, ...] = (
    "critical_amplitude_one", "critical_amplitude_six", "force_generation", "driving_waveform",
)


@dataclass(frozen=True)
class FigureSpec:
    """A registered figure panel."""

    name: str  # paper name, e.g. "fig5b"
    title: str  # one line: what the panel shows
    chapter: str  # book chapter file stem that shows it
    compute: Callable[[str], pd.DataFrame]  # profile -> tidy data (SI columns + display columns)
    plot: Callable[[pd.DataFrame], object]  # data -> matplotlib Figure


FIGURES: dict[str, FigureSpec] = {}


def register_figure(name: str, *, title: str, chapter: str, plot: Callable):
    """Decorator registering ``compute(profile) -> DataFrame`` as figure ``name``."""

    def deco(compute):
        if name in FIGURES and FIGURES[name].compute is not compute:
            raise ValueError(f"figure {name!r} is registered twice")
        FIGURES[name] = FigureSpec(name, title, chapter, compute, plot)
        return compute

    return deco


def _load_topics() -> None:
    for mod in TOPIC_MODULES:
        importlib.import_module(f"passmd.experiments.{mod}")


def figure_names() -> list[str]:
    """Names of every registered figure panel, in paper order."""
    _load_topics()

    def key(n):  # chapter by chapter as in the book, then fig5a < fig5b < ... < fig10c
        chapter = FIGURES[n].chapter
        position = CHAPTERS.index(chapter) if chapter in CHAPTERS else len(CHAPTERS)
        digits = "".join(c for c in n if c.isdigit())
        return (position, int(digits) if digits else float("inf"), n)

    return sorted(FIGURES, key=key)


def figure_spec(name: str) -> FigureSpec:
    """The registered spec of a figure; ``ValueError`` naming the known ones otherwise."""
    names = figure_names()
    if name not in FIGURES:
        known = ", ".join(names) or "(none yet)"
        raise ValueError(f"figure = {name!r} is not available: must be one of {known}")
    return FIGURES[name]


def figure_data(name: str, profile: str = "paper") -> pd.DataFrame:
    """Compute (or fetch from the sweep cache) the data of one figure panel."""
    check_choice("profile", profile, PROFILES)
    return figure_spec(name).compute(profile)


def figure_plot(name: str, data: pd.DataFrame):
    """Draw one figure panel from its data; returns a matplotlib Figure."""
    return figure_spec(name).plot(data)
