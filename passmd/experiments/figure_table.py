"""The figure table: every figure the book shows, by name, in the book's chapter order.

Each row (:class:`FigureSpec`) names a panel, says in one line what it shows and which
chapter shows it, and gives its compute function (run configuration → tidy DataFrame, SI
columns plus display columns) and its plot function (DataFrame → matplotlib Figure). The
book, ``passmd figure`` and the ledger all go through :func:`figure_data` and
:func:`figure_plot`, so one code path produces every figure.

:data:`CLAIM_MODULES` holds the experiment modules with claim extractors, found by name.
"""

from __future__ import annotations

import functools
import importlib
import pkgutil
import re
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import NamedTuple

import pandas as pd

from passmd.experiments.critical_amplitude.facts import fig5_flyback_steps
from passmd.experiments.critical_amplitude.figures import (
    AC_PANELS,
    ac_readings,
    fig5a,
    fig5a_readings,
    fig5b,
    fig6a,
    fig6b,
    fig6c,
    fig56_frequency,
    fig56_viscosity,
)
from passmd.experiments.driving_waveform.facts import settling_scans
from passmd.experiments.driving_waveform.figures import (
    fig8a,
    fig8a_readings,
    fig8b,
    fig8b_readings,
    fig8b_window,
    fig8b_window_readings,
    fig9a,
    fig9a_response,
    fig9b,
    fig9b_readings,
    fig10a,
    fig10a_readings,
    fig10b,
    fig10b_readings,
    fig10c,
    fig10c_readings,
)
from passmd.experiments.driving_waveform.studies import flexible_study, numerical_optimum, startup_transient
from passmd.experiments.force_generation.facts import fig7_difference
from passmd.experiments.force_generation.figures import (
    fig7_readings,
    fig7a,
    fig7b,
    fig7cycle,
    fig7freq,
    fig7grid,
)
from passmd.experiments.mdr_validation.figures import (
    mdr_convergence,
    mdr_cost,
    mdr_hysteresis,
    mdr_normal,
    mdr_springs,
    mdr_virgin,
)
from passmd.experiments.model.figures import (
    model_cross_section,
    model_free_body,
    model_mdr_loop,
    model_sawtooth,
)
from passmd.experiments.numerics.figures import model_convergence, model_coulomb_limit
from passmd.runtime.config import RunConfig

__all__ = [
    "CLAIM_MODULES", "FIGURES", "READING_TABLES", "FigureSpec", "ReadingTable", "figure_data", "figure_names",
    "figure_plot", "figure_spec",
]


class FigureSpec(NamedTuple):
    """One figure panel of the book."""

    name: str  #: paper name, e.g. "fig5b"
    title: str  #: one line: what the panel shows
    chapter: str  #: book chapter file stem that shows it
    compute: Callable[[RunConfig], pd.DataFrame]  #: run configuration -> tidy data
    #: ``"module:function"`` of ``passmd.plots`` drawing the data (a matplotlib Figure); named,
    #: not imported, so that computing a figure's data (the ledger, the sweeps) loads no matplotlib
    plot: str

    def plot_function(self) -> Callable[[pd.DataFrame], object]:
        """The plot function of :attr:`plot`, imported on first use."""
        module, _, name = self.plot.partition(":")
        return getattr(importlib.import_module(f"passmd.plots.{module}"), name)


