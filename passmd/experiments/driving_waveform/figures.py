"""Driving waveform, Section 5.1: Eq. 15's waveform against the saw-tooth at 100 Hz (Figs. 8, 9a).

Section 5 drives the six-contact drive with rigid actuators (R = 1 mm, F_p = 0.4 N,
A = 202 nm, μ assumed) with the standard saw-tooth and with the optimized waveform
of Eq. 15 (:func:`passmd.model.optimized_waveform.optimized`), designed once per drive from its own
100 Hz saw-tooth response (:func:`passmd.protocols.eq15.optimized_design`). The runs are those of
:mod:`passmd.protocols.section5`; this module supplies Section 5's unstated μ
(:data:`SECTION5_FRICTION`, the ledger's reading) through :func:`section5_fields`.

Figures (rows of the figure table): ``fig8a`` saw-tooth response with contact status; ``fig8b`` the
optimized waveform with t_s, t_a, Δ_a; ``fig8b_window`` its fly-back and acceleration resolved in
time; ``fig9a`` runner position over three 100 Hz periods, both waveforms. The velocities over
frequency (Figs. 9b, 10) are :mod:`passmd.experiments.waveform_velocity.figures`'s.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from passmd.experiments import FigureSpec, ReadingTable
from passmd.ledger import readings
from passmd.protocols import ringing
from passmd.protocols.section5 import (
    STEP_FREQUENCY,
    WINDOW_RESOLUTION,
    WINDOW_SAMPLES_PER_ACCELERATION,
    design_fields,
    designs,
    full_stroke_flyback,
    section5_drive,
    trace_point,
    window_point,
)
from passmd.protocols.velocity import FULL_SLIDING_SHARE, MIN_PERIODS, STEP_PERIODS
from passmd.runtime import sweep
from passmd.runtime.config import PROFILES, RunConfig
from passmd.runtime.validation import check_choice

#: μ of Section 5 (not stated there): the default of the ledger's axis ``friction_coefficient``.
SECTION5_FRICTION = float(readings.axis("friction_coefficient").default)
#: μ of the Fig. 9a runs: the default and the ledger's evaluated alternatives (Section 4.2's 0.3).
FIG9A_FRICTION = tuple(float(mu) for mu in readings.axis("friction_coefficient").values())


def section5_fields(hemisphere_radius: float = 1e-3, preload: float = 0.4, runner: str = "steel",
                    actuator_model: str = "rigid", friction_coefficient: float = SECTION5_FRICTION) -> dict:
    """A Section 5 drive as the plain sweep parameters of :func:`passmd.protocols.section5.section5_drive`
    (its arguments), by default Section 5's: R = 1 mm, F_p = 0.4 N, steel runner, rigid actuators and
    the ledger's reading of μ (:data:`SECTION5_FRICTION`)."""
    return {"hemisphere_radius": float(hemisphere_radius), "preload": float(preload), "runner": runner,
            "actuator_model": actuator_model, "friction_coefficient": float(friction_coefficient)}


def _trace(c: dict, frequency: float, periods: int, waveform: str, fields: dict, zoom: tuple[float, float],
           full_samples: int, zoom_samples: int, config: RunConfig) -> dict:
    point = {**c, "frequency": float(frequency), "periods": int(periods), "waveform": waveform, **fields,
             "zoom_start": float(zoom[0]), "zoom_end": float(zoom[1]), "full_samples": int(full_samples),
             "zoom_samples": int(zoom_samples)}
    return sweep.run(trace_point, [point], description="trace", config=config).iloc[0].to_dict()


def _status(shares: np.ndarray) -> np.ndarray:
    """Contact status per sample: full slip (a group slides fully), partial slip, stick."""
    top = shares.max(axis=0)
    return np.where(top >= FULL_SLIDING_SHARE, "full slip", np.where(top > 1e-3, "partial slip", "stick"))


