"""Claim extractors of Section 5.1: the driving waveform's time series (Figs. 8 and 9a).

Decides the ledger's Section 5.1 rows (``passmd/data/reference/claims.csv``) from the time series
of Figs. 8 and 9a, the resolved fly-back window (``fig8b_window``) and the runner's ringing after
Fig. 8a's fly-back (``fig8a_ringing``), each at the ledger's reading of Section 5's μ (the readings
tables ``fig8a_readings``, ``fig8a_ringing_readings``, ``fig8b_readings``, ``fig8b_window_readings``,
``fig9a_response``): in the saw-tooth's stick phase the runner moves with the hemispheres, the
fly-back makes a back-step and leaves the runner vibrating, and that micro-vibration is (or is not)
damped within the stick phase of the following period (the swing left at the next fly-back); the
response to the optimized waveform against the saw-tooth's it is designed from; the runner moving
backward and reversing within t_s, t_a starting at its velocity maximum, stick during t_a, the
contacts deformed to u_x,max after the fly-back, the runner fastest and the contact spring's energy
largest at the end of t_a, and the runner slipping forward further than the hemispheres move
(Sub-phase II); Fig. 9a's final positions and step increase. Positions are ordered to the
integrator's stated accuracy (the tie rule of :mod:`passmd.ledger.rules`). Section 5.2's velocities
are in :mod:`passmd.experiments.waveform_velocity.claims`. Too few samples in a phase make a claim
inconclusive.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd.experiments.driving_waveform.figures import (
    SECTION5_FRICTION,
    at_section5_friction,
    section5_fields,
)
from passmd.experiments.model_numerics.facts import POSITION_ACCURACY
from passmd.ledger.checks import ClaimFails, NoRun, NotEvaluable, evidence, extractor
from passmd.ledger.readings import default_reading
from passmd.model import theory
from passmd.protocols.section5 import WINDOW_SAMPLES_PER_ACCELERATION, section5_drive
from passmd.protocols.velocity import FULL_SLIDING_SHARE

__all__ = ["fig8b_points", "optimized_period_timing"]


def _fig9a_run(results, waveform: str, reading=None) -> pd.DataFrame:
    """Fig. 9a's per-period rows of one waveform at a ledger reading's μ (default 0.2)."""
    mu = SECTION5_FRICTION if reading is None else float(reading["friction_coefficient"])
    table = at_section5_friction(results["fig9a"], mu)
    rows = table[(table["waveform"] == waveform) & (table["view"] == "period")].sort_values("period")
    if rows.empty:
        raise NoRun(f"no Fig. 9a {waveform} run at μ = {mu:g}")
    return rows


def at_mu(results, key: str, reading) -> pd.DataFrame:
    """The rows of a Section 5 readings table (``<key>_readings``) at a reading's μ."""
    table = results[f"{key}_readings"]
    mu = float(reading["friction_coefficient"])
    rows = table[np.isclose(table["friction_coefficient"], mu, rtol=1e-9, atol=0)]
    if rows.empty:
        raise NoRun(f"no {key} run at μ = {mu:g}")
    return rows.drop(columns="friction_coefficient").reset_index(drop=True)


#: The axis these claims depend on: Section 5's unstated μ.
_AXES = ("friction_coefficient",)
#: What two runner positions must differ by to be ordered (nm): the integrator's stated accuracy.
_POSITION_NM = POSITION_ACCURACY * 1e9


@extractor("fig9a-standard-position-552nm", depends_on=_AXES)
def _fig9a_standard(results, reading):
    return float(_fig9a_run(results, "sawtooth", reading)["settled_position_m"].iloc[-1]) * 1e9


@extractor("fig9a-optimized-position-716nm", depends_on=_AXES)
def _fig9a_optimized(results, reading):
    return float(_fig9a_run(results, "optimized", reading)["settled_position_m"].iloc[-1]) * 1e9


@extractor("fig9a-step-increase-46.8pct", depends_on=_AXES)
def _fig9a_increase(results, reading):
    std = _fig9a_run(results, "sawtooth", reading)["settled_position_m"].to_numpy()
    opt = _fig9a_run(results, "optimized", reading)["settled_position_m"].to_numpy()
    return 100.0 * (opt[-1] - std[-1]) / (std[-1] - std[0])


