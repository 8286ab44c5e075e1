"""Facts the velocity chapter reads from the data of Figs. 9b and 10 (Section 5.2).

Small functions of the figures' tidy tables (:mod:`passmd.experiments.waveform_velocity.figures`)
that return the numbers and tables the chapter glues into its prose: the start-up, the velocities
of Fig. 9b and the reachable maxima of Fig. 10. Display units: nm, µs, kHz, mm/s, %.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd.experiments.waveform_velocity.figures import (
    FIG10A_PRELOADS,
    PAPER_MAXIMUM_KHZ,
    eq15_fit_limit,
    range_maximum,
)
from passmd.model import waveforms
from passmd.model.parameters import Drive
from passmd.runtime.units import round_down


def startup_facts(fig9b_data: pd.DataFrame, frequency: float = PAPER_MAXIMUM_KHZ * 1e3) -> dict:
    """The saw-tooth's steady and first-to-last velocity at ``frequency`` (mm/s) and the largest
    drift between the third and fourth quarter of any Fig. 9b run (%)."""
    rows = fig9b_data[(fig9b_data["variant"] == "sawtooth") & np.isclose(fig9b_data["frequency"], frequency)]
    saw = rows.iloc[0]
    return {"v110_steady": saw["velocity_mm_per_s"], "v110_sim": saw["simulator_mean_velocity_m_per_s"] * 1e3,
            "max_drift_pct": np.nanmax(np.abs(fig9b_data["velocity_drift"])) * 100}


def fig9b_facts(fig9b_data: pd.DataFrame, design: pd.Series, drive: Drive) -> dict:
    """Fig. 9b: up to which frequency one whole Eq. 15 period fits (kHz,
    :func:`~passmd.experiments.waveform_velocity.figures.eq15_fit_limit`; ``fit_limit_printed_kHz``
    as ``passmd run --waveform optimized`` prints it, rounded down to four digits); the room for t_s
    in a period at the paper's 110 kHz (µs), the f_s it would need (kHz) and the contact-stiffness
    factor that means; the optimized velocity there; the skip variant's largest gain on the grid up to
    110 kHz (mm/s, %, kHz, and the grid points either side of it: ``skip_gain_where``); the
    saw-tooth's step at the grid's ends (nm); how far the measured f_s lies from its linear estimate
    (%)."""
    opt = fig9b_data[fig9b_data["variant"] == "optimized"].set_index("frequency")
    saw = fig9b_data[fig9b_data["variant"] == "sawtooth"].set_index("frequency")
    skip = fig9b_data[fig9b_data["variant"] == "optimized_skip"].set_index("frequency")
    paper_f = PAPER_MAXIMUM_KHZ * 1e3
    t_s_max = (1 / paper_f - waveforms.flyback_time(drive.actuator.full_stroke_amplitude, drive)
               - design["acceleration_time_s"])
    f_s_needed = 0.5 / t_s_max
    gain = (skip["velocity_mm_per_s"] - saw["velocity_mm_per_s"])[saw.index <= paper_f]
    grid = saw.index.to_numpy(dtype=float)
    at = float(gain.idxmax())
    below, above = grid[grid < at], grid[grid > at]
    either = [f"{side / 1e3:g} kHz" for side in (below.max() if below.size else None,
                                                   above.min() if above.size else None) if side is not None]
    limit_kHz = eq15_fit_limit(design, drive) / 1e3
    # an upper limit is printed as the command line prints it: rounded down to its four digits
    return {"fit_limit_kHz": limit_kHz, "fit_limit_printed_kHz": round_down(limit_kHz, 4),
            "t_s_room_us": t_s_max * 1e6,
            "skip_gain_where": (f"at the grid point {at / 1e3:g} kHz, between {' and '.join(either)}"
                                if len(either) == 2 else f"at {at / 1e3:g} kHz, the grid's edge"),
            # "within" this many per cent: rounded up
            "f_s_linear_dev_pct": float(np.ceil(100 * abs(design["micro_vibration_frequency_Hz"]
                                                          / design["linear_frequency_Hz"] - 1))),
            "f_s_needed_kHz": f_s_needed / 1e3,
            "stiffness_factor": (f_s_needed / design["micro_vibration_frequency_Hz"]) ** 2,
            "v110_opt": opt.loc[paper_f, "velocity_mm_per_s"], "skip_gain_max": gain.max(),
            "skip_gain_f": gain.idxmax() / 1e3,
            "skip_gain_pct": 100 * gain.max() / saw.loc[gain.idxmax(), "velocity_mm_per_s"],
            "saw_step_1k": saw.loc[saw.index.min(), "step_nm"],
            "saw_step_130k": saw.loc[saw.index.max(), "step_nm"]}


def reachable_table(table: pd.DataFrame, key: str) -> pd.DataFrame:
    """Largest steady velocity of each value of ``key`` and waveform variant, where on the grid it lies
    (and whether at the grid's edge), the back-step there and the design's f_s."""
    rows = []
    for value, part in table.groupby(key, sort=False):
        for variant in ("sawtooth", "optimized", "optimized_skip"):
            series = part[part["variant"] == variant]
            best = range_maximum(series)
            edge = best["frequency_kHz"] in (series["frequency_kHz"].min(), series["frequency_kHz"].max())
            rows.append({key: value, "variant": variant, "max velocity (mm/s)": best["velocity_mm_per_s"],
                         "at (kHz)": best["frequency_kHz"], "at the grid's edge": edge,
                         "back-step there (nm)": best["back_step_nm"],
                         "f_s (kHz)": best["micro_vibration_frequency_Hz"] / 1e3})
    return pd.DataFrame(rows)


def stick_lost(fig10a_data: pd.DataFrame, preload: float = min(FIG10A_PRELOADS)) -> dict:
    """Frequencies (kHz) where the optimized waveform loses the stick during t_a at ``preload``:
    ``all`` of them and those ``with_full_settling`` (the full t_s fits)."""
    rows = fig10a_data[(fig10a_data["variant"] == "optimized") & np.isclose(fig10a_data["preload"], preload)]
    lost = rows[~rows["stick_during_acceleration"].astype(bool)]
    return {"all": list(lost["frequency_kHz"]),
            "with_full_settling": list(lost[lost["settling_fits"].astype(bool)]["frequency_kHz"])}
