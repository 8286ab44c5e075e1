"""Design maps: one quantity of :mod:`passmd.protocols.maps` over a grid of drives and waveforms.

:func:`compute_map` runs the points through :func:`passmd.runtime.sweep.run` (process pool or Dask,
progress, the result cache: an interrupted map resumes where it stopped, and any point
already computed, by an earlier map or another quantity of the same run, is reused) and
returns one row per point in grid order. What varies is the caller's: a point holds the
:class:`~passmd.model.parameters.Drive` itself, so any parameter of the drive can be an axis.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import pandas as pd

from passmd.protocols.eq15 import DESIGN_RESPONSES
from passmd.protocols.maps import MAP_QUANTITIES, READINGS, with_ringing
from passmd.protocols.ringing import ringing_point
from passmd.runtime import sweep
from passmd.runtime.config import RunConfig
from passmd.runtime.validation import check_choice

__all__ = ["compute_map"]


def compute_map(quantity: str, points: Sequence[Mapping], *, reading: str = "steady",
                waveform: str = "sawtooth", design_response: str = "paper", config: RunConfig | None = None,
                description: str | None = None) -> pd.DataFrame:
    """``quantity`` (a key of :data:`~passmd.protocols.maps.MAP_QUANTITIES`) at every point.

    Parameters
    ----------
    quantity : str
        ``velocity``, ``step``, ``back-step``, ``critical-amplitude``, ``stall-force`` or ``gain``.
    points : list of dict
        Each ``{"drive": Drive, "frequency": f}`` plus ``"amplitude": A`` (m) for every
        quantity but the critical amplitude; further keys (the axes' values for display)
        are carried into the table and not passed on.
    reading : {"steady", "first"}
        The critical amplitude's reading (ignored by the other quantities).
    waveform : {"sawtooth", "optimized"}
        Waveform of ``velocity``, ``step`` and ``back-step``.
    design_response : {"paper", "driving"}
        The saw-tooth response the Eq. 15 waveform (``gain``, ``waveform="optimized"``) is designed
        from (:func:`passmd.protocols.eq15.response_frequency`).
    config : RunConfig, optional
        How the sweep runs (executor, workers, cache, progress).

    Returns
    -------
    pandas.DataFrame
        The points' extra keys, then the point function's results, then (every quantity but the
        critical amplitude, whose point measures it at A_c, and the stall force) the runner's
        ringing after a fly-back and what of it is left at the next (``ringing_*`` columns);
        ``attrs["sweep"]`` as :func:`passmd.runtime.sweep.run` gives it for the quantity.
    """
    check_choice("quantity", quantity, tuple(MAP_QUANTITIES))
    check_choice("reading", reading, READINGS)
    check_choice("waveform", waveform, ("sawtooth", "optimized"))
    check_choice("design_response", design_response, DESIGN_RESPONSES)
    spec = MAP_QUANTITIES[quantity]
    inputs = ("drive", "frequency", "amplitude") if spec.amplitude else ("drive", "frequency")
    calls = []
    for i, point in enumerate(points):
        missing = [key for key in inputs if key not in point]
        if missing:
            raise ValueError(f"points[{i}] has no {missing[0]!r}: a {quantity} map needs {', '.join(inputs)}")
        call = {key: point[key] for key in inputs}
        if quantity == "critical-amplitude":
            call["reading"] = reading
        elif spec.function.__name__ == "steady_point":
            call["waveform"] = waveform
        if quantity == "gain" or (spec.function.__name__ == "steady_point" and waveform == "optimized"):
            call["design_response"] = design_response
        calls.append(call)
    frame = sweep.run(spec.function, calls, config=config, description=description or f"{quantity} map")
    extra = pd.DataFrame([{k: v for k, v in p.items() if k not in inputs} for p in points])
    results = frame.drop(columns=[c for c in frame.columns if c in (*inputs, "reading", "waveform",
                                                                     "design_response")])
    table = pd.concat([extra.reset_index(drop=True), results.reset_index(drop=True)], axis=1)
    if spec.amplitude and quantity != "stall-force":
        _add_ringing(table, calls, config)
    table.attrs["sweep"] = frame.attrs["sweep"]
    return table


def _add_ringing(table: pd.DataFrame, calls: list[dict], config: RunConfig | None) -> None:
    """The runner's ringing after a fly-back at each point (``ringing_*`` columns,
    :func:`passmd.protocols.maps.with_ringing`): one probe per drive and amplitude, whatever the
    frequency, so a frequency axis costs one probe."""
    keys = list(dict.fromkeys((c["drive"], c["amplitude"]) for c in calls))
    probes = sweep.run(ringing_point, [{"drive": d, "amplitude": a} for d, a in keys], config=config,
                       description="runner ringing")
    found = dict(zip(keys, probes.to_dict(orient="records"), strict=True))
    with_ringing(table, [found[(c["drive"], c["amplitude"])] for c in calls], [c["frequency"] for c in calls])