@extractor("fig9a-optimized-step-larger", depends_on=_AXES)
def _fig9a_step_larger(results, reading):
    steps = {w: float(np.mean(np.diff(_fig9a_run(results, w, reading)["settled_position_m"].to_numpy())))
             * 1e9 for w in ("optimized", "sawtooth")}
    return {"lhs": steps["optimized"], "rhs": steps["sawtooth"], "resolution": _POSITION_NM}


#: Why the Fig. 8a back-step and the full sliding after the fly-back cannot fail: at 202 nm the
#: fly-back is six to ten times the presliding u_x,max of either contact side (31 and 20 nm at
#: 0.4 N, Eq. 10), so every contact slides fully and the friction it transmits while sliding pulls
#: the runner back. u_x,max scales as (E*, G*)^(-2/3), so this holds for any contact down to about
#: a sixteenth of the Table 1 stiffness (checked with E*, G* scaled 0.5x to 100x: back-step
#: 0.07-0.11 nm, both groups at slip share 1).
_FLYBACK_SLIDES = ("holds for any contact stiffness down to a sixteenth of Table 1's at 202 nm: the "
                   "fly-back is six to ten times the presliding u_x,max of either side (Eq. 10), so every "
                   "contact slides fully and drags the runner back; with E*, G* scaled 0.5x to 100x the "
                   "check still holds")


@extractor("fig8a-back-step", depends_on=_AXES, not_informative=_FLYBACK_SLIDES)
def _fig8a_back_step(results, reading):
    return {"lhs": float(at_mu(results, "fig8a", reading)["first_back_step_m"].iloc[0]) * 1e9, "rhs": 0.0,
            "resolution": _POSITION_NM}


#: Why the runner moves with the hemispheres in Fig. 8a's stick phase whatever the model: Section 5's
#: runner is free (no load cell), so on the slow ramp the contacts carry only its inertia, brought to
#: A/T within a cycle of its micro-vibration, over two orders of magnitude below their sliding force.
_RAMP_STICKS = ("the free runner of Section 5 needs, on the slow 100 Hz ramp, only the force of its inertia "
                "(a 3 g runner brought to A/T = 20 µm/s within a cycle of its micro-vibration), over two "
                "orders of magnitude below the contacts' sliding force μ(2F_N1 + 4F_N2): no contact with "
                "static friction lets it slide")


def _first_ramp(results, reading) -> pd.DataFrame:
    """Fig. 8a's full record over the first period's slow ramp (up to point 1, the first fly-back)."""
    table = at_mu(results, "fig8a", reading)
    points = table[table["view"] == "point"].set_index("point")
    points.index = points.index.astype(str)
    full = table[table["view"] == "full"].sort_values("time_s")
    if full.empty or "1" not in points.index:
        raise NotEvaluable("the Fig. 8a trace or its point 1 (end of the first stick phase) is missing")
    return full[full["time_s"] < float(points.at["1", "time_s"])]


@extractor("fig8a-runner-moves-with-hemispheres-in-stick", depends_on=_AXES, not_informative=_RAMP_STICKS)
def _moves_with_hemispheres(results, reading):
    # "moved together": the runner never slides against the hemispheres on the first ramp, its lag behind
    # them staying below the presliding u_x,max of the weaker contact side (Eq. 10)
    ramp = _first_ramp(results, reading)
    lag = np.abs(ramp["piezo_position_m"].to_numpy() - ramp["runner_position_m"].to_numpy()).max() * 1e9
    return {"lhs": float(lag), "rhs": _presliding_nm(reading), "resolution": _POSITION_NM}


def _presliding_nm(reading) -> float:
    """The smaller presliding u_x,max of the two contact sides of the Section 5 drive at a reading's μ
    (nm)."""
    drive = section5_drive(**section5_fields(friction_coefficient=float(reading["friction_coefficient"])))
    return float(np.min(np.asarray(theory.drive_theory(drive)["presliding_m"]))) * 1e9


