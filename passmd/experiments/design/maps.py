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

from passmd.protocols.maps import MAP_QUANTITIES, READINGS
from passmd.runtime import sweep
from passmd.runtime.config import RunConfig
from passmd.runtime.validation import check_choice

__all__ = ["compute_map"]


def compute_map(quantity: str, points: Sequence[Mapping], *, reading: str = "steady",
                waveform: str = "sawtooth", config: RunConfig | None = None,
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
    config : RunConfig, optional
        How the sweep runs (executor, workers, cache, progress).

    Returns
    -------
    pandas.DataFrame
        The points' extra keys, then the point function's results; ``attrs["sweep"]`` as
        :func:`passmd.runtime.sweep.run`.
    """
    check_choice("quantity", quantity, tuple(MAP_QUANTITIES))
    check_choice("reading", reading, READINGS)
    check_choice("waveform", waveform, ("sawtooth", "optimized"))
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
        calls.append(call)
    frame = sweep.run(spec.function, calls, config=config, description=description or f"{quantity} map")
    extra = pd.DataFrame([{k: v for k, v in p.items() if k not in inputs} for p in points])
    results = frame.drop(columns=[c for c in frame.columns if c in (*inputs, "reading", "waveform")])
    table = pd.concat([extra.reset_index(drop=True), results.reset_index(drop=True)], axis=1)
    table.attrs["sweep"] = frame.attrs["sweep"]
    return table