def _series_frame(trace: dict, view: str, groups: int) -> pd.DataFrame:
    t = np.asarray(trace[f"{view}_time_s"])
    frame = pd.DataFrame({"view": view, "time_s": t})
    for name in ("piezo_position_m", "runner_position_m", "runner_velocity_m_per_s"):
        frame[name] = np.asarray(trace[f"{view}_{name}"])
    shares = []
    for g in range(1, groups + 1):
        frame[f"slip_share_{g}"] = np.asarray(trace[f"{view}_slip_share_{g}"])
        frame[f"friction_force_{g}_N"] = np.asarray(trace[f"{view}_friction_force_{g}_N"])
        shares.append(frame[f"slip_share_{g}"].to_numpy())
    frame["contact_status"] = _status(np.array(shares))
    return frame


def _points_frame(series: pd.DataFrame, times: dict) -> pd.DataFrame:
    """Rows marking the numbered points of Fig. 8 (interpolated from the zoom series)."""
    zoom = series[series["view"] == "zoom"]
    rows = []
    for label, t in times.items():
        if not np.isfinite(t):
            continue
        row = {"view": "point", "point": label, "time_s": t}
        for col in zoom.columns:
            if col not in ("view", "time_s", "contact_status"):
                row[col] = float(np.interp(t, zoom["time_s"], zoom[col]))
        nearest = int(np.argmin(np.abs(zoom["time_s"].to_numpy() - t)))
        row["contact_status"] = zoom["contact_status"].iloc[nearest]
        rows.append(row)
    return pd.DataFrame(rows)


def _display(frame: pd.DataFrame) -> pd.DataFrame:
    for col in ("piezo_position_m", "runner_position_m", "settled_position_m", "back_step_m"):
        if col in frame:
            frame[col.replace("_m", "_nm")] = frame[col] * 1e9
    frame["time_ms"] = frame["time_s"] * 1e3
    frame["time_us"] = frame["time_s"] * 1e6
    return frame


# ======================================================================================
# Figures 8 and 9a
# ======================================================================================


def _samples(profile: str) -> tuple[int, int]:
    check_choice("profile", profile, PROFILES)
    return (400, 300) if profile == "quick" else (2000, 1500)


def fig8a(config: RunConfig, friction_coefficient: float = SECTION5_FRICTION) -> pd.DataFrame:
    """Saw-tooth response (100 Hz, two periods, Section 5 drive) with the contact status.

    Views: ``full`` (both periods), ``zoom`` (the first fly-back and the micro-vibration
    after it), ``point`` (points 1–4 of Section 5.1: end of stick, fastest backward motion,
    reversal, fastest forward motion). Constant columns: ``first_back_step_m`` and the
    measured ``micro_vibration_frequency_Hz``. ``friction_coefficient``: Section 5's unstated μ.
    """
    c = section5_fields(friction_coefficient=friction_coefficient)
    T = 1.0 / STEP_FREQUENCY
    trace = _trace(c, STEP_FREQUENCY, 2, "sawtooth", {"settling_time": 0.0, "acceleration_time": 0.0,
                                                    "acceleration_amplitude": 0.0},
                   (T - 10e-6, T + 250e-6), *_samples(config.profile), config)
    series = pd.concat([_series_frame(trace, "full", 2), _series_frame(trace, "zoom", 2)], ignore_index=True)
    z1, z2 = trace["turning_times_s"][0], trace["turning_times_s"][1]
    zoom = series[series["view"] == "zoom"]
    t, v = zoom["time_s"].to_numpy(), zoom["runner_velocity_m_per_s"].to_numpy()
    first, second = (t >= T) & (t <= z1), (t >= z1) & (t <= z2)
    times = {"1": trace["flyback_start_s"], "2": float(t[first][np.argmin(v[first])]), "3": float(z1),
             "4": float(t[second][np.argmax(v[second])])}
    frame = pd.concat([series, _points_frame(series, times)], ignore_index=True)
    frame["first_back_step_m"] = float(trace["back_steps_m"][0])
    frame["micro_vibration_frequency_Hz"] = float(trace["micro_vibration_frequency_Hz"])
    return _display(frame)