def _ringing(results, reading) -> pd.Series:
    rows = at_mu(results, "fig8a_ringing", reading)
    return rows.iloc[0]


#: Why the runner vibrates after the slip phase whatever the model: it sits on elastic contacts of
#: tangential stiffness 2aG*, and the fly-back that makes the back-step (fully sliding contacts) leaves it
#: moving: a mass on springs swings.
_SLIP_RINGS = ("a runner on elastic contacts (tangential stiffness 2aG* per contact) that the fly-back "
               "leaves moving (the back-step row: every contact slides fully at 202 nm) swings at "
               "√(k/m_r): every finite contact stiffness gives a micro-vibration after the slip phase")


@extractor("fig8a-runner-vibrates-after-slip", depends_on=_AXES, not_informative=_SLIP_RINGS)
def _vibrates_after_slip(results, reading):
    # the first swing of the micro-vibration after the fly-back against what a step measurement resolves
    row = _ringing(results, reading)
    return {"lhs": float(row["ringing_amplitude_m"]) * 1e9, "rhs": float(row["measurable_m"]) * 1e9}


def optimized_period_timing(results, reading=None) -> dict:
    """Timing of the runner in the optimized period of Fig. 8b (µs), from the zoomed trace at a
    reading's μ (default: the figure's own table).

    ``flyback_end`` (point 4 minus t_s), ``reversal`` (the runner's backward extreme between
    points 2 and 5, Section 5.1's point 3), ``point4`` (end of t_s, start of t_a), ``t_s`` and
    the design's ``f_s`` (Hz). Inconclusive when the trace or the points are missing.
    """
    table = results["fig8b"] if reading is None else at_mu(results, "fig8b", reading)
    points = table[table["view"] == "point"].set_index("point")
    zoom = table[table["view"] == "zoom"].sort_values("time_us")
    if zoom.empty or not {"2", "4", "5"} <= set(points.index.astype(str)):
        raise NotEvaluable("the Fig. 8b trace or its points 2, 4 and 5 are missing")
    points.index = points.index.astype(str)
    t2, t4, t5 = (float(points.at[p, "time_us"]) for p in ("2", "4", "5"))
    t_s = float(points.at["4", "settling_time_s"]) * 1e6
    window = zoom[(zoom["time_us"] >= t2) & (zoom["time_us"] <= t5)]
    if len(window) < 3:
        raise NotEvaluable("fewer than three trace samples between points 2 and 5")
    reversal = float(window.loc[window["runner_position_nm"].idxmin(), "time_us"])
    return {"flyback_end": t4 - t_s, "reversal": reversal, "point4": t4, "t_s": t_s,
            "f_s": float(points.at["4", "micro_vibration_frequency_Hz"])}


def _response(results, reading) -> pd.Series:
    table = results["fig9a_response"]
    rows = table[np.isclose(table["friction_coefficient"], float(reading["friction_coefficient"]), rtol=1e-9,
                            atol=0)]
    if rows.empty:
        raise NoRun(f"no response run at μ = {reading['friction_coefficient']:g}")
    return rows.iloc[0]


@extractor("sec5-response-to-optimized-similar", depends_on=_AXES)
def _response_similar(results, reading):
    # Eq. 15 is designed from the saw-tooth's micro-vibration after a fly-back: how fast the runner
    # moves and when it turns (t_s lands on it). In continued operation, where a period is too short
    # for the vibration to die out, the two waveforms leave the runner in different states: the
    # largest speed over t_s after the last fly-back (mm/s) and, where the runner turns, when (µs),
    # optimized against saw-tooth. A turn in one run and none in the other is a failure outright.
    row = _response(results, reading)
    turns = [bool(np.isfinite(row[f"{w}_reversal_s"])) for w in ("response", "sawtooth")]
    if turns[0] != turns[1]:
        turned = "after the optimized waveform's fly-back" if turns[0] else "after the saw-tooth's"
        raise ClaimFails(f"the runner turns within 1.5 t_s only {turned}: the two responses differ in kind")
    columns = ("peak_speed_m_per_s", "reversal_s") if turns[0] else ("peak_speed_m_per_s",)
    scale = {"peak_speed_m_per_s": 1e3, "reversal_s": 1e6}
    return {side: np.array([row[f"{w}_{c}"] * scale[c] for c in columns])
            for side, w in (("lhs", "response"), ("rhs", "sawtooth"))}


