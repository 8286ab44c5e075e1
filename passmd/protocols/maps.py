"""The quantities a design map evaluates at one point: a drive, an amplitude, a frequency.

Each quantity is a pure point function of a :class:`~passmd.model.parameters.Drive` and the
waveform's parameters, built from the protocols the book uses (nothing is re-derived here):

* ``velocity``, ``step``, ``back-step``: the steady-velocity protocol
  (:func:`passmd.protocols.velocity.steady_run`: a run of ``max(20, f · 5 ms)`` periods
  from rest, the slope of the period-mean position over its second half; step = velocity / f,
  back-step the mean over the second half), one run giving all three;
* ``critical-amplitude``: the bisection of :func:`passmd.protocols.critical_amplitude.critical_amplitude`
  with the reading ``steady`` (the last step of a run of saw-tooth periods exceeds the
  measurable step: the amplitude a drive in continuous operation needs) or ``first`` (full
  sliding of every contact in the first fly-back from rest: the amplitude that moves a
  drive once), plus the closed form (Eqs. 7–8, 11–12, :func:`passmd.model.theory.drive_theory`);
* ``stall-force``: the generated force at stall against the load cell
  (:func:`passmd.protocols.stall.generated_force`, Section 4.2);
* ``gain``: the steady velocity of the optimized waveform (Eq. 15, designed from this drive's
  own saw-tooth response at this amplitude, :func:`passmd.protocols.eq15.design_at`: by default
  the 100 Hz response of Section 5.2) minus that of the saw-tooth, both by the steady-velocity
  protocol. Where Eq. 15 gives no waveform (no micro-vibration in the saw-tooth response, Δ_a ≥ A
  at small amplitudes, or a period too short for t_s + t_a, the fly-back and the slow ramp) the
  point's gain is ``None`` and ``note`` says why; the highest frequency at which Eq. 15 fits is
  a column of every point.

All values are SI, keys carrying the unit, and the cache stores them as they are.

:func:`compute_map` evaluates one quantity over a grid of points through :func:`passmd.runtime.sweep.run`
(process pool or Dask, progress, the result cache: an interrupted map resumes where it stopped, and any
point already computed, by an earlier map or another quantity of the same run, is reused) and returns
one row per point in grid order. What varies is the caller's: a point holds the
:class:`~passmd.model.parameters.Drive` itself, so any parameter of the drive can be an axis. The
command line's ``passmd sweep`` and the design chapter run it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import pandas as pd

from passmd.model import theory
from passmd.model.parameters import Drive
from passmd.protocols import critical_amplitude, eq15, ringing, stall, velocity
from passmd.runtime import sweep
from passmd.runtime.config import RunConfig
from passmd.runtime.validation import InputError, check_choice

__all__ = ["MAP_QUANTITIES", "READINGS", "MapQuantity", "compute_map", "critical_amplitude_point",
           "gain_point", "stall_point", "steady_point", "with_ringing"]

#: Readings of the simulated critical amplitude (:data:`passmd.protocols.critical_amplitude.PROTOCOLS`).
READINGS = critical_amplitude.PROTOCOLS


def steady_point(drive: Drive, amplitude: float, frequency: float, waveform: str = "sawtooth",
                 design_response: str = "paper") -> dict:
    """Steady velocity, step and back-step of one waveform (:func:`~passmd.protocols.velocity.steady_run`).

    ``waveform="optimized"``: the Eq. 15 waveform designed from this drive's saw-tooth response
    (``design_response``, :func:`passmd.protocols.eq15.design_at`); where it does not fit the
    period, or Eq. 15 gives none, the values are ``None`` and ``note`` says why.
    """
    check_choice("waveform", waveform, ("sawtooth", "optimized"))
    if waveform == "sawtooth":
        return velocity.steady_run(drive, amplitude, frequency, waveform, "cut", None)
    design, f_max, note = _eq15_design(drive, amplitude, frequency, design_response)
    if note is not None:
        return {"velocity_m_per_s": None, "step_m": None, "back_step_m": None, "velocity_drift": None,
                **_design_columns(design, f_max), "note": note}
    out = velocity.steady_run(drive, amplitude, frequency, waveform, "refuse", design)
    return {**out, **_design_columns(design, f_max), "note": None}


def _eq15_design(drive, amplitude, frequency, response):
    """(design, highest fitting frequency, note): the Eq. 15 design at this point (None where there is
    none) and why it gives no waveform here (None where it does)."""
    try:
        design, f_max = eq15.design_at(amplitude, frequency, drive, response=response)
    except InputError as exc:  # no micro-vibration to design from, or V_a ≤ V_r (Eq. 15)
        return None, None, f"no Eq. 15 waveform at this amplitude: {exc.detail or exc}"
    if not design.acceleration_amplitude < amplitude:
        return design, f_max, (f"no Eq. 15 waveform at this amplitude: Δ_a = "
                               f"{design.acceleration_amplitude * 1e9:.4g} nm is not below A")
    if frequency > f_max:
        busy = (design.settling_time + design.acceleration_time) * 1e6
        return design, f_max, (f"Eq. 15 does not fit the period: t_s + t_a = {busy:.4g} µs, the fly-back "
                               f"and the slow ramp need f <= {f_max / 1e3:.4g} kHz")
    return design, f_max, None


def _design_columns(design, f_max) -> dict:
    """The Eq. 15 design's times, amplitude, source response and highest fitting frequency."""
    if design is None:
        return {"settling_time_s": None, "acceleration_time_s": None, "acceleration_amplitude_m": None,
                "response_frequency_Hz": None, "eq15_highest_frequency_Hz": None}
    return {"settling_time_s": design.settling_time, "acceleration_time_s": design.acceleration_time,
            "acceleration_amplitude_m": design.acceleration_amplitude,
            "response_frequency_Hz": design.response_frequency, "eq15_highest_frequency_Hz": f_max}


