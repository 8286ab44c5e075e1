"""The facts the Section 4.1 chapters quote, and their figure of per-fly-back steps.

Small tested functions over the figure data of :mod:`passmd.experiments.critical_amplitude.figures`
(onsets, deviations from the closed forms, spans over the sensitivity panels) and the few
runs the chapters show beyond the preload grids (the step across each fly-back, the
prestrain of the two sides). The chapters glue their results into the prose.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd.experiments.critical_amplitude.figures import (
    FIG5A_DRIVE,
    PROFILE_SETTINGS,
    paper_drive_for,
    primary,
)
from passmd.model.defaults import PROTOCOL
from passmd.model.tables import ACTUATOR_DAMPING_RATIO, actuator_for_radius
from passmd.protocols.critical_amplitude import (
    STEADY_PERIODS,
    STEP_THRESHOLD,
    critical_amplitude,
    steady_step,
)
from passmd.runtime.config import RunConfig

# --------------------------------------------------------------------------------------
# One contact (Figs. 5a, 5b)
# --------------------------------------------------------------------------------------

#: Amplitude of the fly-back time quoted as an example in the protocol section (m).
EXAMPLE_FLYBACK_AMPLITUDE = 40e-9
#: Tolerance of the steady-state search of the per-fly-back figure (m).
FLYBACK_STEPS_TOLERANCE = 0.2e-9


def fig5_flyback_steps(config: RunConfig) -> pd.DataFrame:
    """Step across each fly-back of a run from rest, one contact, rigid actuator, 0.4 N, R = 1 mm.

    Four amplitudes: 2 nm below the steady-state A_c (searched to
    :data:`FLYBACK_STEPS_TOLERANCE`), midway between it and u_x,max (Eq. 7), 0.2 nm below
    u_x,max and 3 nm above it. The same on every profile.

    Returns
    -------
    DataFrame
        One row per amplitude and fly-back: ``amplitude_nm``, ``flyback`` (1, 2, ...),
        ``step_nm``; scalars ``steady_ac_nm``, ``u_x_max_nm``, ``threshold_nm``.
    """
    from passmd.model.theory import drive_theory

    rigid = paper_drive_for(1, "rigid", *FIG5A_DRIVE)
    u_max = drive_theory(rigid)["critical_amplitude_rigid_m"]
    steady_ac = critical_amplitude(rigid, tolerance=FLYBACK_STEPS_TOLERANCE)["critical_amplitude_m"]
    amplitudes = [steady_ac - 2e-9, 0.5 * (steady_ac + u_max), u_max - 0.2e-9, u_max + 3e-9]
    frames = []
    for a in amplitudes:
        steps = np.array(steady_step(rigid, a)["steps_m"]) * 1e9
        frames.append(pd.DataFrame({"amplitude_nm": a * 1e9, "flyback": np.arange(1, steps.size + 1),
                                    "step_nm": steps}))
    table = pd.concat(frames, ignore_index=True)
    table["steady_ac_nm"] = steady_ac * 1e9
    table["u_x_max_nm"] = u_max * 1e9
    table["threshold_nm"] = STEP_THRESHOLD * 1e9
    return table


def protocol_facts(config: RunConfig) -> dict:
    """The protocol's numbers the one-contact chapter quotes (flexible actuator, 0.4 N, R = 1 mm).

    Step threshold (nm), periods, drive frequency (Hz), the profile's bisection tolerance
    (nm), the full stroke A_max (nm), the bare actuator's frequency (MHz) and period (µs), the
    fixed 2 µs fly-back in actuator periods, the slew-rate fly-back time at
    :data:`EXAMPLE_FLYBACK_AMPLITUDE` (µs), ζ, the mass factor (m_r + m_a)/m_r − 1 of Eq. 9 and
    the amplifier's full-stroke time (µs).
    """
    drive = paper_drive_for(1, "flexible", *FIG5A_DRIVE)
    actuator = drive.actuator
    f_mode = np.sqrt(actuator.stiffness / actuator.mass) / (2 * np.pi)
    return {
        "threshold_nm": STEP_THRESHOLD * 1e9,
        "periods": STEADY_PERIODS,
        "f_drive": PROTOCOL.drive_frequency,
        "tol_nm": PROFILE_SETTINGS[config.profile].tolerance * 1e9,
        "a_max_nm": actuator.full_stroke_amplitude * 1e9,
        "f_actuator_MHz": f_mode / 1e6,
        "period_actuator_us": 2 * np.pi * np.sqrt(actuator.mass / actuator.stiffness) * 1e6,
        "fixed_periods": drive.amplifier.full_stroke_time * f_mode,
        "example_amplitude_nm": EXAMPLE_FLYBACK_AMPLITUDE * 1e9,
        "flyback_us_40": EXAMPLE_FLYBACK_AMPLITUDE / actuator.full_stroke_amplitude
        * drive.amplifier.full_stroke_time * 1e6,
        "full_stroke_time_us": drive.amplifier.full_stroke_time * 1e6,
        "zeta": ACTUATOR_DAMPING_RATIO,
        "mass_factor": (drive.runner_mass + actuator.mass) / drive.runner_mass - 1,
    }


def band_text(config: RunConfig) -> dict[str, str]:
    """``band``: the paper profile's frequency band; ``band_here``: whether this build runs it."""
    band = PROFILE_SETTINGS["paper"].frequencies
    here = "as in this build"
    if len(PROFILE_SETTINGS[config.profile].frequencies) < 2:
        here = f"in the paper profile; this {config.profile} build runs {PROTOCOL.drive_frequency:g} Hz only"
    return {"band": f"{band[0]:g}–{band[-1]:g} Hz", "band_here": here}


