"""Velocity against driving frequency, Section 5.2: the saw-tooth and Eq. 15's waveform (Figs. 9b, 10).

The Section 5 drive of :mod:`passmd.experiments.driving_waveform.figures` (its μ, designs and runs), driven
over the paper's frequency grid with the saw-tooth and with its Eq. 15 design under either
short-period rule, and Fig. 10's drives with other preloads, radii and runner materials, each with
its own design. The velocities are measured by the protocol of :mod:`passmd.protocols.velocity`
(the *steady* velocity at kHz frequencies); ``SimulationResult.mean_velocity`` (settled positions of
the first and last period) includes the start-up and is kept as ``simulator_mean_velocity_m_per_s``
for comparison, and :func:`startup_transient` shows why.

Figures (rows of the figure table): ``study_startup`` the velocity period by period from rest;
``fig9b`` steady velocity against frequency, every waveform variant; ``fig10a``–``fig10c`` the same
for three preloads, two radii, two runner materials.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd.experiments import FigureSpec, ReadingTable
from passmd.experiments.driving_waveform.figures import (
    SECTION5_FRICTION,
    at_every_mu,
    section5_fields,
)
from passmd.ledger.checks import NotEvaluable
from passmd.model.optimized_waveform import highest_fitting_frequency
from passmd.model.parameters import Assumption
from passmd.protocols.section5 import (
    RUNNERS,
    VARIANTS,
    design_fields,
    designs,
    make_design,
    section5_drive,
    variant_name,
    velocity_table,
)
from passmd.protocols.velocity import MIN_PERIODS, STEADY_TIME, make_waveform, steady_periods
from passmd.runtime import sweep
from passmd.runtime.config import PROFILES, RunConfig
from passmd.runtime.validation import check_choice
from passmd.solver import simulation

#: Fig. 9b/10 frequency grids (Hz): the paper's "1 to 130 kHz with a step of 5 kHz".
FREQUENCIES = {
    "paper": np.array([1e3] + [5e3 * k for k in range(1, 27)]),
    "quick": np.array([1e3, 20e3, 60e3, 100e3, 110e3, 120e3, 130e3]),
}


#: Preloads of Fig. 10a (N) and radii of Fig. 10b (m).
FIG10A_PRELOADS = (0.1, 0.4, 1.0)

FIG10B_RADII = (1e-3, 0.25e-3)

ASSUMPTIONS: tuple[Assumption, ...] = (
    Assumption(
        key="frequency_grid",
        symbol="f",
        value=", ".join([*(f"{f / 1e3:g}" for f in FREQUENCIES["paper"][:3]), "…",
                         f"{FREQUENCIES['paper'][-1] / 1e3:g}"]),
        unit="kHz",
        rationale=(
            "'from 1 to 130 kHz with a step of 5 kHz' (Section 5.2) does not say whether the grid is "
            "1, 6, 11, … or 1, 5, 10, …; the second contains the 80 and 110 kHz the text names."
        ),
        sensitivity="Only where a threshold falls between grid points (±5 kHz).",
    ),
    Assumption(
        key="steady_velocity",
        symbol="v̄",
        value=(
            f"slope of the period-mean runner position over the second half of a run of "
            f"max({MIN_PERIODS}, f·{STEADY_TIME * 1e3:g} ms) periods from rest"
        ),
        unit="mm/s",
        rationale=(
            "The paper calls the velocity 'a multiple of the driving frequency and step size' without "
            "saying over which periods. At 100 kHz there is no stick phase and the runner needs ~1 ms "
            "from rest to its steady velocity; the steady velocity is what a user of the drive sees."
        ),
        sensitivity="Velocity chapter: third against fourth quarter of each run (velocity_drift).",
    ),
    Assumption(
        key="controllable_frequency",
        symbol="f_max",
        value="the frequency of the largest steady velocity on the grid",
        unit="kHz",
        rationale=(
            "Section 5.2 reads the 'reachable maximal velocity' 'at maximal controllable frequencies' "
            "(0.4 N: 19 mm/s at 110 kHz), beyond which the velocity drops; the model has no chaos "
            "criterion of its own."
        ),
        sensitivity="Fig. 10b's ordering of maximal controllable frequencies only.",
    ),
    Assumption(
        key="stick_during_acceleration",
        symbol="–",
        value="no contact group reaches full sliding (slip share 1) during t_a, second half of the run",
        unit="–",
        rationale=(
            "Section 5.1's stick condition u ≤ u_x,max: the contacts must not slide fully while the "
            "hemispheres accelerate the runner. Partial slip of the contact's rim is not a relative "
            "slip of runner and hemisphere."
        ),
        sensitivity="Fig. 10a's 0.1 N stick threshold.",
    ),
)


def _frequencies(profile: str) -> np.ndarray:
    check_choice("profile", profile, PROFILES)
    return FREQUENCIES[profile]


def eq15_fit_limit(design, drive) -> float:
    """Highest frequency (Hz) at which one whole Eq. 15 period of ``design`` (a
    :func:`~passmd.protocols.section5.designs` row) fits ``drive`` at its full stroke: the criterion and
    function ``passmd run --waveform optimized`` prints
    (:func:`passmd.model.optimized_waveform.highest_fitting_frequency`), not a grid point."""
    made = make_design(float(design["settling_time_s"]), float(design["acceleration_time_s"]),
                       float(design["acceleration_amplitude_m"]))
    return highest_fitting_frequency(made, drive.actuator.full_stroke_amplitude, drive)


def _velocities(drives: list[dict], config: RunConfig) -> pd.DataFrame:
    """:func:`~passmd.protocols.section5.velocity_table` over the profile's frequencies, with each row's
    ``eq15_highest_frequency_Hz`` (:func:`eq15_fit_limit` of its drive's design)."""
    table = velocity_table(drives, _frequencies(config.profile), config)
    limits = {}
    for c, (_, d) in zip(drives, designs(drives, config).iterrows(), strict=True):
        limits[tuple(c.values())] = eq15_fit_limit(d, section5_drive(**c))
    table["eq15_highest_frequency_Hz"] = [limits[tuple(row[k] for k in drives[0])]
                                          for _, row in table.iterrows()]
    return table


def fig9b(config: RunConfig, friction_coefficient: float = SECTION5_FRICTION) -> pd.DataFrame:
    """Steady velocity of the Section 5 drive over the frequency grid, every waveform variant (μ:
    Section 5's unstated friction coefficient)."""
    return _velocities([section5_fields(friction_coefficient=friction_coefficient)], config)


def fig10a(config: RunConfig, friction_coefficient: float = SECTION5_FRICTION) -> pd.DataFrame:
    """Steady velocity against frequency for F_p = 0.1, 0.4, 1 N (R = 1 mm, steel)."""
    return _velocities([section5_fields(preload=p, friction_coefficient=friction_coefficient)
                        for p in FIG10A_PRELOADS], config)


def fig10b(config: RunConfig, friction_coefficient: float = SECTION5_FRICTION) -> pd.DataFrame:
    """Steady velocity against frequency for R = 1 mm (A = 202 nm) and 0.25 mm (A = 96 nm), 0.4 N."""
    return _velocities([section5_fields(hemisphere_radius=r, friction_coefficient=friction_coefficient)
                        for r in FIG10B_RADII], config)


def fig10c(config: RunConfig, friction_coefficient: float = SECTION5_FRICTION) -> pd.DataFrame:
    """Steady velocity against frequency for a steel (210 GPa) and a molybdenum (310 GPa) runner."""
    return _velocities([section5_fields(runner=r, friction_coefficient=friction_coefficient)
                        for r in RUNNERS], config)


fig9b_readings, fig10a_readings, fig10b_readings, fig10c_readings = (
    at_every_mu(f) for f in (fig9b, fig10a, fig10b, fig10c))


# ======================================================================================
# The start-up: why velocities at kHz frequencies are read at steady state
# ======================================================================================


def startup_point(hemisphere_radius: float, preload: float, runner: str, actuator_model: str,
                  frequency: float, waveform: str, short_period: str, settling_time: float,
                  acceleration_time: float, acceleration_amplitude: float,
                  friction_coefficient: float) -> dict:
    """Period-mean runner positions of a steady-velocity run from rest (the start-up transient)."""
    drive = section5_drive(hemisphere_radius, preload, runner, actuator_model, friction_coefficient)
    design = None if waveform == "sawtooth" else make_design(
        settling_time, acceleration_time, acceleration_amplitude)
    wave = make_waveform(drive, drive.actuator.full_stroke_amplitude, frequency, steady_periods(frequency),
                         waveform, short_period, design)
    result = simulation.simulate(drive, wave, max_points=2)
    return {"period_mean_position_m": result.period_mean_position,
            "settled_positions_m": result.settled_positions}


def startup_transient(config: RunConfig, frequency: float = 110e3) -> pd.DataFrame:
    """The runner's velocity period by period from rest at ``frequency`` (Section 5 drive).

    One row per period and waveform variant: ``time_s`` (end of the period), ``velocity_m_per_s``
    (difference of consecutive period-mean positions over T) and ``settled_velocity_m_per_s``
    (the same from the settled positions, which assume a stick phase).
    """
    c = section5_fields()
    fields = design_fields(designs([c], config).iloc[0])
    points = [{**c, "frequency": float(frequency), "waveform": w, "short_period": r, **fields}
              for w, r in VARIANTS]
    runs = sweep.run(startup_point, points, description="start-up", config=config)
    parts = []
    for _, run in runs.iterrows():
        means = np.asarray(run["period_mean_position_m"])
        settled = np.asarray(run["settled_positions_m"])
        k = np.arange(1, means.size)
        parts.append(pd.DataFrame({
            "variant": variant_name(run["waveform"], run["short_period"]),
            "period": k + 1, "time_s": (k + 1) / frequency,
            "velocity_m_per_s": np.diff(means) * frequency,
            "settled_velocity_m_per_s": np.diff(settled) * frequency,
        }))
    table = pd.concat(parts, ignore_index=True)
    table["time_ms"] = table["time_s"] * 1e3
    table["velocity_mm_per_s"] = table["velocity_m_per_s"] * 1e3
    table["settled_velocity_mm_per_s"] = table["settled_velocity_m_per_s"] * 1e3
    return table


# ======================================================================================
# Readings of the velocity tables (the chapter's facts and the ledger's claims)
# ======================================================================================


#: Frequency at which Section 5.2 reads the reachable maximal velocity at 0.4 N (kHz).
PAPER_MAXIMUM_KHZ = 110.0


def range_maximum(part: pd.DataFrame) -> pd.Series:
    """The row of the largest steady velocity over the whole frequency grid (edges included)."""
    if not np.all(np.isfinite(part["velocity_mm_per_s"].to_numpy(dtype=float))):
        raise NotEvaluable("non-finite velocities on the frequency grid")
    return part.loc[part["velocity_mm_per_s"].idxmax()]


#: The chapter's rows of the figure table.
FIGURES = tuple(FigureSpec(name, title, "waveform_velocity", compute, f"driving_waveform:{plot}") for
                name, title, compute, plot in (
    ("study_startup", "Velocity period by period from rest at 110 kHz (steady-velocity protocol)",
     startup_transient, "plot_startup"),
    ("fig9b", "Steady velocity against driving frequency, saw-tooth and optimized", fig9b, "plot_fig9b"),
    ("fig10a", "Velocity of the optimized waveform for preloads 0.1, 0.4, 1 N", fig10a, "plot_fig10a"),
    ("fig10b", "Velocity of the optimized waveform for R = 1 mm and 0.25 mm", fig10b, "plot_fig10b"),
    ("fig10c", "Velocity of the optimized waveform, steel and molybdenum runner", fig10c, "plot_fig10c"),
))

#: The chapter's profile-dependent grids (:data:`passmd.experiments.figure_table.GRIDS`).
GRIDS = {name: (lambda profile: {"frequencies": tuple(_frequencies(profile))})
         for name in ("fig9b", "fig10a", "fig10b", "fig10c")}

#: The ledger's readings of the chapter's figures: each at every μ.
READING_TABLES = (
    ReadingTable("fig9b_readings", "Fig. 9b at every μ", ("fig9b",), fig9b_readings),
    ReadingTable("fig10a_readings", "Fig. 10a at every μ", ("fig10a",), fig10a_readings),
    ReadingTable("fig10b_readings", "Fig. 10b at every μ", ("fig10b",), fig10b_readings),
    ReadingTable("fig10c_readings", "Fig. 10c at every μ", ("fig10c",), fig10c_readings),
)