def fig8b(config: RunConfig, friction_coefficient: float = SECTION5_FRICTION) -> pd.DataFrame:
    """The optimized waveform of the Section 5 drive and the runner's response (100 Hz).

    Period 1 is a saw-tooth, period 2 optimized. Views ``full``, ``zoom`` (the fly-back,
    t_s and t_a) and ``point`` (1: end of stick; 2: fastest backward motion; 3: reversal,
    if within t_s; 4: end of t_s; 5: end of t_a). Constant columns: the design
    (``settling_time_s``, ``acceleration_time_s``, ``acceleration_amplitude_m``,
    ``acceleration_velocity_m_per_s``, ``micro_vibration_frequency_Hz``,
    ``design_runner_velocity_m_per_s`` (V_r of Eq. 15), ``presliding_m``, ``linear_frequency_Hz``).
    ``friction_coefficient``: Section 5's unstated μ.
    """
    c = section5_fields(friction_coefficient=friction_coefficient)
    design = designs([c], config).iloc[0]
    fields = design_fields(design)
    T = 1.0 / STEP_FREQUENCY
    t_s, t_a = fields["settling_time"], fields["acceleration_time"]
    trace = _trace(c, STEP_FREQUENCY, 2, "optimized", fields, (T - 5e-6, T + t_s + t_a + 60e-6),
                   *_samples(config.profile), config)
    series = pd.concat([_series_frame(trace, "full", 2), _series_frame(trace, "zoom", 2)], ignore_index=True)
    z1 = trace["turning_times_s"][0]
    zoom = series[series["view"] == "zoom"]
    t, v = zoom["time_s"].to_numpy(), zoom["runner_velocity_m_per_s"].to_numpy()
    hold = (t >= T) & (t <= min(z1, T + t_s))
    times = {"1": trace["flyback_start_s"], "2": float(t[hold][np.argmin(v[hold])]),
             "3": float(z1) if z1 < T + t_s else math.nan, "4": T + t_s, "5": T + t_s + t_a}
    frame = pd.concat([series, _points_frame(series, times)], ignore_index=True)
    for key in ("settling_time_s", "acceleration_time_s", "acceleration_amplitude_m",
                "acceleration_velocity_m_per_s", "micro_vibration_frequency_Hz", "presliding_m",
                "linear_frequency_Hz"):
        frame[key] = float(design[key])
    # the design's V_r under its own name: the series' runner_velocity_m_per_s is the run's
    frame["design_runner_velocity_m_per_s"] = float(design["runner_velocity_m_per_s"])
    return _display(frame)


def fig8b_window(config: RunConfig, friction_coefficient: float = SECTION5_FRICTION) -> pd.DataFrame:
    """The fly-back and the acceleration t_a of Fig. 8b's optimized period, resolved inside t_a.

    One run of the Section 5 drive (0.4 N, 100 Hz, its own Eq. 15 design) integrated with the
    step divided by :data:`~passmd.protocols.section5.WINDOW_RESOLUTION` and
    recorded every t_a /
    :data:`~passmd.protocols.section5.WINDOW_SAMPLES_PER_ACCELERATION`
    (:func:`~passmd.protocols.section5.window_point`). Columns: ``time_s``,
    ``time_us``, runner and piezo positions (nm) and velocity, ``slip_share_1`` and
    ``slip_share_2``, ``phase`` (``flyback``, ``settling``, ``acceleration``, ``after``) and
    the constant phase times (s) and record spacing. ``friction_coefficient``: Section 5's unstated μ.
    """
    c = section5_fields(friction_coefficient=friction_coefficient)
    fields = design_fields(designs([c], config).iloc[0])
    point = {**c, **fields, "resolution": WINDOW_RESOLUTION[config.profile],
             "samples_per_acceleration": WINDOW_SAMPLES_PER_ACCELERATION}
    run = sweep.run(window_point, [point], description="fly-back window", config=config).iloc[0].to_dict()
    t = np.asarray(run["time_s"])
    frame = pd.DataFrame({"time_s": t, "time_us": t * 1e6})
    for name in ("runner_velocity_m_per_s", "runner_position_m", "piezo_position_m", "slip_share_1",
                 "slip_share_2"):
        frame[name] = np.asarray(run[name])
    frame["runner_position_nm"] = frame["runner_position_m"] * 1e9
    frame["piezo_position_nm"] = frame["piezo_position_m"] * 1e9
    marks = {k: float(run[k]) for k in ("flyback_start_s", "flyback_end_s", "acceleration_start_s",
                                       "acceleration_end_s", "record_spacing_s")}
    frame["phase"] = np.select(
        [t < marks["flyback_start_s"], t <= marks["flyback_end_s"], t < marks["acceleration_start_s"],
         t <= marks["acceleration_end_s"]], ["before", "flyback", "settling", "acceleration"], "after")
    for key, value in marks.items():
        frame[key] = value
    frame["wall_time_s"] = float(run["wall_time_s"])
    return frame