def step_onset(rows: pd.DataFrame, column: str = "steady_step_nm") -> float:
    """First amplitude (nm) of the grid from which on the step stays above δ; NaN if it never does."""
    rows = rows.sort_values("amplitude_nm")
    above = (rows[column] > rows["threshold_nm"]).to_numpy()
    last_below = np.flatnonzero(~above)
    i = last_below[-1] + 1 if last_below.size else 0
    return float(rows["amplitude_nm"].iloc[i]) if i < len(rows) else float("nan")


def fig5a_facts(fig5a_table: pd.DataFrame) -> dict:
    """Onsets of the three series of Fig. 5a (nm), Eqs. 7 and 8 (nm), the largest first step below
    u_x,max (nm) and the rigid steady step's slope above 5 δ (nm per nm)."""
    series = {key: g for key, g in fig5a_table.groupby(["actuator_model", "flyback"])}
    below = fig5a_table[fig5a_table["amplitude_nm"] < fig5a_table["u_x_max_nm"]]
    rigid = series[("rigid", "slew")]
    rigid = rigid[rigid["steady_step_nm"] > 5 * fig5a_table["threshold_nm"].iloc[0]]
    return {
        "onset_flex_slew": step_onset(series[("flexible", "slew")]),
        "onset_flex_fixed": step_onset(series[("flexible", "fixed")]),
        "onset_rigid": step_onset(series[("rigid", "slew")]),
        "eq7_04": fig5a_table["u_x_max_nm"].iloc[0],
        "eq8_04": fig5a_table["u_x_max_plus_u_x_a_nm"].iloc[0],
        "first_step_below_max": below["first_step_nm"].abs().max(),
        "slope_rigid": np.polyfit(rigid["amplitude_nm"], rigid["steady_step_nm"], 1)[0],
    }


