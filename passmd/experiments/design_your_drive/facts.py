"""What the chapter "Design your own drive" quotes: each map's and curve's numbers, and its calibration
(the fit's estimates against the values that made the data, the held-back predictions' misfit, the
measurements as ``passmd fit`` reads them, and the fit with the other fly-back rule).

The data of every figure, the calibration's included, are
:mod:`passmd.experiments.design_your_drive.figures`.
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from passmd.experiments.design_your_drive.figures import run_config
from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import Drive
from passmd.protocols import diagnosis, fit, ringing
from passmd.runtime.config import RunConfig

__all__ = ["curve_facts", "fit_facts", "gain_facts", "heldback_facts", "map_facts", "measurements_csv",
           "other_flyback_fit", "ringing_facts"]


def measurements_csv(data: fit.Measurements) -> str:
    """The text of the measurement CSV that ``passmd fit`` reads
    (:func:`passmd.protocols.fit.measurements.write_measurements`)."""
    with tempfile.TemporaryDirectory(prefix="passmd-design-") as folder:
        path = Path(folder) / "measurements.csv"
        fit.write_measurements(path, data)
        return path.read_text(encoding="utf-8")


def other_flyback_fit(start: Drive, data: fit.Measurements, profile: str,
                      config: RunConfig | None = None) -> fit.FitResult:
    """μ fitted to ``data`` with the fly-back rule the data were not made with (``"fixed"`` for a drive
    whose rule is ``"slew"``, else ``"slew"``): a wrong fixed assumption for the χ² test to judge."""
    other = "fixed" if start.amplifier.flyback == "slew" else "slew"
    wrong = replace(start, amplifier=replace(start.amplifier, flyback=other))
    return fit.fit(wrong, data, ["friction_coefficient"], config=run_config(config, profile))


def fit_facts(result: fit.FitResult, truth: Drive, start: Drive) -> pd.DataFrame:
    """One row per free parameter: the value simulated (truth), the first guess, the estimate, its
    local standard error, its 95 % region (pieces, and their hull) and whether the region holds the
    truth (SI)."""
    rows = []
    for name in result.names:
        p = fit.FREE_PARAMETERS[name]
        est = result.estimates[name]
        low, high = est["interval"]
        rows.append({"parameter": name, "symbol": p.symbol, "unit": p.unit, "truth": p.get(truth),
                     "start": p.get(start), "estimate": est["value"], "stderr": est["stderr"],
                     "low": low, "high": high, "pieces": len(est["intervals"]),
                     "holds_truth": any(a <= p.get(truth) <= b for a, b in est["intervals"])})
    return pd.DataFrame(rows)


def heldback_facts(table: pd.DataFrame, labels=("start", "fitted")) -> dict:
    """Root-mean-square deviation (nm) of each drive's predictions from the held-back measurements."""
    out = {"heldback_points": len(table)}
    for label in labels:
        out[f"rms_{label}_nm"] = float(np.sqrt(np.mean((table[f"{label}_nm"] - table["measured_nm"]) ** 2)))
    return out


def map_facts(table: pd.DataFrame) -> dict:
    """The step/velocity map's extremes: the fastest point, and the step at the grid's lowest and
    highest frequency at the largest amplitude (nm, mm/s, kHz)."""
    v = table["velocity_m_per_s"].to_numpy(float)
    best = int(np.nanargmax(v))
    a = table["amplitude_m"].to_numpy(float)
    top = table[np.isclose(a, a.max(), rtol=1e-9, atol=0.0)].sort_values("frequency_Hz")  # the largest only
    return {"v_max_mm_s": v[best] * 1e3, "v_max_f_kHz": table["frequency_Hz"].iloc[best] / 1e3,
            "v_max_A_nm": table["amplitude_m"].iloc[best] * 1e9,
            "step_low_f_nm": top["step_m"].iloc[0] * 1e9, "step_high_f_nm": top["step_m"].iloc[-1] * 1e9,
            "f_low_kHz": top["frequency_Hz"].iloc[0] / 1e3, "f_high_kHz": top["frequency_Hz"].iloc[-1] / 1e3,
            "A_top_nm": top["amplitude_m"].iloc[0] * 1e9, "map_points": len(table)}


def gain_facts(table: pd.DataFrame) -> dict:
    """How the Eq. 15 waveform compares with the saw-tooth over the map: points with a waveform,
    how many of them are faster, the largest gain and loss (mm/s) and where the gain is largest."""
    gain = np.array([np.nan if g is None else float(g) for g in table["gain_m_per_s"]])
    valid = np.isfinite(gain)
    out = {"gain_points": len(table), "gain_designed": int(valid.sum()), "gain_none": int((~valid).sum()),
           "gain_faster": int((gain[valid] > 0).sum())}
    if valid.any():
        best, worst = int(np.nanargmax(gain)), int(np.nanargmin(gain))
        out.update(gain_max_mm_s=gain[best] * 1e3, gain_max_f_kHz=table["frequency_Hz"].iloc[best] / 1e3,
                   gain_max_A_nm=table["amplitude_m"].iloc[best] * 1e9, gain_min_mm_s=gain[worst] * 1e3)
    return out