@evidence("sec5-response-to-optimized-similar")
def _response_similar_evidence(results):
    row = _response(results, default_reading())

    def reversal(waveform):
        at = row[f"{waveform}_reversal_s"]
        return f"{at * 1e6:.2f} µs" if np.isfinite(at) else "none within 1.5 t_s"

    return [f"at {row['frequency_Hz'] / 1e3:.3g} kHz, over t_s = {row['settling_time_s'] * 1e6:.2f} µs "
            "after the last fly-back: largest speed "
            f"{row['sawtooth_peak_speed_m_per_s'] * 1e3:.4g} mm/s (saw-tooth) against "
            f"{row['response_peak_speed_m_per_s'] * 1e3:.4g} mm/s (optimized), reversal "
            f"{reversal('sawtooth')} against {reversal('response')}; "
            "V_r "
            f"{row['sawtooth_runner_velocity_m_per_s'] * 1e3:.3g} against "
            f"{row['response_runner_velocity_m_per_s'] * 1e3:.3g} mm/s; f_s = "
            f"{row['micro_vibration_frequency_Hz'] / 1e3:.4g} kHz, set by the runner's mass and its "
            "contacts' stiffness (defaults)"]


@extractor("sec5-1-acceleration-starts-at-velocity-maximum", depends_on=_AXES)
def _acceleration_phase(results, reading):
    timing = optimized_period_timing(results, reading)
    return (timing["point4"] - timing["reversal"]) * 1e-6 * timing["f_s"]


@evidence("sec5-1-acceleration-starts-at-velocity-maximum")
def _acceleration_phase_evidence(results):
    t = optimized_period_timing(results)
    return [f"fly-back ends at {t['flyback_end']:.2f} µs, the runner reverses at {t['reversal']:.2f} µs, "
            f"t_s ends (point 4) at {t['point4']:.2f} µs; f_s = {t['f_s'] / 1e3:.4g} kHz"]


def _window_phase(results, phases: tuple[str, ...], reading=None) -> pd.DataFrame:
    """Rows of the resolved fly-back window (``fig8b_window``) in the given phases, at a reading's μ
    (default: the figure's own table).

    Inconclusive when a phase holds fewer than :data:`WINDOW_SAMPLES_PER_ACCELERATION` // 2
    samples: the record then cannot resolve it.
    """
    table = results["fig8b_window"] if reading is None else at_mu(results, "fig8b_window", reading)
    rows = table[table["phase"].isin(phases)]
    for phase in phases:
        n = int((rows["phase"] == phase).sum())
        if n < WINDOW_SAMPLES_PER_ACCELERATION // 2:
            raise NotEvaluable(f"only {n} recorded samples in the {phase} phase of the fly-back window")
    return rows


@extractor("sec5-1-stick-during-acceleration", depends_on=_AXES)
def _stick_during_acceleration(results, reading):
    # Section 5.1 chooses V_a so that the runner still sticks during t_a: no contact group may
    # reach full sliding (slip share 1) between points 4 and 5. Ours: the share of t_a's record in which
    # one does (%).
    rows = _window_phase(results, ("acceleration",), reading)
    full = rows[["slip_share_1", "slip_share_2"]].to_numpy().max(axis=1) >= FULL_SLIDING_SHARE
    return 100.0 * float(full.mean())