def critical_amplitude_point(drive: Drive, frequency: float, reading: str = "steady") -> dict:
    """Simulated A_c (``reading``: ``steady`` or ``first``) and the closed form of the drive.

    ``critical_amplitude_m`` is ``None`` when no amplitude up to the full stroke moves the runner.
    The runner's ringing after a fly-back at A_c (at the full stroke if none) is measured too
    (:func:`passmd.protocols.ringing.at_frequency`): ``ringing_*`` columns; for the steady reading
    ``ringing_affects_steps`` says whether a measurable swing is left at the next fly-back (the
    first reading has no earlier fly-back, so it never does).
    """
    found = critical_amplitude.critical_amplitude(drive, protocol=reading, frequency=frequency)
    for key in ("critical_amplitude_m", "bracket_high_m"):  # NaN: no onset up to the full stroke
        if math.isnan(found[key]):
            found[key] = None
    closed_form = theory.drive_theory(drive)["analytic_critical_amplitude_m"]
    found["analytic_critical_amplitude_m"] = float(closed_form)
    at = found["critical_amplitude_m"] or drive.actuator.full_stroke_amplitude
    rings = ringing.at_frequency(ringing.stick_ringing(drive, at, frequency), frequency)
    rings["ringing_affects_steps"] = rings["ringing_affects_steps"] and reading == "steady"
    return {**found, **rings}


def stall_point(drive: Drive, amplitude: float, frequency: float) -> dict:
    """Generated force at stall (:func:`passmd.protocols.stall.generated_force`)."""
    return stall.generated_force(drive, amplitude, frequency)