def closed_form_deviations(table: pd.DataFrame, reference: dict[str, str]) -> pd.DataFrame:
    """Relative deviation (%) of each simulated A_c series from its closed form, over the preloads.

    ``reference`` maps an actuator model to the closed-form column it is compared with. One
    row per series (model, protocol, fly-back, frequency, ζ): mean and largest |deviation|.
    """
    rows = []
    for (model, protocol, flyback, f, zeta), g in table.groupby(
        ["actuator_model", "protocol", "flyback", "frequency_Hz", "damping_ratio"], sort=False
    ):
        dev = 100 * (g["critical_amplitude_nm"] / g[reference[model]] - 1)
        rows.append({"actuators": model, "A_c": protocol, "fly-back": flyback, "f (Hz)": f, "ζ": zeta,
                     "closed form": reference[model].removesuffix("_nm"),
                     "mean deviation (%)": dev.mean(), "largest |deviation| (%)": dev.abs().max()})
    return pd.DataFrame(rows)


def series_deviation(deviations: pd.DataFrame, model: str, protocol: str, flyback: str,
                     frequency: float = PROTOCOL.drive_frequency) -> tuple[float, float]:
    """(largest |deviation|, mean deviation) in % of one series of :func:`closed_form_deviations`
    at the default ζ."""
    sel = deviations[(deviations["actuators"] == model) & (deviations["A_c"] == protocol)
                     & (deviations["fly-back"] == flyback) & np.isclose(deviations["f (Hz)"], frequency)
                     & np.isclose(deviations["ζ"], ACTUATOR_DAMPING_RATIO)]
    return float(sel["largest |deviation| (%)"].iloc[0]), float(sel["mean deviation (%)"].iloc[0])


def side_of(mean_deviation: float) -> str:
    """``"x.x % below"`` or ``"x.x % above"`` for a mean deviation in %."""
    return f"{abs(mean_deviation):.1f} % {'below' if mean_deviation < 0 else 'above'}"


def band_spread(table: pd.DataFrame, actuator_model: str) -> float:
    """Largest spread (max − min over the drive frequencies) of the steady-state A_c (slew-rate
    fly-back, default ζ) of one actuator model, in % of its mean; NaN with a single frequency."""
    steady = table[(table["protocol"] == "steady") & (table["flyback"] == "slew")
                   & np.isclose(table["damping_ratio"], ACTUATOR_DAMPING_RATIO)
                   & (table["actuator_model"] == actuator_model)]
    if steady["frequency_Hz"].nunique() < 2:
        return float("nan")
    spread = steady.groupby("preload_N")["critical_amplitude_nm"].agg(["min", "max", "mean"])
    return float(100 * ((spread["max"] - spread["min"]) / spread["mean"]).max())


# --------------------------------------------------------------------------------------
# Six contacts (Figs. 6a-c and the sensitivity panels)
# --------------------------------------------------------------------------------------


def deviation_table(table: pd.DataFrame, columns: dict[str, str]) -> pd.DataFrame:
    """Mean and largest |relative deviation| (%) of each simulated A_c series from each closed form.

    ``columns`` maps a label ("Eq. 11") to a closed-form column of ``table``; one row per
    series (protocol, fly-back, frequency, ζ).
    """
    rows = []
    series = ["protocol", "flyback", "frequency_Hz", "damping_ratio"]
    for (protocol, flyback, f, zeta), g in table.groupby(series, sort=False):
        row = {"A_c": protocol, "fly-back": flyback, "f (Hz)": f, "ζ": zeta}
        for label, column in columns.items():
            dev = 100 * (g["critical_amplitude_nm"] / g[column] - 1)
            row[f"{label}: mean (%)"] = dev.mean()
            row[f"{label}: largest |dev| (%)"] = dev.abs().max()
        rows.append(row)
    return pd.DataFrame(rows)


def deviation_at(deviations: pd.DataFrame, protocol: str, flyback: str, column: str,
                 frequency: float = PROTOCOL.drive_frequency) -> float:
    """One entry of :func:`deviation_table` at the default ζ."""
    sel = deviations[(deviations["A_c"] == protocol) & (deviations["fly-back"] == flyback)
                     & np.isclose(deviations["f (Hz)"], frequency)
                     & np.isclose(deviations["ζ"], ACTUATOR_DAMPING_RATIO)]
    return float(sel[column].iloc[0])