@evidence("sec5-1-stick-during-acceleration")
def _stick_during_acceleration_evidence(results):
    rows = _window_phase(results, ("settling", "acceleration"))
    end_settling = rows[rows["phase"] == "settling"].iloc[-1]
    acc = rows[rows["phase"] == "acceleration"]
    first_full = acc.loc[acc[["slip_share_1", "slip_share_2"]].max(axis=1) >= FULL_SLIDING_SHARE, "time_s"]
    start = float(acc["acceleration_start_s"].iloc[0])
    lines = [f"slip shares at the end of t_s: side 1 {end_settling['slip_share_1']:.2f}, side 2 "
             f"{end_settling['slip_share_2']:.2f}"]
    if len(first_full):
        lines.append(f"a contact group slides fully {(float(first_full.iloc[0]) - start) * 1e9:.0f} ns into "
                     f"t_a = {(float(acc['acceleration_end_s'].iloc[0]) - start) * 1e9:.0f} ns")
    return lines


@extractor("sec5-1-spring-deformed-to-ux-max-after-flyback", depends_on=_AXES,
           not_informative=_FLYBACK_SLIDES)
def _deformed_to_ux_max(results, reading):
    # The contact's tangential displacement reaches u_x,max exactly when the whole contact slides
    # (slip share 1); every contact group must get there between the fly-back and the end of t_s.
    rows = _window_phase(results, ("flyback", "settling"), reading)
    return float(rows[["slip_share_1", "slip_share_2"]].max(axis=0).min())


@extractor("sec5-1-fastest-at-end-of-acceleration", depends_on=_AXES)
def _fastest_at_point5(results, reading):
    # Section 5.1: at point 5 (end of t_a) the runner has its highest velocity. The time of the
    # runner's largest forward velocity from point 4 to the end of the window, after point 5, in
    # units of t_a; a maximum at the window's last sample does not locate it (inconclusive).
    rows = _window_phase(results, ("acceleration", "after"), reading)
    v = rows["runner_velocity_m_per_s"].to_numpy()
    k = int(np.argmax(v))
    if k == v.size - 1:
        raise NotEvaluable("the runner's velocity is largest at the last sample of the window")
    row = rows.iloc[0]
    t_a = float(row["acceleration_end_s"] - row["acceleration_start_s"])
    return (float(rows["time_s"].iloc[k]) - float(row["acceleration_end_s"])) / t_a


@evidence("sec5-1-fastest-at-end-of-acceleration")
def _fastest_at_point5_evidence(results):
    rows = _window_phase(results, ("acceleration", "after"))
    acc = rows[rows["phase"] == "acceleration"]
    k = int(np.argmax(rows["runner_velocity_m_per_s"].to_numpy()))
    return [f"runner velocity at point 5: {acc['runner_velocity_m_per_s'].iloc[-1] * 1e3:.3f} mm/s; largest, "
            f"{rows['runner_velocity_m_per_s'].iloc[k] * 1e3:.3f} mm/s, "
            f"{(rows['time_s'].iloc[k] - acc['acceleration_end_s'].iloc[0]) * 1e6:.2f} µs after point 5"]


