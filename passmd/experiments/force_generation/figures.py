"""Force generation against the load cell: Fig. 7 (Section 4.2).

The measurement itself — runs from rest against the load cell until the steps stall, the
stall criterion and the onset of force generation, with their assumptions — is the protocol of
:mod:`passmd.protocols.stall`. This module runs it over the grids of the figures (through
the sweep engine, cached). By momentum balance over a periodic (stalled) cycle F_gen equals the
mean total friction force on the runner; the tests check that.

Figures: ``fig7a`` (R = 1 mm, 0.3 and 0.8 N), ``fig7b`` (R = 0.25 mm, 0.2 and 0.4 N), each
with the earlier model (rigid actuators, μ = 0.3, [12]) and this paper's (flexible, μ = 0.2);
``fig7_difference`` (their difference); ``fig7grid`` (every preload of both radii); ``fig7freq`` (F_gen
against the drive frequency) and ``fig7cycle`` (one period at stall, rigid/flexible × μ = 0.2/0.3, the
physics of the difference). Each compute function takes the run configuration and returns a tidy
DataFrame in display units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from passmd.experiments import FigureSpec, ReadingTable
from passmd.ledger import readings
from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import MOLYBDENUM, STEEL, Drive, paper_drive
from passmd.model.tables import ACTUATOR_DAMPING_RATIO, PRELOAD_GRIDS, Assumption, actuator_for_radius
from passmd.model.theory import drive_theory
from passmd.protocols import stall
from passmd.protocols.critical_amplitude import critical_amplitude
from passmd.protocols.stall import force_onset, generated_force
from passmd.protocols.stall_period import stall_cycle
from passmd.runtime import sweep
from passmd.runtime.config import PROFILES, RunConfig
from passmd.runtime.validation import check_choice, check_range

__all__ = [
    "CYCLE_COMBINATIONS", "DEPENDENCE_PAIRS", "EARLIER", "FIGURES", "FORCE_FREQUENCY", "GRIDS", "MODELS",
    "ONSET_TOLERANCE", "PANELS", "PANELS_FULL_STROKE_NM", "PROFILE_SETTINGS", "READING_TABLES",
    "RUNNER_MATERIALS", "THIS", "cycle_point", "fig7_dependence_readings", "fig7_difference", "fig7_readings",
    "fig7a", "fig7b", "fig7cycle", "fig7freq", "fig7grid",
    "force_difference", "force_drive", "model_rows", "onset_point", "stall_point",
]

#: Saw-tooth frequency of every force run (Hz): Section 5.2's 100 Hz (Fig. 9a), as in the
#: critical-amplitude chapters (assumption ``force_frequency``).
FORCE_FREQUENCY = PROTOCOL.drive_frequency
#: Width of the final bracket of the onset (critical-amplitude) search per profile (m).
ONSET_TOLERANCE = {"quick": 0.5e-9, "paper": stall.ONSET_TOLERANCE}

#: (actuator model, μ, label): the earlier model of [12] and this paper's.
MODELS = (
    ("rigid", 0.3, "rigid actuators, μ = 0.3 (earlier work [12])"),
    ("flexible", 0.2, "flexible actuators, μ = 0.2 (this paper)"),
)
#: The earlier model of [12] (rigid actuators, μ = 0.3) and this paper's (flexible, μ = 0.2).
EARLIER, THIS = MODELS[0][:2], MODELS[1][:2]
#: Fig. 7 panels: hemisphere radius (m) and the preloads shown (N).
PANELS = {"fig7a": (1.0e-3, (0.3, 0.8)), "fig7b": (0.25e-3, (0.2, 0.4))}
#: Full stroke A_max of each panel's radius (nm), the amplitude of the 115 mN claim for fig7a.
PANELS_FULL_STROKE_NM = {name: paper_drive(r).actuator.full_stroke_amplitude * 1e9
                         for name, (r, _) in PANELS.items()}


@dataclass(frozen=True)
class ProfileSettings:
    """What a profile computes."""

    panel_fractions: tuple  # amplitudes of the Fig. 7 panels, as fractions of A_max
    grid_fractions: tuple  # amplitudes of the full preload grid (fractions of A_max)
    grid_preloads: dict  # radius -> preloads of the full grid
    frequencies: tuple  # drive frequencies of the sensitivity panel (Hz)
    cycle_samples: int  # recorded samples per period of the stall-cycle runs
    cycle_preload: float  # preload of the stall-cycle runs (N), R = 1 mm, full stroke


PROFILE_SETTINGS = {
    "quick": ProfileSettings(panel_fractions=(0.0, 0.2, 0.7, 1.0), grid_fractions=(1.0,),
                             grid_preloads={1.0e-3: (0.1, 0.3, 0.8), 0.25e-3: (0.2, 0.4)},
                             frequencies=(FORCE_FREQUENCY, 1000.0), cycle_samples=1000, cycle_preload=0.8),
    "paper": ProfileSettings(
        panel_fractions=tuple(i / 10 for i in range(11)),
        grid_fractions=(0.5, 1.0),
        grid_preloads={r: tuple(float(p) for p in grid) for r, grid in PRELOAD_GRIDS.items()},
        frequencies=(90.0, FORCE_FREQUENCY, 110.0, 200.0, 500.0, 900.0, 1000.0, 1100.0),
        cycle_samples=2000,
        cycle_preload=0.8,
    ),
}

ASSUMPTIONS: tuple[Assumption, ...] = (
    Assumption(
        key="force_frequency",
        symbol="f",
        value=f"{FORCE_FREQUENCY:g}",
        unit="Hz",
        rationale=(
            "Section 4.2 does not state the saw-tooth frequency of the force runs. 100 Hz is the "
            "frequency Section 5.2 uses (Fig. 9a) and the critical-amplitude chapters use, so the onset "
            "of force generation is their critical amplitude. After each fly-back the runner rings on "
            "its contacts (about 10 kHz) with only micro-slip to damp it; at 100 Hz the ringing has "
            "mostly died out before the next fly-back, at 1 kHz it has not and the stall force scatters "
            "several times more from one frequency to the next."
        ),
        sensitivity="Force chapter: F_gen at full amplitude from 90 Hz to 1.1 kHz (fig7freq).",
    ),
)


#: Runner materials a force run can have: Table 1's steel and Fig. 10c's molybdenum.
RUNNER_MATERIALS = {"steel": STEEL, "molybdenum": MOLYBDENUM}


def force_drive(
    hemisphere_radius: float, preload: float, actuator_model: str, friction_coefficient: float,
    damping_ratio: float = ACTUATOR_DAMPING_RATIO, runner: str = "steel",
) -> Drive:
    """The Fig. 7 drive: Tables 1–2, six contacts, load cell engaged (Section 4.2); actuator damping ζ
    (Table 2's lost c_p, ledger axis ``damping_ratio``) and the runner's material
    (:data:`RUNNER_MATERIALS`)."""
    check_choice("runner", runner, tuple(RUNNER_MATERIALS))
    return paper_drive(hemisphere_radius, preload, actuator_model=actuator_model,
                       friction_coefficient=friction_coefficient, load_cell=True,
                       runner_material=RUNNER_MATERIALS[runner],
                       actuator=actuator_for_radius(hemisphere_radius, damping_ratio=damping_ratio))


def stall_point(
    hemisphere_radius: float,
    preload: float,
    actuator_model: str,
    friction_coefficient: float,
    amplitude_fraction: float,
    frequency: float,
    flyback: str = "slew",
    damping_ratio: float = ACTUATOR_DAMPING_RATIO,
    runner: str = "steel",
) -> dict:
    """:func:`~passmd.protocols.stall.generated_force` of the Fig. 7 drive at ``amplitude_fraction`` × A_max,
    with the ``flyback`` rule, actuator damping ζ and the runner's material."""
    drive = force_drive(hemisphere_radius, preload, actuator_model, friction_coefficient, damping_ratio,
                        runner)
    fraction = check_range("amplitude_fraction", amplitude_fraction, 0.0, 1.0)
    amplitude = fraction * drive.actuator.full_stroke_amplitude
    out = generated_force(drive, amplitude, frequency, flyback=flyback)
    out["amplitude_m"] = amplitude
    return out


def onset_point(
    hemisphere_radius: float,
    preload: float,
    actuator_model: str,
    friction_coefficient: float,
    frequency: float,
    tolerance: float,
    flyback: str = "slew",
) -> dict:
    """:func:`~passmd.protocols.stall.force_onset`
    of the Fig. 7 drive (the critical amplitude with the load cell engaged, with the ``flyback``
    rule), plus the closed form (Eq. 11 or 12) in m."""
    drive = force_drive(hemisphere_radius, preload, actuator_model, friction_coefficient)
    out = (force_onset(drive, frequency, tolerance) if flyback == "slew" else
           critical_amplitude(drive, frequency=frequency, tolerance=tolerance, flyback=flyback))
    if out["critical_amplitude_m"] is None:
        out["critical_amplitude_m"] = math.nan
    out["analytic_critical_amplitude_m"] = float(drive_theory(drive)["analytic_critical_amplitude_m"])
    return out


def cycle_point(
    hemisphere_radius: float,
    preload: float,
    actuator_model: str,
    friction_coefficient: float,
    amplitude_fraction: float,
    frequency: float,
    periods: int,
    samples_per_period: int,
) -> dict:
    """:func:`~passmd.protocols.stall_period.stall_cycle` of the Fig. 7 drive at ``amplitude_fraction``
    × A_max."""
    drive = force_drive(hemisphere_radius, preload, actuator_model, friction_coefficient)
    fraction = check_range("amplitude_fraction", amplitude_fraction, 0.0, 1.0)
    return stall_cycle(drive, fraction * drive.actuator.full_stroke_amplitude, frequency, int(periods),
                       int(samples_per_period))


def _settings(profile: str) -> ProfileSettings:
    return PROFILE_SETTINGS[check_choice("profile", profile, PROFILES)]


def _stall_frame(points: list[dict], description: str, config: RunConfig) -> pd.DataFrame:
    """Stall runs through the sweep engine; tidy frame in display units (nm, mN)."""
    f = sweep.run(stall_point, points, description=description, config=config)
    labels = {(m, mu): label for m, mu, label in MODELS}
    return pd.DataFrame({
        "radius_mm": f["hemisphere_radius"] * 1e3,
        "preload_N": f["preload"],
        "actuator_model": f["actuator_model"],
        "friction_coefficient": f["friction_coefficient"],
        "model": [labels.get((m, mu), f"{m} actuators, μ = {mu:g}")
                  for m, mu in zip(f["actuator_model"], f["friction_coefficient"], strict=True)],
        "frequency_Hz": f["frequency"],
        "amplitude_fraction": f["amplitude_fraction"],
        "amplitude_nm": f["amplitude_m"] * 1e9,
        "generated_force_mN": f["generated_force_N"] * 1e3,
        "converged": f["converged"].astype(bool),
        "periods": f["periods"].astype(int),
        "periods_simulated": f["periods_simulated"].astype(int),
        "remaining_force_mN": f["remaining_force_N"].astype(float) * 1e3,  # None: not estimated
        "force_spread_mN": f["force_spread_N"] * 1e3,
        "mean_friction_mN": f["mean_friction_N"] * 1e3,
        "piezo_mean_force_mN": f["no_slip_reference_force_N"] * 1e3,
        "net_displacement_nm": f["net_displacement_m"] * 1e9,
        "last_step_nm": f["last_step_m"] * 1e9,
        "cpu_time_s": f["cpu_time_s"],
    })


def _onset_frame(curves: list[tuple], config: RunConfig) -> pd.DataFrame:
    points = [{"hemisphere_radius": r, "preload": float(p), "actuator_model": m, "friction_coefficient": mu,
               "frequency": FORCE_FREQUENCY, "tolerance": ONSET_TOLERANCE[config.profile], **_flyback(fb)}
              for r, p, m, mu, fb in curves]
    f = sweep.run(onset_point, points, description="fig7 onsets", config=config)
    return pd.DataFrame({
        "radius_mm": f["hemisphere_radius"] * 1e3,
        "preload_N": f["preload"],
        "actuator_model": f["actuator_model"],
        "friction_coefficient": f["friction_coefficient"],
        "onset_nm": f["critical_amplitude_m"] * 1e9,
        "onset_low_nm": f["bracket_low_m"] * 1e9,
        "onset_high_nm": f["bracket_high_m"] * 1e9,
        "analytic_onset_nm": f["analytic_critical_amplitude_m"] * 1e9,
        "onset_cpu_time_s": f["wall_time_s"],
    })


def _flyback(rule: str) -> dict:
    """The fly-back parameter of a sweep point: none for the slew-rate default, so those points
    are the same (and cached once) in every table."""
    return {} if rule == "slew" else {"flyback": rule}


def _curves_frame(radius_preloads: dict, fractions, config: RunConfig, panel: str,
                  models=MODELS, flyback: str = "slew") -> pd.DataFrame:
    """F_gen against amplitude for every (radius, preload, model), with each curve's onset; the
    flexible actuators' saw-tooth has the ``flyback`` rule (rigid actuators follow any fly-back:
    their runs use the slew-rate one)."""
    curves = [(r, float(p), m, mu, flyback if m == "flexible" else "slew")
              for r, preloads in radius_preloads.items() for p in preloads for m, mu, *_ in models]
    points = [{"hemisphere_radius": r, "preload": p, "actuator_model": m, "friction_coefficient": mu,
               "amplitude_fraction": float(a), "frequency": FORCE_FREQUENCY, **_flyback(fb)}
              for r, p, m, mu, fb in curves for a in fractions]
    stalls = _stall_frame(points, panel, config)
    onsets = _onset_frame(curves, config)
    keys = ["radius_mm", "preload_N", "actuator_model", "friction_coefficient"]
    frame = stalls.merge(onsets, on=keys, how="left", validate="many_to_one")
    frame.insert(0, "panel", panel)
    return frame


def _panel(name: str, config: RunConfig) -> pd.DataFrame:
    radius, preloads = PANELS[name]
    return _curves_frame({radius: preloads}, _settings(config.profile).panel_fractions, config, name)


def fig7a(config: RunConfig) -> pd.DataFrame:
    """Fig. 7a: F_gen against A (0–202 nm), R = 1 mm, F_p = 0.3 and 0.8 N, both models (mN, nm)."""
    return _panel("fig7a", config)


def fig7b(config: RunConfig) -> pd.DataFrame:
    """Fig. 7b: F_gen against A (0–96 nm), R = 0.25 mm, F_p = 0.2 and 0.4 N, both models (mN, nm)."""
    return _panel("fig7b", config)


#: Amplitudes of the ledger's readings of this paper's force runs, as fractions of A_max: the force's
#: dependence on the amplitude (half and full stroke) and, at the full stroke, on the preload.
READINGS_FRACTIONS = (0.5, 1.0)


def fig7_readings(config: RunConfig) -> pd.DataFrame:
    """This paper's model (flexible actuators, μ = 0.2) at the Fig. 7 panels' preloads and
    ``READINGS_FRACTIONS`` of the stroke, at every point of the axes that change its runs:
    fly-back rule × actuator damping ζ × drive frequency (mN, nm; the default runs are the panels'
    own). Columns of :func:`fig7a`'s stall runs plus ``flyback`` and ``damping_ratio``."""
    model, mu = THIS
    runs = [{"hemisphere_radius": radius, "preload": float(p), "actuator_model": model,
             "friction_coefficient": mu, "amplitude_fraction": float(a)}
            for radius, preloads in PANELS.values() for p in preloads for a in READINGS_FRACTIONS]
    return _reading_runs(runs, "fig7 readings", config)


def _reading_runs(runs: list[dict], description: str, config: RunConfig, **labels: list) -> pd.DataFrame:
    """Stall runs ``runs`` (sweep points without drive frequency, fly-back rule and ζ) at every reading of
    the axes that change them, fly-back rule × ζ × drive frequency (the readings outermost): the columns
    of :func:`_stall_frame` after ``flyback``, ``damping_ratio`` and one column per ``labels`` (a value
    per run)."""
    points = []
    for reading in readings.design(("flyback", "damping_ratio", "force_frequency")):
        zeta = float(reading["damping_ratio"])
        points.extend({**run, "frequency": float(reading["force_frequency"]), **_flyback(reading["flyback"]),
                       **({} if zeta == ACTUATOR_DAMPING_RATIO else {"damping_ratio": zeta})} for run in runs)
    table = _stall_frame(points, description, config)
    table.insert(0, "flyback", [p.get("flyback", "slew") for p in points])
    table.insert(1, "damping_ratio", [p.get("damping_ratio", ACTUATOR_DAMPING_RATIO) for p in points])
    for i, (name, values) in enumerate(labels.items(), start=2):
        table.insert(i, name, values * (len(points) // len(runs)))  # the same runs at every reading
    return table


#: The runs of :func:`fig7_dependence_readings`: what changes against what, each a pair of stall runs of
#: this paper's model (flexible actuators, μ = 0.2 unless changed) at the same point of the readings:
#: name -> (base run, changed run), each ``(R in m, F_p in N, amplitude as a fraction of that R's
#: A_max, μ, runner)``. The radius pair keeps F_p and the amplitude (R = 0.25 mm's full stroke, 96 nm,
#: inside R = 1 mm's range), each radius with its Table 2 actuator; μ and the material change Fig. 7a's
#: 0.8 N run at the full stroke (μ to Table 1's other value, the runner to Fig. 10c's molybdenum).
DEPENDENCE_PAIRS = {
    "radius": ((1.0e-3, 0.4, PANELS_FULL_STROKE_NM["fig7b"] / PANELS_FULL_STROKE_NM["fig7a"], 0.2, "steel"),
               (0.25e-3, 0.4, 1.0, 0.2, "steel")),
    "friction coefficient": ((1.0e-3, 0.8, 1.0, 0.2, "steel"), (1.0e-3, 0.8, 1.0, 0.3, "steel")),
    "material": ((1.0e-3, 0.8, 1.0, 0.2, "steel"), (1.0e-3, 0.8, 1.0, 0.2, "molybdenum")),
}


def fig7_dependence_readings(config: RunConfig) -> pd.DataFrame:
    """This paper's model's generated force for each pair of :data:`DEPENDENCE_PAIRS` (one input changed),
    at every point of the axes that change the force runs: fly-back rule × actuator damping ζ × drive
    frequency. Columns of :func:`fig7a`'s stall runs plus ``flyback``, ``damping_ratio``, ``runner``,
    ``pair`` and ``side`` (``base`` or ``changed``)."""
    runs = [{"hemisphere_radius": radius, "preload": preload, "actuator_model": THIS[0],
             "friction_coefficient": mu, "amplitude_fraction": float(fraction),
             **({} if runner == "steel" else {"runner": runner})}
            for both in DEPENDENCE_PAIRS.values() for radius, preload, fraction, mu, runner in both]
    return _reading_runs(runs, "fig7 dependence readings", config,
                         runner=[run.get("runner", "steel") for run in runs],
                         pair=[pair for pair in DEPENDENCE_PAIRS for _ in ("base", "changed")],
                         side=["base", "changed"] * len(DEPENDENCE_PAIRS))


def fig7grid(config: RunConfig) -> pd.DataFrame:
    """F_gen against A for the full preload grids of both radii, both models, with onsets."""
    s = _settings(config.profile)
    return _curves_frame(s.grid_preloads, s.grid_fractions, config, "grid")


def fig7freq(config: RunConfig) -> pd.DataFrame:
    """F_gen at A_max against the saw-tooth frequency, each panel's higher preload, both models."""
    s = _settings(config.profile)
    points = [
        {"hemisphere_radius": radius, "preload": float(max(preloads)), "actuator_model": m,
         "friction_coefficient": mu, "amplitude_fraction": 1.0, "frequency": float(f)}
        for radius, preloads in PANELS.values() for m, mu, _ in MODELS for f in s.frequencies
    ]
    return _stall_frame(points, "fig7freq", config)


#: Actuator model × μ of the stall-cycle figure: the two models and the two crossings.
CYCLE_COMBINATIONS = (("rigid", 0.3), ("rigid", 0.2), ("flexible", 0.3), ("flexible", 0.2))
#: Radius (m) and amplitude fraction of the stall-cycle figure: Fig. 7a's drive at the full stroke
#: (the paper profile's preload, 0.8 N, is the one of the 115 mN claim).
CYCLE_DRIVE = (1.0e-3, 1.0)
#: What the stall-cycle figure shows of a stall cycle (:func:`~passmd.protocols.stall_period.stall_cycle`),
#: in its columns' order: the time series, then the run's measures (repeated on every row of the run).
_CYCLE_ENTRIES = (
    "time_s", "piezo_m", "runner_m", "load_cell_N", "friction_N", "friction_side1_N", "deflection_side1_m",
    "slip_share_side1", "friction_side2_N", "deflection_side2_m", "slip_share_side2",
    "generated_force_N", "sliding_capacity_N", "back_slide_m", "full_slip_time_s", "sample_spacing_s",
    "deflection_before_flyback_side1_m", "deflection_before_flyback_side2_m", "mean_slip_share_side1",
    "mean_slip_share_side2",
)
#: The figure's units of an SI entry, by the suffix naming its unit: (suffix shown, factor).
_SHOWN_UNITS = {"_N": ("_mN", 1e3), "_m": ("_nm", 1e9), "_s": ("_us", 1e6)}


def fig7cycle(config: RunConfig) -> pd.DataFrame:
    """One stall period of the four actuator-model × μ combinations (tidy, one row per sample).

    Per-run measures (``generated_force_mN``, ``back_slide_nm``, ...) repeat on every row of
    their run.
    """
    s = _settings(config.profile)
    radius, fraction = CYCLE_DRIVE
    preload = s.cycle_preload
    base = {"hemisphere_radius": radius, "preload": preload, "amplitude_fraction": fraction,
            "frequency": FORCE_FREQUENCY}
    combos = [{**base, "actuator_model": m, "friction_coefficient": mu} for m, mu in CYCLE_COMBINATIONS]
    stalls = sweep.run(stall_point, combos, description="fig7cycle stall", config=config)
    if not stalls["converged"].all():
        bad = stalls.loc[~stalls["converged"], ["actuator_model", "friction_coefficient"]]
        raise RuntimeError(f"stall-cycle runs did not stall: {bad.to_dict('records')}")
    points = [{**c, "periods": int(p), "samples_per_period": s.cycle_samples}
              for c, p in zip(combos, stalls["periods"], strict=True)]
    cycles = sweep.run(cycle_point, points, description="fig7cycle", config=config)
    frames = []
    for (_, row), stalled in zip(cycles.iterrows(), stalls.itertuples(), strict=True):
        n = len(row["time_s"])
        frame = {"actuator_model": [row["actuator_model"]] * n,
                 "friction_coefficient": row["friction_coefficient"]}
        for key in _CYCLE_ENTRIES:
            si = next((suffix for suffix in _SHOWN_UNITS if key.endswith(suffix)), "")
            shown, factor = _SHOWN_UNITS.get(si, ("", 1.0))
            frame[key.removesuffix(si) + shown] = row[key] * factor
        frame["periods"] = int(stalled.periods)
        frames.append(pd.DataFrame(frame))
    out = pd.concat(frames, ignore_index=True)
    out.insert(0, "amplitude_nm", float(stalls["amplitude_m"].iloc[0]) * 1e9)
    out.insert(0, "preload_N", preload)
    out.insert(0, "radius_mm", radius * 1e3)
    return out


def model_rows(table: pd.DataFrame, model: tuple, preload: float) -> pd.DataFrame:
    """The rows of one (actuator model, μ) at one preload, indexed by amplitude fraction."""
    rows = table[(table["actuator_model"] == model[0]) & np.isclose(table["friction_coefficient"], model[1])
                 & np.isclose(table["preload_N"], preload)]
    return rows.set_index("amplitude_fraction").sort_index()


def force_difference(table: pd.DataFrame, preload: float) -> pd.DataFrame:
    """F_gen(rigid, μ = 0.3) − F_gen(flexible, μ = 0.2) against amplitude at one preload (mN).

    Only amplitudes where both runs stalled; columns ``amplitude_nm``, ``difference_mN``.
    """
    earlier, this = model_rows(table, EARLIER, preload), model_rows(table, THIS, preload)
    common = earlier.index.intersection(this.index)
    ok = earlier.loc[common, "converged"].to_numpy() & this.loc[common, "converged"].to_numpy()
    common = common[ok]
    return pd.DataFrame({
        "amplitude_nm": this.loc[common, "amplitude_nm"].to_numpy(),
        "difference_mN": (earlier.loc[common, "generated_force_mN"]
                      - this.loc[common, "generated_force_mN"]).to_numpy(),
    })


def fig7_difference(config: RunConfig) -> pd.DataFrame:
    """F_gen(rigid, μ = 0.3) − F_gen(flexible, μ = 0.2) against A at every preload of Fig. 7.

    One row per amplitude at which both models stalled (fig7a's and fig7b's panel differences), with
    the panel, its radius and the preload, and the lower and higher of the two models' onsets of force
    generation at that preload (mN, nm).
    """
    data = {"fig7a": fig7a(config), "fig7b": fig7b(config)}
    rows = []
    for name, (_, preloads) in PANELS.items():
        frame = data[name]
        for preload in preloads:
            part = frame[np.isclose(frame["preload_N"], preload)]
            onsets = part.drop_duplicates(["actuator_model", "friction_coefficient"])["onset_nm"]
            rows.append(force_difference(frame, preload).assign(
                panel=name, radius_mm=float(frame["radius_mm"].iloc[0]), preload_N=float(preload),
                onset_low_nm=float(onsets.min()), onset_high_nm=float(onsets.max())))
    columns = ["panel", "radius_mm", "preload_N", "amplitude_nm", "difference_mN", "onset_low_nm",
               "onset_high_nm"]
    return pd.concat(rows, ignore_index=True)[columns]


#: The chapter's rows of the figure table.
FIGURES = (
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
)

def _panel_grid(profile: str) -> dict:
    return {"amplitudes (fractions of A_max)": PROFILE_SETTINGS[profile].panel_fractions}


#: The chapter's profile-dependent grids (:data:`passmd.experiments.figure_table.GRIDS`).
GRIDS = {
    "fig7a": _panel_grid, "fig7b": _panel_grid,
    "fig7grid": lambda profile: {"(radius, preload, amplitude)": tuple(
        (r, p, a) for r, preloads in PROFILE_SETTINGS[profile].grid_preloads.items() for p in preloads
        for a in PROFILE_SETTINGS[profile].grid_fractions)},
    "fig7freq": lambda profile: {"drive frequencies": PROFILE_SETTINGS[profile].frequencies},
}

#: The ledger's readings of the chapter's figures.
READING_TABLES = (
    ReadingTable("fig7_readings", "This paper's force runs at half and full stroke at every reading",
                 ("fig7a", "fig7b"), fig7_readings),
    ReadingTable("fig7_dependence_readings", "This paper's force with R, μ or the runner changed, at every "
                 "reading", ("fig7a", "fig7b"), fig7_dependence_readings),
)