def side_prestrain(frequency_table: pd.DataFrame, fraction: float = 0.97) -> pd.DataFrame:
    """Mean friction force per contact over each settle window, six rigid contacts, 0.4 N, R = 1 mm.

    The run is :data:`~passmd.protocols.critical_amplitude.STEADY_PERIODS` saw-tooth periods
    at ``fraction`` of the steady-state A_c that ``frequency_table`` (``fig56_frequency``)
    holds at the drive frequency. Columns: ``period``, each side's force over its sliding
    force, the net force on the runner (mN); ``amplitude_nm``.
    """
    from passmd.model import waveforms
    from passmd.model.theory import drive_theory
    from passmd.solver import simulation

    rigid = paper_drive_for(6, "rigid", *FIG5A_DRIVE)
    steady = primary(frequency_table, "rigid")
    steady_ac = float(steady[steady["contacts"] == 6]["critical_amplitude_nm"].iloc[0]) * 1e-9
    amplitude = fraction * steady_ac
    wave = waveforms.sawtooth(amplitude, PROTOCOL.drive_frequency, rigid, periods=STEADY_PERIODS)
    run = simulation.simulate(rigid, wave, max_points=200_001)
    sliding = np.array([f * rigid.friction_coefficient for f in drive_theory(rigid)["normal_force_N"]])
    rows = []
    for k, (t0, t1) in enumerate(wave.settle_windows, start=1):
        inside = (run.time >= t0) & (run.time <= t1)
        force = run.friction_force[:, inside].mean(axis=1)
        rows.append({"period": k, "side 1: T_1 / μF_N1": force[0] / sliding[0],
                     "side 2: T_2 / μF_N2": force[1] / sliding[1],
                     "net 2T_1 + 4T_2 (mN)": 1e3 * (2 * force[0] + 4 * force[1])})
    table = pd.DataFrame(rows)
    table.attrs["amplitude_nm"] = amplitude * 1e9
    return table


def slew_facts() -> dict:
    """Slew-rate fly-back time per nm of amplitude (ns/nm) for R = 1 mm (``b``) and 0.25 mm (``c``)
    and the bare actuator period of R = 1 mm (µs)."""
    facts = {}
    for key, radius in (("b", 1e-3), ("c", 0.25e-3)):
        drive = paper_drive_for(6, "flexible", radius, 0.4)
        facts[f"ns_per_nm_{key}"] = (drive.amplifier.full_stroke_time * 1e9
                                     / (drive.actuator.full_stroke_amplitude * 1e9))
    actuator = actuator_for_radius(1e-3)
    facts["period_b_us"] = 2 * np.pi * np.sqrt(actuator.mass / actuator.stiffness) * 1e6
    return facts


def ac_span(
    table: pd.DataFrame,
    contacts: int,
    protocol: str,
    *,
    flyback: str | None = None,
    actuator_model: str | None = None,
    band: tuple[float, float] | None = None,
) -> tuple[float, float]:
    """(min, max) of A_c (nm) over the rows of one series, optionally within a frequency ``band``."""
    sel = table[(table["contacts"] == contacts) & (table["protocol"] == protocol)]
    if flyback is not None:
        sel = sel[sel["flyback"] == flyback]
    if actuator_model is not None:
        sel = sel[sel["actuator_model"] == actuator_model]
    if band is not None:
        sel = sel[(sel["frequency_Hz"] >= band[0]) & (sel["frequency_Hz"] <= band[1])]
    return float(sel["critical_amplitude_nm"].min()), float(sel["critical_amplitude_nm"].max())