def fig9a(config: RunConfig) -> pd.DataFrame:
    """Three 100 Hz periods from rest with both waveforms (Section 5 drive, Fig. 9a).

    Views per ``waveform``: ``full`` (time series), ``period`` (``period`` 1–3 with
    ``settled_position_m`` and ``back_step_m``). Constant columns per waveform:
    ``final_position_m`` (settled position after three periods) and
    ``micro_vibration_frequency_Hz`` (after the first fly-back for the saw-tooth, after the
    first acceleration for the optimized waveform).

    ``friction_coefficient`` tags each run: μ = 0.2 (the figure) and the evaluated alternatives
    of the ledger's axis ``friction_coefficient`` (:data:`FIG9A_FRICTION`), each with its own
    Eq. 15 design.
    """
    full, _ = _samples(config.profile)
    parts = []
    for mu in FIG9A_FRICTION:
        c = section5_fields(friction_coefficient=mu)
        fields = design_fields(designs([c], config).iloc[0])
        for waveform in ("sawtooth", "optimized"):
            trace = _trace(c, STEP_FREQUENCY, STEP_PERIODS, waveform, fields, (0.0, 1e-3), full, 2, config)
            series = _series_frame(trace, "full", 2)
            settled = np.asarray(trace["settled_positions_m"])
            per = pd.DataFrame({"view": "period", "period": np.arange(1, settled.size + 1),
                                "time_s": np.arange(1, settled.size + 1) / STEP_FREQUENCY,
                                "settled_position_m": settled,
                                "back_step_m": np.asarray(trace["back_steps_m"])})
            frame = pd.concat([series, per], ignore_index=True)
            frame["waveform"] = waveform
            frame["friction_coefficient"] = mu
            frame["section5_friction"] = mu == SECTION5_FRICTION
            frame["final_position_m"] = float(settled[-1])
            frame["micro_vibration_frequency_Hz"] = float(trace["micro_vibration_frequency_Hz"])
            parts.append(frame)
    return _display(pd.concat(parts, ignore_index=True))


def at_section5_friction(frame: pd.DataFrame, friction_coefficient: float = SECTION5_FRICTION
                         ) -> pd.DataFrame:
    """The rows of a table tagged with ``friction_coefficient`` at one μ (default: Section 5's 0.2)."""
    return frame[np.isclose(frame["friction_coefficient"], friction_coefficient, rtol=1e-9, atol=0)]


# ======================================================================================
# The ledger's readings of Section 5.1: every figure at every value of μ
# ======================================================================================


def at_every_mu(compute):
    """A readings table: ``compute(config, friction_coefficient=μ)`` at every value of the ledger's axis
    ``friction_coefficient`` (Section 5's unstated μ), tagged with it."""

    def readings_table(config: RunConfig) -> pd.DataFrame:
        parts = [compute(config, friction_coefficient=mu).assign(friction_coefficient=mu)
                 for mu in FIG9A_FRICTION]
        return pd.concat(parts, ignore_index=True)

    readings_table.__name__ = readings_table.__qualname__ = f"{compute.__name__}_readings"
    readings_table.__doc__ = (f"{compute.__name__} at every value of μ (ledger readings), tagged "
                              "``friction_coefficient``.")
    return readings_table