def curve_facts(curve: pd.DataFrame) -> dict:
    """What the chapter says of A_c against preload, all read off ``curve``
    (:func:`~passmd.experiments.design_your_drive.figures.curve_from_maps`): at how many preloads the
    closed form lies at or above both simulated readings, where the steady reading exceeds it most
    (nm, N), how often the steady curve turns (changes beyond the measurable step) and at how many
    preloads the runner still rings at the next fly-back."""
    closed, steady, first = (curve[c].to_numpy(float) for c in ("closed_form_nm", "steady_nm", "first_nm"))
    above = (closed >= steady) & (closed >= first)
    excess = steady - closed
    worst = int(np.nanargmax(excess))
    turns = ringing.turns(steady, [PROTOCOL.step_threshold * 1e9] * len(steady))
    return {"ca_points": len(curve), "ca_closed_above": int(above.sum()),
            "ca_excess_nm": float(excess[worst]), "ca_excess_at_N": float(curve["preload_N"].iloc[worst]),
            "ca_turns": len(turns), "ca_ringing_points": int(curve["ringing_affects"].sum()),
            "ca_ringing_left_nm": float(np.nanmax(curve["ringing_left_nm"]))}


def ringing_facts(probe: dict, frequency: float) -> dict:
    """The ringing after a fly-back (:func:`passmd.protocols.ringing.stick_ringing`) as the chapter
    quotes it: frequency (kHz), first swing (nm), 1/e time (ms), swing left at the next fly-back at
    ``frequency`` (nm) and the longest period at which that is below the measurable step (ms; NaN
    if the swing stays above it while recorded)."""
    at = ringing.at_frequency(probe, frequency)
    swings, times = np.asarray(probe["swing_amplitudes_m"]), np.asarray(probe["swing_times_s"])
    below = np.flatnonzero(swings < ringing.MEASURABLE)
    return {"ring_f_kHz": probe["ringing_frequency_Hz"] / 1e3,
            "ring_amp_nm": probe["ringing_amplitude_m"] * 1e9,
            "ring_decay_ms": probe["ringing_decay_time_s"] * 1e3,
            "ring_left_nm": at["ringing_at_next_flyback_m"] * 1e9,
            "ring_hold_ms": probe["ringing_hold_s"] * 1e3, "ring_next_ms": at["next_flyback_after_s"] * 1e3,
            "ring_quiet_ms": float(times[below[0]] * 1e3) if below.size else math.nan}


def diagnosis_table(found: dict) -> pd.DataFrame:
    """The causes of a critical amplitude's departure (:func:`passmd.protocols.diagnosis.diagnose`), one row
    each: the counterfactual (what was removed), its A_c (nm) and its share of the departure (%)."""
    return pd.DataFrame([{"cause": c["cause"], "counterfactual": c["changed"],
                          "counterfactual A_c [nm]": ("–" if c["counterfactual_value"] is None
                                                      else f"{c['counterfactual_value'] * 1e9:.4g}"),
                          "share [%]": "–" if c["share"] is None else f"{100 * c['share']:.0f}"}
                         for c in found["causes"]])


def _share_range(low: float, high: float) -> str:
    """The naming shares between ``low`` (excluded) and ``high`` (included), in words."""
    if math.isinf(low) and math.isinf(high):
        return "whatever the naming share"
    if math.isinf(low):
        return f"for any naming share up to {100 * high:.0f} %"
    if math.isinf(high):
        return f"for any naming share above {100 * low:.0f} %"
    return f"for any naming share above {100 * low:.0f} % and up to {100 * high:.0f} %"


def diagnosis_facts(found: dict) -> dict:
    """The numbers and words the page says of a diagnosis: the value, the closed form, the gap, the causes
    named and those that gave no value (with why), and the naming shares that name the same causes
    (``why_naming_range``, the sensitivity of assumption ``diagnosis_thresholds``)."""
    value, closed = found["values"][-1], found["expected"][-1]
    named = found["named"]
    untried = [f"{c['cause']}: {c['changed']}" for c in found["causes"] if c["share"] is None]
    shares = [c["share"] for c in found["causes"] if c["share"] is not None]
    below = [s for s in shares if s < diagnosis.EXPLAINS]
    above = [s for s in shares if s >= diagnosis.EXPLAINS]
    # the named causes are the same for every naming share in (largest share below, smallest at or above];
    # a negative share (its removal widens the departure) bounds no threshold worth naming
    low = max(below) if below and max(below) >= 0 else -math.inf
    high = min(above) if above else math.inf
    return {"why_value_nm": value * 1e9, "why_closed_nm": closed * 1e9,
            "why_naming_range": _share_range(low, high),
            "why_gap_pct": 100 * abs(value / closed - 1), "why_side": "below" if value < closed else "above",
            "why_named": (" and ".join(f"**{n}**" for n in named) if named
                          else "none of the candidates (each takes away less than half of the departure)"),
            "why_untried": ("Without a value: " + "; ".join(untried) + ".") if untried else ""}
