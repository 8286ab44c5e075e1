"""Critical actuation amplitude, six contacts: Figs. 6a–c and the sensitivity panels (Section 4.1).

Six contacts against Eqs. 10–14, and two sensitivity panels beyond the paper for one and six
contacts, ``fig56_viscosity`` (A_c vs actuator viscosity c_p) and ``fig56_frequency`` (A_c vs drive
frequency). The drives, profiles, searches and readings of Section 4.1 are those of
:mod:`passmd.experiments.critical_amplitude_one.figures`. Each compute function takes a
:class:`~passmd.runtime.config.RunConfig` and returns a tidy DataFrame (lengths in nm)."""

from __future__ import annotations

import functools

import pandas as pd

from passmd.experiments import FigureSpec, ReadingTable
from passmd.experiments.critical_amplitude_one.figures import (
    FIG5A_DRIVE,
    PROFILE_SETTINGS,
    ac_readings,
    paper_drive_for,
    preload_figure,
    run_searches,
)
from passmd.model.defaults import PROTOCOL
from passmd.model.tables import ACTUATOR_DAMPING_RATIO, actuator_for_radius
from passmd.protocols.critical_amplitude import PROTOCOLS
from passmd.runtime.config import RunConfig

__all__ = ["FIG5A_DRIVE", "FIGURES", "GRIDS", "PROFILE_SETTINGS", "READING_TABLES", "fig56_frequency",
           "fig56_viscosity", "fig6a", "fig6b", "fig6c"]


def fig6a(config: RunConfig) -> pd.DataFrame:
    """Fig. 6a: A_c against preload, six contacts, rigid actuators, with Eqs. 10 and 11 (nm)."""
    return preload_figure(config, 6, 1.0e-3, ("rigid",), "fig6a_closed_form")


def fig6b(config: RunConfig) -> pd.DataFrame:
    """Fig. 6b: A_c against preload, six contacts, flexible actuators, R = 1 mm, with Eqs. 12–14 (nm)."""
    return preload_figure(config, 6, 1.0e-3, ("flexible",), "fig6b_closed_form")


def fig6c(config: RunConfig) -> pd.DataFrame:
    """Fig. 6c: A_c against preload, six contacts, flexible actuators, R = 0.25 mm, with Eqs. 12–14 (nm)."""
    return preload_figure(config, 6, 0.25e-3, ("flexible",), "fig6c_closed_form")


def _closed_form_at(contacts: int, actuator_model: str, radius: float, preload: float) -> float:
    """Eq. 7/8 (one contact) or Eq. 11/12 (six contacts) in nm, from passmd.model.theory."""
    from passmd.model.theory import drive_theory

    drive = paper_drive_for(contacts, actuator_model, radius, preload)
    return drive_theory(drive)["analytic_critical_amplitude_m"] * 1e9


def fig56_viscosity(config: RunConfig) -> pd.DataFrame:
    """Beyond the paper: A_c of flexible actuators against c_p (a decade either side of the default).

    One and six contacts, F_p = 0.4 N, R = 1 mm; both protocols and both fly-back rules.
    ``actuator_viscosity_kg_per_s`` is c_p = 2ζ√(k_p m_a); ``closed_form_nm`` is Eq. 8
    (one contact) or Eq. 12 (six), which do not depend on c_p.
    """
    s = PROFILE_SETTINGS[config.profile]
    radius, preload = FIG5A_DRIVE
    points = [
        {
            "contacts": n,
            "actuator_model": "flexible",
            "hemisphere_radius": radius,
            "preload": preload,
            "protocol": protocol,
            "frequency": PROTOCOL.drive_frequency,
            "flyback": flyback,
            "tolerance": s.tolerance,
            "damping_ratio": float(z),
        }
        for n in (1, 6)
        for z in s.damping_ratios
        for protocol in PROTOCOLS
        for flyback in ("slew", "fixed")
    ]
    table = run_searches(points, "fig56_viscosity", config)
    table["actuator_viscosity_kg_per_s"] = [
        actuator_for_radius(radius, damping_ratio=z).viscosity for z in table["damping_ratio"]
    ]
    table["closed_form_nm"] = [_closed_form_at(n, "flexible", radius, preload) for n in table["contacts"]]
    return table


def fig56_frequency(config: RunConfig) -> pd.DataFrame:
    """Beyond the paper: A_c (both protocols) against the drive frequency of the runs.

    One and six contacts, rigid and flexible (slew-rate fly-back), F_p = 0.4 N, R = 1 mm;
    ``closed_form_nm`` is Eq. 7/8 (one contact) or Eq. 11/12 (six).
    """
    s = PROFILE_SETTINGS[config.profile]
    radius, preload = FIG5A_DRIVE
    points = [
        {
            "contacts": n,
            "actuator_model": model,
            "hemisphere_radius": radius,
            "preload": preload,
            "protocol": protocol,
            "frequency": float(f),
            "flyback": "slew",
            "tolerance": s.tolerance,
            "damping_ratio": ACTUATOR_DAMPING_RATIO,
        }
        for n in (1, 6)
        for model in ("rigid", "flexible")
        for protocol in PROTOCOLS
        for f in s.sensitivity_frequencies
    ]
    table = run_searches(points, "fig56_frequency", config)
    table["closed_form_nm"] = [
        _closed_form_at(n, m, radius, preload)
        for n, m in zip(table["contacts"], table["actuator_model"], strict=True)
    ]
    return table


#: The chapter's rows of the figure table.
FIGURES = (
    FigureSpec("fig6a", "Critical amplitude against preload, six contacts, rigid, R = 1 mm",
               "critical_amplitude_six", fig6a, "critical_amplitude:plot_fig6"),
    FigureSpec("fig6b", "Critical amplitude against preload, six contacts, flexible, R = 1 mm",
               "critical_amplitude_six", fig6b, "critical_amplitude:plot_fig6"),
    FigureSpec("fig6c", "Critical amplitude against preload, six contacts, flexible, R = 0.25 mm",
               "critical_amplitude_six", fig6c, "critical_amplitude:plot_fig6"),
    FigureSpec("fig56_frequency", "Critical amplitude against drive frequency, 0.4 N, R = 1 mm",
               "critical_amplitude_six", fig56_frequency, "critical_amplitude:plot_frequency"),
    FigureSpec("fig56_viscosity", "Critical amplitude against actuator viscosity c_p, 0.4 N, R = 1 mm",
               "critical_amplitude_six", fig56_viscosity, "critical_amplitude:plot_viscosity"),
)

def _preload_grid(radius: float):
    return lambda profile: {"preloads": PROFILE_SETTINGS[profile].preloads[radius],
                            "drive frequencies": PROFILE_SETTINGS[profile].frequencies}


#: The chapter's profile-dependent grids (:data:`passmd.experiments.figure_table.GRIDS`).
GRIDS = {
    "fig6a": _preload_grid(1.0e-3), "fig6b": _preload_grid(1.0e-3), "fig6c": _preload_grid(0.25e-3),
    "fig56_frequency": lambda profile: {
        "drive frequencies": PROFILE_SETTINGS[profile].sensitivity_frequencies},
    "fig56_viscosity": lambda profile: {"damping ratios": PROFILE_SETTINGS[profile].damping_ratios},
}

#: The ledger's readings of the chapter's figures.
READING_TABLES = tuple(
    ReadingTable(f"{panel}_readings", f"Fig. {panel[3:]}'s A_c searches at every reading", (panel,),
                 functools.partial(ac_readings, panel=panel))
    for panel in ("fig6a", "fig6b", "fig6c"))
