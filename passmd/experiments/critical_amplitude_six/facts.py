"""The facts the six-contact chapter quotes (Section 4.1, Figs. 6a–c and the sensitivity panels).

Small tested functions over the figure data of :mod:`passmd.experiments.critical_amplitude_six.figures`
(deviations from the closed forms, spans over the sensitivity panels) and the run the chapter shows
beyond the preload grids (the prestrain of the two sides). The chapter glues their results into the
prose.
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
from passmd.model.tables import ACTUATOR_DAMPING_RATIO, actuator_for_radius
from passmd.protocols.critical_amplitude import STEADY_PERIODS
from passmd.runtime.config import RunConfig


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