def gain_point(drive: Drive, amplitude: float, frequency: float, design_response: str = "paper") -> dict:
    """Steady velocity of the Eq. 15 waveform minus that of the saw-tooth (m/s), both measured.

    ``gain_m_per_s`` is ``None`` with a ``note`` where Eq. 15 gives no waveform: no
    micro-vibration in the saw-tooth response at this amplitude, an acceleration segment Δ_a not
    below the amplitude, or a period too short for it (above ``eq15_highest_frequency_Hz``).
    """
    saw = velocity.steady_run(drive, amplitude, frequency, "sawtooth", "cut")
    out = {"sawtooth_velocity_m_per_s": saw["velocity_m_per_s"], "optimized_velocity_m_per_s": None,
           "gain_m_per_s": None}
    design, f_max, note = _eq15_design(drive, amplitude, frequency, design_response)
    out.update(_design_columns(design, f_max))
    if note is not None:
        return {**out, "note": note}
    opt = velocity.steady_run(drive, amplitude, frequency, "optimized", "refuse", design)
    out.update(optimized_velocity_m_per_s=opt["velocity_m_per_s"],
               gain_m_per_s=opt["velocity_m_per_s"] - saw["velocity_m_per_s"], note=None)
    return out


def with_ringing(table, ringing_rows, frequencies) -> None:
    """Add to each row of ``table`` what the runner's ringing (its record, as
    :func:`passmd.protocols.ringing.ringing_point` gives it) leaves at the row's next fly-back at its
    frequency (:func:`passmd.protocols.ringing.at_frequency`): the ``ringing_*`` columns, in place."""
    rows = [ringing.at_frequency(r, f) for r, f in zip(ringing_rows, frequencies, strict=True)]
    for key in rows[0] if rows else ():
        table[key] = [r[key] for r in rows]


@dataclass(frozen=True)
class MapQuantity:
    """One quantity of a map: its point function, the column it shows, and how to show it."""

    name: str
    function: object
    column: str
    unit: str
    #: the SI value of one ``unit`` (the column is SI)
    scale: float
    label: str
    #: whether the point takes an amplitude (the critical amplitude searches over it)
    amplitude: bool = True
    #: further columns drawn on a one-axis curve (e.g. the closed form)
    also: tuple[str, ...] = ()


#: The quantities of a map by name (``passmd sweep QUANTITY``).
MAP_QUANTITIES = {q.name: q for q in (
    MapQuantity("velocity", steady_point, "velocity_m_per_s", "mm/s", 1e-3, "steady velocity"),
    MapQuantity("step", steady_point, "step_m", "nm", 1e-9, "steady step (velocity / f)"),
    MapQuantity("back-step", steady_point, "back_step_m", "nm", 1e-9, "back-step"),
    MapQuantity("critical-amplitude", critical_amplitude_point, "critical_amplitude_m", "nm", 1e-9,
                "critical amplitude A_c", amplitude=False, also=("analytic_critical_amplitude_m",)),
    MapQuantity("stall-force", stall_point, "generated_force_N", "N", 1.0, "stall force"),
    MapQuantity("gain", gain_point, "gain_m_per_s", "mm/s", 1e-3, "Eq. 15 velocity gain over the saw-tooth"),
)}


def compute_map(quantity: str, points: Sequence[Mapping], *, reading: str = "steady",
                waveform: str = "sawtooth", design_response: str = "paper", config: RunConfig | None = None,
                description: str | None = None) -> pd.DataFrame:
    """``quantity`` (a key of :data:`MAP_QUANTITIES`) at every point.

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
    check_choice("design_response", design_response, eq15.DESIGN_RESPONSES)
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
    :func:`with_ringing`): one probe per drive and amplitude, whatever the
    frequency, so a frequency axis costs one probe."""
    keys = list(dict.fromkeys((c["drive"], c["amplitude"]) for c in calls))
    probes = sweep.run(ringing.ringing_point, [{"drive": d, "amplitude": a} for d, a in keys], config=config,
                       description="runner ringing")
    found = dict(zip(keys, probes.to_dict(orient="records"), strict=True))
    with_ringing(table, [found[(c["drive"], c["amplitude"])] for c in calls], [c["frequency"] for c in calls])
