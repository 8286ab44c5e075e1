"""Which one added measurement would best tell a fit's basins apart.

When a parameter is known only to several separated basins, the measurements taken cannot tell
them apart; one more row at other conditions may. :func:`separating_row` predicts candidate rows
(the data's conditions with one of frequency, amplitude or preload moved: :func:`candidates`)
at each basin's parameters and picks the row whose predictions would exclude the most basins: a
basin b' is excluded, were basin b the truth, when its cost rise over b's plus the new row's
squared misfit (prediction difference over the row's σ) exceeds the 95 % level.
"""

from __future__ import annotations

import math

import numpy as np

from passmd.model.parameters import PLAUSIBLE_RANGES, Drive
from passmd.model.waveforms import flyback_time
from passmd.protocols.fit.measurements import Measurements, measurements_from_rows
from passmd.protocols.fit.prediction import _Model

__all__ = ["candidates", "separating_row"]

_COLUMN = {"step": "step_nm", "velocity": "velocity_mm_per_s", "position": "position_nm", "force": "force_N",
           "critical_amplitude": "critical_amplitude_nm"}


def _valid(drive: Drive, amplitude: float, frequency: float, kind: str) -> bool:
    """Whether the drive can run a row (amplitude within its stroke, the fly-back within half a period)."""
    if not PLAUSIBLE_RANGES["frequency"].soft_low <= frequency <= PLAUSIBLE_RANGES["frequency"].soft_high:
        return False
    if kind == "critical_amplitude":
        return flyback_time(drive.actuator.full_stroke_amplitude, drive) < 0.5 / frequency
    a_max = drive.actuator.full_stroke_amplitude
    return 0.0 < amplitude <= a_max and flyback_time(amplitude, drive) < 0.5 / frequency


def candidates(drive: Drive, data: Measurements) -> Measurements:
    """Candidate rows: the data's most frequent kind at its most frequent preload and frequency and
    its largest amplitude, with one of them moved (other preloads, amplitudes, frequencies)."""
    kinds = list(data.kind)
    kind = max(set(kinds), key=kinds.count)
    rows = [i for i in range(len(data)) if data.kind[i] == kind]
    preload = np.where(np.isfinite(data.preload), data.preload, drive.preload)
    p0 = max(set(preload[rows].tolist()), key=preload[rows].tolist().count)
    f0 = max(set(data.frequency[rows].tolist()), key=data.frequency[rows].tolist().count)
    amps = data.amplitude[rows][np.isfinite(data.amplitude[rows])]
    a0 = float(amps.max()) if amps.size else math.nan
    low, high = float(preload[rows].min()), float(preload[rows].max())
    preloads = sorted({*preload[rows].tolist(), 0.5 * low, 1.5 * high})
    frequencies = sorted({*data.frequency[rows].tolist(), 0.5 * f0, 2.0 * f0, 10.0 * f0})
    a_max = drive.actuator.full_stroke_amplitude
    amplitudes = sorted({*amps.tolist(), 0.5 * (float(amps.min()) + a0), 0.95 * a_max}) if amps.size else [a0]
    points = ({(p, a0, f0) for p in preloads} | {(p0, a, f0) for a in amplitudes}
              | {(p0, a0, f) for f in frequencies})
    header = ["amplitude_nm", "preload_N", "frequency_Hz", _COLUMN[kind]]
    cells = []
    for p, a, f in sorted(points):
        row_drive = drive.replace(preload=p, allow_extrapolation=True)
        if not (PLAUSIBLE_RANGES["preload"].soft_low <= p <= PLAUSIBLE_RANGES["preload"].soft_high):
            continue
        if not _valid(row_drive, a, f, kind):
            continue
        cells.append(["" if math.isnan(a) else repr(a * 1e9), repr(p), repr(f), "1"])
    return measurements_from_rows(header, cells, name="candidate rows")


def separating_row(model: _Model, basin_points: list[np.ndarray], basin_costs: list[float], sigma: float,
                   s2: float, threshold: float) -> dict | None:
    """The candidate row that would exclude the most basins (module docstring), or None.

    ``model``: the fit's model (its drive, free parameters and evaluation); ``sigma``: the new
    row's standard deviation (SI, as the data's of its kind); costs and ``s2`` as the fit's.
    Returns ``{"kind", "amplitude_m", "preload_N", "frequency_Hz", "predictions", "excluded"}``:
    the predictions at each basin (SI) and how many (basin, truth) pairs the row excludes.
    """
    rows = candidates(model.drive, model.data)
    if len(rows) == 0 or len(basin_points) < 2:
        return None
    probe = _Model(model.drive, rows, model.names, model.reading, executor=model.executor, cache=model.cache,
                   config=model.config)
    preds = np.array(probe.evaluate(basin_points))  # (basins, rows)
    model.simulations += probe.simulations
    costs = np.asarray(basin_costs, float)
    best, best_score = None, (-1, -1.0)
    for r in range(len(rows)):
        excluded, spread = 0, 0.0
        for b in range(len(costs)):
            for other in range(len(costs)):
                if other == b:
                    continue
                rise = max(costs[other] - costs[b], 0.0) + ((preds[other, r] - preds[b, r]) / sigma) ** 2
                excluded += rise > threshold * s2
                spread += ((preds[other, r] - preds[b, r]) / sigma) ** 2
        if (excluded, spread) > best_score:
            best, best_score = r, (excluded, spread)
    return {"kind": rows.kind[best], "column": rows.column[best], "amplitude_m": float(rows.amplitude[best]),
            "preload_N": float(rows.preload[best]), "frequency_Hz": float(rows.frequency[best]),
            "predictions": preds[:, best].tolist(), "excluded": int(best_score[0]),
            "pairs": len(costs) * (len(costs) - 1)}
