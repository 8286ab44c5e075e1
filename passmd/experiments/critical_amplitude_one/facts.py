"""The facts the one-contact chapter quotes (Section 4.1, Figs. 5a and 5b).

Small tested functions over the figure data of :mod:`passmd.experiments.critical_amplitude_one.figures`
(onsets, deviations from the closed forms, the band's spread) and the protocol's numbers. The chapter
glues their results into the prose.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd.experiments.critical_amplitude_one.figures import (
    FIG5A_DRIVE,
    PROFILE_SETTINGS,
    paper_drive_for,
    primary,
)
from passmd.model.defaults import PROTOCOL
from passmd.model.tables import ACTUATOR_DAMPING_RATIO
from passmd.protocols.critical_amplitude import STEADY_PERIODS, STEP_THRESHOLD
from passmd.runtime.config import RunConfig

#: Amplitude of the fly-back time quoted as an example in the protocol section (m).
EXAMPLE_FLYBACK_AMPLITUDE = 40e-9


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