#: Every figure of the book, in the book's chapter order (book/_toc.yml).
FIGURES: tuple[FigureSpec, ...] = (
    # Sections 2-3, the model (book/model.md)
    FigureSpec("model_sawtooth", "Saw-tooth piezo position x_p(t) at full stroke (Figs. 1d, 3c)",
               "model", model_sawtooth, "model:plot_sawtooth"),
    FigureSpec("model_free_body", "Free-body diagram of the macroscopic model, Eqs. 2-3 (Fig. 3a, schematic)",
               "model", model_free_body, "model:plot_free_body"),
    FigureSpec("model_cross_section", "Cross-section of the runner with the normal forces of Eq. 1 (Fig. 3b)",
               "model", model_cross_section, "model:plot_cross_section"),
    FigureSpec("model_mdr_loop", "The 1-D MDR contact and its force loop, exact and 50 springs (Fig. 4)",
               "model", model_mdr_loop, "model:plot_mdr_loop"),
    # Integrator (book/model_numerics.md)
    FigureSpec("model_convergence", "Time-step convergence of the runner position after three periods",
               "model_numerics", model_convergence, "numerics:plot_convergence"),
    FigureSpec("model_coulomb_limit", "Simulated step against the rigid Coulomb limit, stiffened contacts",
               "model_numerics", model_coulomb_limit, "numerics:plot_coulomb_limit"),
    # The MDR contact (book/mdr_validation.md)
    FigureSpec("mdr_springs", "Springs of the discrete MDR contact after loading and unloading (Fig. 4b)",
               "mdr_validation", mdr_springs, "mdr:plot_springs"),
    FigureSpec("mdr_normal", "MDR normal force against Hertz", "mdr_validation", mdr_normal,
               "mdr:plot_normal"),
    FigureSpec("mdr_virgin", "Virgin tangential loading against Cattaneo-Mindlin", "mdr_validation",
               mdr_virgin, "mdr:plot_virgin"),
    FigureSpec("mdr_hysteresis", "Major and nested minor hysteresis loop against Masing", "mdr_validation",
               mdr_hysteresis, "mdr:plot_hysteresis"),
    FigureSpec("mdr_convergence", "Deviation of the discrete MDR contact from the exact one against N",
               "mdr_validation", mdr_convergence, "mdr:plot_convergence"),
    FigureSpec("mdr_cost", "Cost per contact update against the number of springs (benchmark)",
               "mdr_validation", mdr_cost, "mdr:plot_cost"),
    # Section 4.1, one contact (book/critical_amplitude_one.md)
    FigureSpec("fig5a", "Step size against actuation amplitude, one contact, 0.4 N, R = 1 mm",
               "critical_amplitude_one", fig5a, "critical_amplitude:plot_fig5a"),
    FigureSpec("fig5_flyback_steps", "Step across each fly-back of a run from rest, rigid, 0.4 N, R = 1 mm",
               "critical_amplitude_one", fig5_flyback_steps,
               "critical_amplitude:plot_flyback_steps"),
    FigureSpec("fig5b", "Critical amplitude against preload, one contact, R = 1 mm",
               "critical_amplitude_one", fig5b, "critical_amplitude:plot_fig5b"),
    # Section 4.1, six contacts (book/critical_amplitude_six.md)
    FigureSpec("fig6a", "Critical amplitude against preload, six contacts, rigid, R = 1 mm",
               "critical_amplitude_six", fig6a, "critical_amplitude:plot_fig6"),
    FigureSpec("fig6b", "Critical amplitude against preload, six contacts, flexible, R = 1 mm",
               "critical_amplitude_six", fig6b, "critical_amplitude:plot_fig6"),
    FigureSpec("fig6c", "Critical amplitude against preload, six contacts, flexible, R = 0.25 mm",
               "critical_amplitude_six", fig6c, "critical_amplitude:plot_fig6"),
    FigureSpec("fig56_frequency", "Critical amplitude against drive frequency, 0.4 N, R = 1 mm",
               "critical_amplitude_six", fig56_frequency,
               "critical_amplitude:plot_frequency"),
    FigureSpec("fig56_viscosity", "Critical amplitude against actuator viscosity c_p, 0.4 N, R = 1 mm",
               "critical_amplitude_six", fig56_viscosity,
               "critical_amplitude:plot_viscosity"),
    # Section 4.2 (book/force_generation.md)
    FigureSpec("fig7a", "Generated force against amplitude, R = 1 mm, 0.3 and 0.8 N",
               "force_generation", fig7a, "force_generation:plot_panel"),
    FigureSpec("fig7b", "Generated force against amplitude, R = 0.25 mm, 0.2 and 0.4 N",
               "force_generation", fig7b, "force_generation:plot_panel"),
    FigureSpec("fig7_difference", "F_gen(rigid, μ = 0.3) − F_gen(flexible, μ = 0.2) against amplitude, "
               "each preload of Fig. 7", "force_generation", fig7_difference,
               "force_generation:plot_fig7_difference"),
    FigureSpec("fig7cycle", "One period at stall, rigid/flexible × μ = 0.3/0.2, R = 1 mm, A_max",
               "force_generation", fig7cycle, "force_generation:plot_cycle"),
    FigureSpec("fig7freq", "Generated force at full amplitude against the drive frequency",
               "force_generation", fig7freq, "force_generation:plot_frequency"),
    FigureSpec("fig7grid", "Generated force for every preload of both radii (beyond the paper)",
               "force_generation", fig7grid, "force_generation:plot_grid"),
    # Section 5 (book/driving_waveform.md)
    FigureSpec("fig8a", "Runner response to two saw-tooth periods, with the contact status",
               "driving_waveform", fig8a, "driving_waveform:plot_fig8a"),
    FigureSpec("fig8b", "The optimized waveform (Eq. 15) with t_s, t_a and Δ_a",
               "driving_waveform", fig8b, "driving_waveform:plot_fig8b"),
    FigureSpec("fig8b_window", "Fig. 8b's fly-back and acceleration t_a, resolved in time",
               "driving_waveform", fig8b_window, "driving_waveform:plot_fig8b_window"),
    FigureSpec("fig9a", "Runner position over three 100 Hz periods, saw-tooth and optimized",
               "driving_waveform", fig9a, "driving_waveform:plot_fig9a"),
    FigureSpec("study_startup", "Velocity period by period from rest at 110 kHz (steady-velocity protocol)",
               "driving_waveform", startup_transient, "driving_waveform:plot_startup"),
    FigureSpec("fig9b", "Steady velocity against driving frequency, saw-tooth and optimized",
               "driving_waveform", fig9b, "driving_waveform:plot_fig9b"),
    FigureSpec("fig10a", "Velocity of the optimized waveform for preloads 0.1, 0.4, 1 N",
               "driving_waveform", fig10a, "driving_waveform:plot_fig10a"),
    FigureSpec("fig10b", "Velocity of the optimized waveform for R = 1 mm and 0.25 mm",
               "driving_waveform", fig10b, "driving_waveform:plot_fig10b"),
    FigureSpec("fig10c", "Velocity of the optimized waveform, steel and molybdenum runner",
               "driving_waveform", fig10c, "driving_waveform:plot_fig10c"),
    FigureSpec("study_settling_scan", "Step at 100 Hz against the settling time, Eq. 15's and the optimum's "
               "acceleration (beyond the paper)", "driving_waveform", settling_scans,
               "driving_waveform:plot_settling_scans"),
    FigureSpec("study_optimum", "Velocity of Eq. 15's design and of a numerical optimum relative to the "
               "saw-tooth (beyond the paper)", "driving_waveform", numerical_optimum,
               "driving_waveform:plot_optimum"),
    FigureSpec("study_flexible", "Gain of the optimized waveform with rigid and flexible actuators "
               "(beyond the paper)", "driving_waveform", flexible_study,
               "driving_waveform:plot_flexible"),
)