def ac_at(table: pd.DataFrame, contacts: int, actuator_model: str, protocol: str, frequency: float) -> float:
    """A_c (nm) of one series of the frequency panel at one drive frequency."""
    sel = table[(table["contacts"] == contacts) & (table["actuator_model"] == actuator_model)
                & (table["protocol"] == protocol) & np.isclose(table["frequency_Hz"], frequency)]
    return float(sel["critical_amplitude_nm"].iloc[0])


def ac_range(table: pd.DataFrame, contacts: int, protocol: str, **selection) -> float:
    """Width max − min (nm) of :func:`ac_span` of the same series."""
    low, high = ac_span(table, contacts, protocol, **selection)
    return high - low


# --------------------------------------------------------------------------------------
# What each paragraph of the chapters quotes (numbers, and short texts for {glue:md})
# --------------------------------------------------------------------------------------


def fig5b_facts(fig5b_table: pd.DataFrame, config: RunConfig) -> dict:
    """Deviations of Fig. 5b's series from Eqs. 7 and 8, the band's spread and the fixed fly-back's order."""
    dev = closed_form_deviations(fig5b_table, {"rigid": "u_x_max_nm", "flexible": "u_x_max_plus_u_x_a_nm"})
    band = PROFILE_SETTINGS["paper"].frequencies
    spread = band_spread(fig5b_table, "rigid")
    fixed = fig5b_table[(fig5b_table["protocol"] == "steady") & (fig5b_table["flyback"] == "fixed")]
    fixed = fixed.sort_values("preload_N")["critical_amplitude_nm"].to_numpy()
    rigid = primary(fig5b_table, "rigid")["critical_amplitude_nm"].to_numpy()
    if spread == spread:
        band_rigid = f"Between {band[0]:g} and {band[-1]:g} Hz it moves by up to {spread:.0f} % of its value."
    else:
        band_rigid = (f"(The {config.profile} profile runs {PROTOCOL.drive_frequency:g} Hz only; the paper "
                      "profile shows how much it moves with the drive frequency.)")
    return {
        "first_rigid_max": series_deviation(dev, "rigid", "first", "slew")[0],
        "first_fixed_max": series_deviation(dev, "flexible", "first", "fixed")[0],
        "first_slew_max": series_deviation(dev, "flexible", "first", "slew")[0],
        "steady_rigid_max": series_deviation(dev, "rigid", "steady", "slew")[0],
        "steady_rigid_mean": side_of(series_deviation(dev, "rigid", "steady", "slew")[1]),
        "steady_slew_max": series_deviation(dev, "flexible", "steady", "slew")[0],
        "steady_fixed_max": series_deviation(dev, "flexible", "steady", "fixed")[0],
        "steady_fixed_mean": side_of(series_deviation(dev, "flexible", "steady", "fixed")[1]),
        "band_rigid": band_rigid,
        "fixed_above_rigid": "at every preload" if np.all(fixed > rigid) else "not at every preload",
    }


def fig6a_facts(dev6a: pd.DataFrame, config: RunConfig) -> dict:
    """Largest deviations of Fig. 6a's steady state from Eqs. 11 and 10, of its first-fly-back onset
    from side 1's Eq. 10, and over the profile's drive frequencies (text)."""
    column = "Eq. 11: largest |dev| (%)"
    frequencies = PROFILE_SETTINGS[config.profile].frequencies
    band = [deviation_at(dev6a, "steady", "slew", column, f) for f in frequencies]
    return {
        "a_e": deviation_at(dev6a, "steady", "slew", column),
        "a_1": deviation_at(dev6a, "steady", "slew", "Eq. 10, side 1: largest |dev| (%)"),
        "a_2": deviation_at(dev6a, "steady", "slew", "Eq. 10, side 2: largest |dev| (%)"),
        "a_first_1": deviation_at(dev6a, "first", "slew", "Eq. 10, side 1: largest |dev| (%)"),
        "a_band": (f"and at most {max(band):.1f} % at any drive frequency of the band" if len(band) > 1
                   else f"(the {config.profile} profile runs {PROTOCOL.drive_frequency:g} Hz only)"),
    }