def ringing_point(hemisphere_radius: float, preload: float, runner: str, actuator_model: str,
                  friction_coefficient: float, frequency: float) -> dict:
    """The ringing after the first fly-back of a full-stroke saw-tooth of a Section 5 drive at
    ``frequency`` (:func:`passmd.protocols.ringing.ringing_point`)."""
    drive = section5_drive(hemisphere_radius, preload, runner, actuator_model, friction_coefficient)
    return ringing.ringing_point(drive, drive.actuator.full_stroke_amplitude, frequency)


def fig8a_ringing(config: RunConfig, friction_coefficient: float = SECTION5_FRICTION) -> pd.DataFrame:
    """The runner's micro-vibration after Fig. 8a's first fly-back (100 Hz, the Section 5 drive), one row:
    its frequency, first swing (``ringing_amplitude_m``), 1/e decay time, and the swing left when the next
    fly-back starts, at the end of the following stick phase (``ringing_at_next_flyback_m``,
    :func:`passmd.protocols.ringing.at_frequency`), with the smallest swing a step measurement resolves
    (``measurable_m``). ``friction_coefficient``: Section 5's unstated μ."""
    c = section5_fields(friction_coefficient=friction_coefficient)
    run = sweep.run(ringing_point, [{**c, "frequency": STEP_FREQUENCY}], description="ringing",
                    config=config).iloc[0].to_dict()
    left = ringing.at_frequency(run, STEP_FREQUENCY)
    return pd.DataFrame([{
        "frequency_Hz": STEP_FREQUENCY, "ringing_frequency_Hz": float(run["ringing_frequency_Hz"]),
        "ringing_amplitude_m": float(run["ringing_amplitude_m"]),
        "ringing_decay_time_s": float(run["ringing_decay_time_s"]),
        "next_flyback_after_s": float(left["next_flyback_after_s"]),
        "ringing_at_next_flyback_m": float(left["ringing_at_next_flyback_m"]),
        "ringing_hold_s": float(run["ringing_hold_s"]), "measurable_m": ringing.MEASURABLE,
        "swings": int(np.asarray(run["swing_amplitudes_m"]).size),
    }])


fig8a_readings, fig8b_readings, fig8b_window_readings, fig8a_ringing_readings = (
    at_every_mu(f) for f in (fig8a, fig8b, fig8b_window, fig8a_ringing))


def _settling_response(trace: dict, flyback_end: float, settling_time: float) -> dict:
    """The runner's micro-vibration after a fly-back, from a zoomed trace reaching 1.5 t_s past it: its
    largest speed over the settling time t_s, the time of its reversal (its velocity's first sign
    change after the fly-back, which t_s is meant to land on) and its velocity where t_a starts (V_r)."""
    t = np.asarray(trace["zoom_time_s"])
    v = np.asarray(trace["zoom_runner_velocity_m_per_s"])
    settling = (t >= flyback_end) & (t <= flyback_end + settling_time)
    around = (t >= flyback_end) & (t <= flyback_end + 1.5 * settling_time)
    tw, vw = t[around], v[around]
    turns = np.flatnonzero(np.sign(vw[:-1]) * np.sign(vw[1:]) < 0)
    reversal = (float(tw[turns[0]] - vw[turns[0]] * (tw[turns[0] + 1] - tw[turns[0]])
                      / (vw[turns[0] + 1] - vw[turns[0]])) - flyback_end) if turns.size else math.nan
    return {"peak_speed_m_per_s": float(np.abs(v[settling]).max()), "reversal_s": reversal,
            "runner_velocity_m_per_s": float(np.interp(flyback_end + settling_time, t, v))}


#: Periods of the response runs: enough for the runner's response to a periodic waveform to settle.
RESPONSE_PERIODS = MIN_PERIODS