class ReadingTable(NamedTuple):
    """A table of the ledger's readings: every run some claims read, at every point of the axes of
    :mod:`passmd.ledger.readings` that change it (the defaults are the figures' own runs)."""

    key: str  #: result key, e.g. "fig5b_readings"
    title: str  #: one line: what it holds
    figures: tuple[str, ...]  #: the figures whose claims read it (a chapter's ledger rows)
    compute: Callable[[RunConfig], pd.DataFrame]  #: run configuration -> tidy data


#: Every table of the ledger's readings, by result key.
READING_TABLES: dict[str, ReadingTable] = {
    spec.key: spec
    for spec in (
        ReadingTable("fig5a_readings", "Fig. 5a's step against amplitude at every reading",
                     ("fig5a",), fig5a_readings),
        *(ReadingTable(f"{panel}_readings", f"Fig. {panel[3:]}'s A_c searches at every reading", (panel,),
                       functools.partial(ac_readings, panel=panel))
          for panel in AC_PANELS),
        ReadingTable("fig7_readings", "This paper's force runs at half and full stroke at every reading",
                     ("fig7a", "fig7b"), fig7_readings),
        ReadingTable("fig8a_readings", "Fig. 8a at every μ", ("fig8a",), fig8a_readings),
        ReadingTable("fig8b_readings", "Fig. 8b at every μ", ("fig8b",), fig8b_readings),
        ReadingTable("fig8b_window_readings", "Fig. 8b's fly-back window at every μ", ("fig8b_window",),
                     fig8b_window_readings),
        ReadingTable("fig9a_response", "The response after an optimized period, at every μ", ("fig9a",),
                     fig9a_response),
        ReadingTable("fig9b_readings", "Fig. 9b at every μ", ("fig9b",), fig9b_readings),
        ReadingTable("fig10a_readings", "Fig. 10a at every μ", ("fig10a",), fig10a_readings),
        ReadingTable("fig10b_readings", "Fig. 10b at every μ", ("fig10b",), fig10b_readings),
        ReadingTable("fig10c_readings", "Fig. 10c at every μ", ("fig10c",), fig10c_readings),
    )
}


def _claim_modules() -> tuple[ModuleType, ...]:
    """Every chapter's ``claims.py`` and ``claims_<topic>.py``, found by their names."""
    chapters = Path(__file__).parent
    return tuple(importlib.import_module(f"passmd.experiments.{chapter.name}.{module.name}")
                 for chapter in pkgutil.iter_modules([str(chapters)]) if chapter.ispkg
                 for module in pkgutil.iter_modules([str(chapters / chapter.name)])
                 if re.fullmatch(r"claims(_\w+)?", module.name))


#: The experiment modules whose functions carry claim extractors (Sections 4.1, 4.2, 5): every
#: chapter's ``claims.py`` and ``claims_<topic>.py``.
CLAIM_MODULES: tuple[ModuleType, ...] = _claim_modules()

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