def fig6bc_facts(dev6: pd.DataFrame) -> dict:
    """Largest deviations of Figs. 6b (``b_``) and 6c (``c_``) from Eq. 12 and, for the first-fly-back
    onset with the fixed fly-back, from side 1's Eq. 13."""
    found = {}
    for key, name in (("b", "fig6b"), ("c", "fig6c")):
        dev = dev6[dev6["figure"] == name]
        found[f"{key}_slew"] = deviation_at(dev, "steady", "slew", "Eq. 12: largest |dev| (%)")
        found[f"{key}_fixed"] = deviation_at(dev, "steady", "fixed", "Eq. 12: largest |dev| (%)")
        found[f"{key}_first_fixed"] = deviation_at(dev, "first", "fixed", "Eq. 13, side 1: largest |dev| (%)")
    return found


def prestrain_facts(prestrain: pd.DataFrame) -> dict:
    """Amplitude (nm) of :func:`side_prestrain` and each side's force over its sliding force in the
    last period."""
    return {
        "prestrain_amplitude": prestrain.attrs["amplitude_nm"],
        "prestrain_1": prestrain["side 1: T_1 / μF_N1"].iloc[-1],
        "prestrain_2": prestrain["side 2: T_2 / μF_N2"].iloc[-1],
    }


def viscosity_facts(visc: pd.DataFrame) -> dict:
    """Ranges of A_c (nm) over the viscosity panel and the closed forms Eq. 12 (six) and Eq. 8 (one)."""
    found = {}
    series = {"v6_slew": (6, "steady", "slew"), "v6_fixed": (6, "steady", "fixed"),
              "v1_first_fixed": (1, "first", "fixed")}
    for key, (contacts, protocol, flyback) in series.items():
        found[f"{key}_lo"], found[f"{key}_hi"] = ac_span(visc, contacts, protocol, flyback=flyback)
    found["eq12_04"] = float(visc[visc["contacts"] == 6]["closed_form_nm"].iloc[0])
    found["eq8_04"] = float(visc[visc["contacts"] == 1]["closed_form_nm"].iloc[0])
    return found


def frequency_facts(freq: pd.DataFrame, config: RunConfig) -> dict:
    """How far the first-fly-back onset moves over all frequencies and within the paper's band (text),
    and the six-contact steady-state A_c at the highest and at the drive frequency (nm)."""
    settings = PROFILE_SETTINGS[config.profile]
    band = PROFILE_SETTINGS["paper"].frequencies
    f_hi = max(settings.sensitivity_frequencies)
    series = [(n, m) for n in (1, 6) for m in ("rigid", "flexible")]
    in_band = [f for f in settings.sensitivity_frequencies if band[0] <= f <= band[-1]]
    if len(in_band) > 1:
        span_band = max(ac_range(freq, n, "first", actuator_model=m, band=(band[0], band[-1]))
                        for n, m in series)
        first_band = f"Between {band[0]:g} and {band[-1]:g} Hz it moves by at most {span_band:.1f} nm."
    else:
        first_band = f"(The {config.profile} profile has only one frequency in the band of Figs. 5b and 6.)"
    return {
        "f_hi": f_hi,
        "first_span": max(ac_range(freq, n, "first", actuator_model=m) for n, m in series),
        "first_band": first_band,
        "six_rigid_hi": ac_at(freq, 6, "rigid", "steady", f_hi),
        "six_rigid_primary": ac_at(freq, 6, "rigid", "steady", PROTOCOL.drive_frequency),
        "six_flex_hi": ac_at(freq, 6, "flexible", "steady", f_hi),
        "six_flex_primary": ac_at(freq, 6, "flexible", "steady", PROTOCOL.drive_frequency),
    }