def fig9a_response(config: RunConfig) -> pd.DataFrame:
    """The runner's response to the optimized waveform against its response to the saw-tooth, in
    continued operation where a period is too short for the micro-vibration to die out: at the
    frequency whose period is twice Eq. 15's t_s + t_a + fly-back (the ramp gets half of it), over
    the settling time t_s after the last of :data:`RESPONSE_PERIODS` fly-backs, at every value of μ.

    Columns ``friction_coefficient``, ``frequency_Hz``, the design's ``settling_time_s``,
    ``micro_vibration_frequency_Hz`` and ``design_runner_velocity_m_per_s`` (V_r, from the 100 Hz
    saw-tooth), and for the saw-tooth (``sawtooth_*``) and the optimized waveform (``response_*``):
    ``peak_speed_m_per_s`` (the largest runner speed over t_s), ``reversal_s`` (when the runner
    turns after the fly-back) and ``runner_velocity_m_per_s`` (where t_a starts).
    """
    rows = []
    for mu in FIG9A_FRICTION:
        c = section5_fields(friction_coefficient=mu)
        design = designs([c], config).iloc[0]
        fields = design_fields(design)
        t_s = fields["settling_time"]
        needed = t_s + fields["acceleration_time"] + full_stroke_flyback(c)
        frequency = 1.0 / (2.0 * needed)
        last = (RESPONSE_PERIODS - 1) / frequency  # the end of the last fly-back but one period
        zoom = (last - 5e-6, last + 1.5 * t_s + 5e-6)
        none = {"settling_time": 0.0, "acceleration_time": 0.0, "acceleration_amplitude": 0.0}
        sawtooth = _trace(c, frequency, RESPONSE_PERIODS, "sawtooth", none, zoom, 400, 2000, config)
        optimized = _trace(c, frequency, RESPONSE_PERIODS, "optimized", fields, zoom, 400, 2000, config)
        row = {"friction_coefficient": mu, "frequency_Hz": frequency, "settling_time_s": t_s,
               "micro_vibration_frequency_Hz": float(design["micro_vibration_frequency_Hz"]),
               "design_runner_velocity_m_per_s": float(design["runner_velocity_m_per_s"])}
        row.update({f"sawtooth_{k}": v for k, v in _settling_response(sawtooth, last, t_s).items()})
        row.update({f"response_{k}": v for k, v in _settling_response(optimized, last, t_s).items()})
        rows.append(row)
    return pd.DataFrame(rows)


#: The chapter's rows of the figure table.
FIGURES = tuple(FigureSpec(name, title, "driving_waveform", compute, f"driving_waveform:{plot}") for
                name, title, compute, plot in (
    ("fig8a", "Runner response to two saw-tooth periods, with the contact status", fig8a, "plot_fig8a"),
    ("fig8b", "The optimized waveform (Eq. 15) with t_s, t_a and Δ_a", fig8b, "plot_fig8b"),
    ("fig8b_window", "Fig. 8b's fly-back and acceleration t_a, resolved in time", fig8b_window,
     "plot_fig8b_window"),
    ("fig9a", "Runner position over three 100 Hz periods, saw-tooth and optimized", fig9a, "plot_fig9a"),
))

#: The ledger's readings of the chapter's figures: each at every μ.
READING_TABLES = (
    ReadingTable("fig8a_readings", "Fig. 8a at every μ", ("fig8a",), fig8a_readings),
    ReadingTable("fig8a_ringing_readings", "The micro-vibration after Fig. 8a's fly-back, at every μ",
                 ("fig8a",),
                 fig8a_ringing_readings),
    ReadingTable("fig8b_readings", "Fig. 8b at every μ", ("fig8b",), fig8b_readings),
    ReadingTable("fig8b_window_readings", "Fig. 8b's fly-back window at every μ", ("fig8b_window",),
                 fig8b_window_readings),
    ReadingTable("fig9a_response", "The response after an optimized period, at every μ", ("fig9a",),
                 fig9a_response),
)