def fig8b_points(results, reading, needed: tuple[str, ...]) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Fig. 8b's numbered points (indexed by their label) and its zoomed trace (by time) at a reading's
    μ; inconclusive when the trace or one of the ``needed`` points is missing."""
    table = at_mu(results, "fig8b", reading)
    points = table[table["view"] == "point"].set_index("point")
    points.index = points.index.astype(str)
    zoom = table[table["view"] == "zoom"].sort_values("time_us")
    if zoom.empty or not set(needed) <= set(points.index):
        raise NotEvaluable(f"the Fig. 8b trace or its points {' and '.join(needed)} are missing")
    return points, zoom


@extractor("sec5-1-runner-overshoots-in-slip", depends_on=_AXES)
def _overshoot(results, reading):
    # Sub-phase II: from point 4 to the runner's forward extreme after point 5, the runner moves
    # further than the hemispheres do over the same time (the acceleration Δ_a included).
    points, zoom = fig8b_points(results, reading, ("4", "5"))
    after = zoom[zoom["time_us"] >= float(points.at["5", "time_us"])]
    if len(after) < 3:
        raise NotEvaluable("fewer than three trace samples after point 5")
    k = int(np.argmax(after["runner_position_nm"].to_numpy()))
    if k == len(after) - 1:
        raise NotEvaluable("the runner is still moving forward at the last sample of the trace")
    start, extreme = points.loc["4"], after.iloc[k]
    return {"lhs": float(extreme["runner_position_nm"] - start["runner_position_nm"]),
            "rhs": float(extreme["piezo_position_nm"] - start["piezo_position_nm"]),
            "resolution": _POSITION_NM}


@extractor("sec5-1-runner-backward-then-reverses", depends_on=_AXES)
def _backward_then_reverses(results, reading):
    # Sub-phase I: at point 2 the runner moves backward, at point 3 it starts to reverse, both within the
    # settling time t_s (before point 4). Ours: when, after the fly-back, the runner's velocity first turns
    # forward, against t_s (µs); the record's spacing is the resolution.
    points, zoom = fig8b_points(results, reading, ("2", "4"))
    v2 = float(points.at["2", "runner_velocity_m_per_s"])
    if v2 >= 0:
        raise ClaimFails("the runner does not move backward after the fly-back: its slowest velocity "
                         f"within t_s is {v2 * 1e3:.3g} mm/s")
    t_s = float(points.at["4", "settling_time_s"]) * 1e6
    start = float(points.at["4", "time_us"]) - t_s
    after = zoom[zoom["time_us"] >= float(points.at["2", "time_us"])]
    forward = after[after["runner_velocity_m_per_s"] >= 0]
    turn = (float(forward["time_us"].iloc[0]) if len(forward) else float(after["time_us"].iloc[-1])) - start
    return {"lhs": turn, "rhs": t_s, "resolution": float(np.diff(zoom["time_us"].to_numpy()).max())}


@extractor("sec5-1-potential-energy-maximal-at-point-5", depends_on=_AXES)
def _potential_energy_at_point5(results, reading):
    # Sub-phase II: at point 5 (end of t_a) "the potential energy due to the deformation of the spring" is
    # maximal. In the paper's one-spring picture of the contacts it is F²/2k, F the force the contact springs
    # exert on the free runner, m_r times its acceleration. Ours: how far below its largest value from point 4
    # to the end of the window that energy lies at point 5 (% of the largest): 0 where it is largest there.
    rows = _window_phase(results, ("acceleration", "after"), reading)
    t = rows["time_s"].to_numpy()
    force = np.gradient(rows["runner_velocity_m_per_s"].to_numpy(), t)  # ∝ F (m_r constant)
    end = float(rows["acceleration_end_s"].iloc[0])
    at5 = float(np.interp(end, t, force))
    largest = float(force.max())
    if largest <= 0:
        raise ClaimFails("the contact springs never push the runner forward from point 4 on")
    return 100.0 * (1.0 - min(max(at5, 0.0) / largest, 1.0) ** 2)


@extractor("fig8a-micro-vibration-damped-within-next-stick", depends_on=_AXES)
def _micro_vibration_damped(results, reading):
    # "completely damped within the stick phase of the following period": the swing of the runner's
    # micro-vibration left when the next fly-back starts (the end of the following slow ramp), against the
    # smallest swing a step measurement resolves (the measurable step of the A_c search)
    row = _ringing(results, reading)
    if not row["swings"]:
        raise NotEvaluable("no swing of the runner after the fly-back to follow")
    return {"lhs": float(row["ringing_at_next_flyback_m"]) * 1e9, "rhs": float(row["measurable_m"]) * 1e9}


@evidence("fig8a-micro-vibration-damped-within-next-stick")
def _micro_vibration_evidence(results):
    row = _ringing(results, default_reading())
    decay = row["ringing_decay_time_s"]
    return [f"first swing {row['ringing_amplitude_m'] * 1e9:.3g} nm at "
            f"{row['ringing_frequency_Hz'] / 1e3:.4g} "
            f"kHz; it falls to 1/e "
            + (f"in {decay * 1e6:.3g} µs" if np.isfinite(decay) else
               f"not within the {row['ringing_hold_s'] * 1e3:.3g} ms recorded")
            + f"; {row['ringing_at_next_flyback_m'] * 1e9:.3g} nm left when the next fly-back starts, "
            f"{row['next_flyback_after_s'] * 1e3:.3g} ms after the first (defaults)"]
