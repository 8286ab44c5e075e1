"""Every claim check can fail: each informative extractor has a counter-example on which it fails.

A counter-example is the quick profile's result tables with one quantity changed the way the
claim forbids (a constructed result), or the default model run itself where that run already
contradicts the paper (named "default model run"). The extractor reads it and
:func:`passmd.ledger.checks.check_claim` must report a failure (or the extractor decides the claim
against the paper with :class:`passmd.ledger.checks.ClaimFails`); an undecided counter-example
(:class:`passmd.ledger.checks.NotEvaluable`) does not count.

Claims whose check holds by construction are marked ``not_informative`` on their extractor with
the reason, checked here by computation; claims about the experiment, whose data the paper's
text does not give, are always inconclusive.
"""

import math

import numpy as np
import pandas as pd
import pytest

from passmd.experiments.driving_waveform.figures import section5_fields
from passmd.experiments.force_generation.figures import EARLIER, THIS
from passmd.experiments.waveform_velocity.claims import (
    _located,
    _maxima,
    _scoped,
    controllable_maximum,
    eq15_scope,
    maximum_location,
    stick_edge,
)
from passmd.experiments.waveform_velocity.figures import FREQUENCIES
from passmd.ledger import checks, readings, reference
from passmd.ledger.checks import NO_MEASURED_DATA, ClaimFails, NotEvaluable, check_claim
from passmd.ledger.claims import load_claims
from passmd.model import theory
from passmd.protocols.section5 import section5_drive
from passmd.report import evaluation
from passmd.runtime.config import RunConfig

#: Claims about the experiment of [12]: inconclusive whatever the model computes (passmd.ledger.rules).
EXPERIMENT_CLAIMS = (
    "abstract-agreement-with-experiment",
    "fig6b-experiment-agreement",
    "fig7-critical-amplitude-both-models",
    "fig7-flexible-covers-experiment",
    "fig7a-force-difference-115mn",
    "fig7a-discrepancy-grows-with-amplitude",
    "fig7b-discrepancy-grows-with-amplitude",
    "sec4-2-friction-and-actuator-dynamics-cause-discrepancy",
    "sec4-2-other-preloads-same-trend",
)


# ======================================================================================
# Building counter-examples from the quick tables
# ======================================================================================


def _edit(results: dict, key: str, change) -> dict:
    """A shallow copy of ``results`` whose table ``key`` is ``change(copy of the table)``."""
    out = dict(results)
    out[key] = change(results[key].copy())
    return out


def _scale(key: str, column: str, factor: float, **where):
    def change(t):
        t.loc[_rows(t, **where), column] = t.loc[_rows(t, **where), column] * factor
        return t

    return lambda r: _edit(r, key, change)


def _rows(t: pd.DataFrame, **where) -> pd.Series:
    sel = pd.Series(True, index=t.index)
    for column, value in where.items():
        sel &= np.isclose(t[column], value) if isinstance(value, float) else (t[column] == value)
    return sel


def _model(t: pd.DataFrame, model: tuple) -> pd.Series:
    return (t["actuator_model"] == model[0]) & np.isclose(t["friction_coefficient"], model[1])


def _closed_form_as_ac(key: str, column: str):
    """A_c replaced by one closed-form curve (e.g. a single side's presliding), in the readings table."""
    curve = reference.load_reference_curve(f"{key}_closed_form")

    def change(t):
        t["critical_amplitude_nm"] = np.interp(t["preload_N"], curve["preload_N"], curve[column])
        return t

    return lambda r: _edit(r, f"{key}_readings", change)


def _six_contacts_as_one_side(results):
    """Six-contact A_c (Fig. 6b) set to the one-contact A_c (Fig. 5b) at the side-2 normal force F_N2
    (Eq. 1), the same reading: the interaction changes nothing."""
    keys = ["protocol", "flyback", "frequency_Hz", "damping_ratio", "friction_coefficient"]
    one = results["fig5b_readings"]
    one = one[one["actuator_model"] == "flexible"]

    def change(t):
        for i, row in t.iterrows():
            same = one[np.logical_and.reduce([one[k] == row[k] for k in keys])].sort_values("preload_N")
            f2 = theory.normal_forces(np.array([row["preload_N"]]), contacts=6)[1][0]
            t.at[i, "critical_amplitude_nm"] = np.interp(f2, same["preload_N"], same["critical_amplitude_nm"])
        return t

    return _edit(results, "fig6b_readings", change)


def _force_not_depending(on: str):
    """This paper's force the same at half and full stroke (``amplitude``), or at both preloads of each
    panel (``preload``), in the readings table."""
    varied = "preload_N" if on == "amplitude" else "amplitude_fraction"

    def change(t):
        for _, rows in t.groupby(["flyback", "damping_ratio", "frequency_Hz", "radius_mm", varied]):
            t.loc[rows.index, "generated_force_mN"] = float(rows["generated_force_mN"].mean())
        return t

    return lambda r: _edit(r, "fig7_readings", change)


def _flexible_force_for_rigid(key: str, offset_per_nm: float = 0.0):
    """The earlier model's F_gen set to this paper's minus ``offset_per_nm`` · amplitude."""

    def change(t):
        for preload in t["preload_N"].unique():
            this = t[_model(t, THIS) & np.isclose(t["preload_N"], preload)].set_index("amplitude_fraction")
            earlier = _model(t, EARLIER) & np.isclose(t["preload_N"], preload)
            fractions = t.loc[earlier, "amplitude_fraction"]
            t.loc[earlier, "generated_force_mN"] = (
                this.loc[fractions, "generated_force_mN"].to_numpy()
                - offset_per_nm * t.loc[earlier, "amplitude_nm"].to_numpy()
            )
        return t

    return lambda r: _edit(r, key, change)


def _rigid_onset_doubled(results):
    out = results
    for key in ("fig7a", "fig7b"):

        def change(t):
            for preload in t["preload_N"].unique():
                at = np.isclose(t["preload_N"], preload)
                t.loc[at & _model(t, EARLIER), "onset_nm"] = 2 * float(
                    t.loc[at & _model(t, THIS), "onset_nm"].iloc[0]
                )
            return t

        out = _edit(out, key, change)
    return out


def _cycle_without_friction_part(results):
    def change(t):
        rigid_02 = float(t.loc[_model(t, ("rigid", 0.2)), "generated_force_mN"].iloc[0])
        t.loc[_model(t, ("rigid", 0.3)), "generated_force_mN"] = rigid_02 - 10.0
        return t

    return _edit(results, "fig7cycle", change)


def _earlier_below_at_full_stroke(results):
    def change(t):
        t.loc[_model(t, EARLIER) & np.isclose(t["amplitude_fraction"], 1.0), "generated_force_mN"] = 0.0
        return t

    return _edit(results, "fig7grid", change)


def _fig9a(change_rows):
    def change(t):
        return change_rows(t)

    return lambda r: _edit(r, "fig9a", change)


def _optimized_as_sawtooth(t):
    """Fig. 9a's optimized periods replaced by the saw-tooth's (no gain at all)."""
    for mu in t["friction_coefficient"].unique():
        at = np.isclose(t["friction_coefficient"], mu) & (t["view"] == "period")
        saw = t[at & (t["waveform"] == "sawtooth")].sort_values("period")
        opt = t[at & (t["waveform"] == "optimized")].sort_values("period")
        t.loc[opt.index, "settled_position_m"] = saw["settled_position_m"].to_numpy()
    return t


def _series_values(key: str, column: str, values, variant: str = "optimized", **where):
    """``column`` of one series of a velocity readings table set to ``values(frequency_kHz)`` (every μ)."""

    def change(t):
        sel = _rows(t, variant=variant, **where)
        t.loc[sel, column] = values(t.loc[sel, "frequency_kHz"].to_numpy())
        return t

    return lambda r: _edit(r, f"{key}_readings", change)


def _regrid(key: str):
    """A velocity readings table moved onto the paper's frequency grid (each series interpolated
    linearly, flags from the nearest quick frequency): the Fig. 10 claims need the whole grid."""
    paper = FREQUENCIES["paper"]

    def change(t):
        series = []
        labels = ["friction_coefficient", "variant", "preload", "hemisphere_radius", "runner"]
        for _, rows in t.groupby(labels):
            rows = rows.sort_values("frequency")
            new = pd.DataFrame({"frequency": paper})
            for column in rows.columns:
                if column == "frequency":
                    continue
                values = rows[column].to_numpy()
                if rows[column].dtype.kind == "f":
                    new[column] = np.interp(paper, rows["frequency"], values)
                else:
                    nearest = np.abs(paper[:, None] - rows["frequency"].to_numpy()[None, :]).argmin(axis=1)
                    new[column] = values[nearest]
            new["frequency_kHz"] = paper / 1e3
            series.append(new)
        return pd.concat(series, ignore_index=True)

    return lambda r: _edit(r, f"{key}_readings", change)


def _peak(at_kHz: float, height: float):
    """A velocity curve over the grid with its only maximum, ``height``, at ``at_kHz``."""
    return lambda f: height - 0.01 * np.abs(f - at_kHz)


def _chain(*steps):
    def build(results):
        for step in steps:
            results = step(results)
        return results

    return build


def _optimized_from_sawtooth(offset: float):
    """Fig. 9b's optimized velocities set to the saw-tooth's plus ``offset`` (mm/s), at every μ."""

    def change(t):
        for _, rows in t.groupby("friction_coefficient"):
            saw = rows[rows["variant"] == "sawtooth"].set_index("frequency_kHz")["velocity_mm_per_s"]
            opt = rows.index[rows["variant"] == "optimized"]
            t.loc[opt, "velocity_mm_per_s"] = saw.loc[t.loc[opt, "frequency_kHz"]].to_numpy() + offset
        return t

    return lambda r: _edit(r, "fig9b_readings", change)


def _frozen_runner_after_point4(results):
    """Fig. 8b's runner held where it is at point 4 (it never slips forward), at every μ."""

    def change(t):
        for _, rows in t.groupby("friction_coefficient"):
            point4 = rows[(rows["view"] == "point") & (rows["point"].astype(str) == "4")].iloc[0]
            later = rows.index[(rows["view"] == "zoom") & (rows["time_us"] >= point4["time_us"])]
            t.loc[later, "runner_position_nm"] = point4["runner_position_nm"]
        return t

    return _edit(results, "fig8b_readings", change)


def _runner_frozen_on_first_ramp(results):
    """Fig. 8a's runner left at rest while the hemispheres ramp (it slides on them), at every μ."""

    def change(t):
        t.loc[t["view"] == "full", "runner_position_m"] = 0.0
        return t

    return _edit(results, "fig8a_readings", change)


def _runner_forward_after_flyback(results):
    """Fig. 8b's runner moving forward from the fly-back on (never backward), at every μ."""

    def change(t):
        t.loc[:, "runner_velocity_m_per_s"] = np.abs(t["runner_velocity_m_per_s"]) + 1e-6
        return t

    return _edit(results, "fig8b_readings", change)


def _push_peaks_after_point5(results):
    """The runner's acceleration in Fig. 8b's window largest 10 t_a after point 5: its velocity a ramp
    there, steep after point 5 and flat before."""

    def change(t):
        end, start = t["acceleration_end_s"], t["acceleration_start_s"]
        t_a = end - start
        x = (t["time_s"] - end) / t_a
        t.loc[:, "runner_velocity_m_per_s"] = np.where(x < 5, 1e-3 * x, 5e-3 + 1e-2 * (x - 5))
        return t

    return _edit(results, "fig8b_window_readings", change)


#: claim id -> (what the counter-example is, how it is built from the quick results).
COUNTER_EXAMPLES = {
    # Section 3.2
    "sec3-2-mdr-reproduces-3d-contact": (
        "the MDR normal force √2 off Hertz (R_1 = R instead of R/2)",
        lambda r: _edit(r, "mdr_normal", lambda t: t.assign(rel_error_1000=np.sqrt(2.0) - 1.0)),
    ),
    # Section 4.1
    "fig5a-no-step-below-50nm": (
        "a 1 µm step at every amplitude",
        lambda r: _edit(r, "fig5a_readings", lambda t: t.assign(steady_step_nm=1e3, first_step_nm=1e3)),
    ),
    "fig5a-step-grows-above-ac": (
        "the step falling with the amplitude above A_c (on the paper's amplitude grid)",
        lambda r: _edit(r, "fig5a_readings", lambda t: t.assign(
            steady_step_nm=np.where(t["amplitude_nm"] > 60, 300.0 - t["amplitude_nm"], 0.0),
            first_step_nm=np.where(t["amplitude_nm"] > 60, 300.0 - t["amplitude_nm"], 0.0))),
    ),
    "fig5b-rigid-ac-matches-eq7": (
        "rigid A_c 1.5 times larger",
        _scale("fig5b_readings", "critical_amplitude_nm", 1.5),
    ),
    "fig5b-flexible-ac-matches-eq8": (
        "flexible A_c 1.5 times larger",
        _scale("fig5b_readings", "critical_amplitude_nm", 1.5),
    ),
    "fig5b-flexible-above-rigid": (
        "flexible A_c a hundredth of its value",
        _scale("fig5b_readings", "critical_amplitude_nm", 0.01, actuator_model="flexible"),
    ),
    "fig6a-rigid-ac-matches-eq11": (
        "A_c 1.5 times larger",
        _scale("fig6a_readings", "critical_amplitude_nm", 1.5),
    ),
    "fig6a-rigid-ac-not-eq10": (
        "A_c equal to the side-1 presliding u_x,max,1",
        _closed_form_as_ac("fig6a", "u_x_max_1_nm"),
    ),
    "fig6b-flexible-r1-ac-matches-eq12": (
        "A_c 1.5 times larger",
        _scale("fig6b_readings", "critical_amplitude_nm", 1.5),
    ),
    "fig6c-flexible-r025-ac-matches-eq12": (
        "A_c 1.5 times larger",
        _scale("fig6c_readings", "critical_amplitude_nm", 1.5),
    ),
    "fig6b-flexible-r1-ac-not-eq13": (
        "A_c equal to u*_x,max,1 (Eq. 13)",
        _closed_form_as_ac("fig6b", "u_x_max_1_star_nm"),
    ),
    "fig6c-flexible-r025-ac-not-eq13": (
        "A_c equal to u*_x,max,2 (Eq. 13)",
        _closed_form_as_ac("fig6c", "u_x_max_2_star_nm"),
    ),
    "sec4-1-interaction-changes-ac": (
        "six-contact A_c equal to one side's contact alone (one contact at F_N2)",
        _six_contacts_as_one_side,
    ),
    # Section 4.2: this paper's force, and the studies of the earlier model against it
    "fig7-force-depends-on-amplitude": (
        "the same force at half and full stroke",
        _force_not_depending("amplitude"),
    ),
    "fig7-force-depends-on-preload": (
        "the same force at both preloads of a panel",
        _force_not_depending("preload"),
    ),
    "sec4-2-force-depends-on-radius-friction-material": (
        "the same force with R, μ or the runner changed",
        lambda r: _edit(r, "fig7_dependence_readings", lambda t: t.assign(
            generated_force_mN=t.groupby(["flyback", "damping_ratio", "frequency_Hz", "pair"])[
                "generated_force_mN"].transform("mean"))),
    ),
    "study-fig7a-model-difference-115mn": (
        "the earlier model's F_gen equal to this paper's",
        _flexible_force_for_rigid("fig7a"),
    ),
    "study-fig7a-model-difference-grows": (
        "a difference falling with the amplitude",
        _flexible_force_for_rigid("fig7a", offset_per_nm=1.0),
    ),
    "study-fig7b-model-difference-grows": (
        "a difference falling with the amplitude",
        _flexible_force_for_rigid("fig7b", offset_per_nm=1.0),
    ),
    "study-fig7-onsets-earlier-against-this-model": (
        "the rigid onsets twice the flexible ones",
        _rigid_onset_doubled,
    ),
    "study-fig7-friction-and-actuators-lower-force": (
        "the rigid force at μ 0.3 10 mN below μ 0.2's (equal forces would be a tie)",
        _cycle_without_friction_part,
    ),
    "study-fig7-earlier-model-above-at-every-preload": (
        "the earlier model's full-stroke force 0 at every preload",
        _earlier_below_at_full_stroke,
    ),
    # Section 5.1
    "sec5-response-to-optimized-similar": (
        "the runner turning as under the saw-tooth but 1.5 times faster",
        lambda r: _edit(r, "fig9a_response", lambda t: t.assign(
            response_peak_speed_m_per_s=1.5 * t["sawtooth_peak_speed_m_per_s"],
            response_reversal_s=t["sawtooth_reversal_s"])),
    ),
    "sec5-1-acceleration-starts-at-velocity-maximum": ("default model run", lambda r: r),
    "sec5-1-stick-during-acceleration": ("default model run", lambda r: r),
    "sec5-1-fastest-at-end-of-acceleration": ("default model run", lambda r: r),
    "sec5-1-runner-overshoots-in-slip": ("the runner frozen from point 4 on", _frozen_runner_after_point4),
    "fig8a-micro-vibration-damped-within-next-stick": (
        "a 10 nm swing left at the next fly-back",
        lambda r: _edit(r, "fig8a_ringing_readings", lambda t: t.assign(ringing_at_next_flyback_m=10e-9)),
    ),
    "fig8a-back-step": (
        "the runner stepping 1 nm forward in the fly-back",
        lambda r: _edit(r, "fig8a_readings", lambda t: t.assign(first_back_step_m=-1e-9)),
    ),
    "fig8a-runner-moves-with-hemispheres-in-stick": (
        "the runner left at rest while the hemispheres ramp",
        _runner_frozen_on_first_ramp,
    ),
    "fig8a-runner-vibrates-after-slip": (
        "no swing after the fly-back",
        lambda r: _edit(r, "fig8a_ringing_readings", lambda t: t.assign(ringing_amplitude_m=0.0)),
    ),
    "sec5-1-runner-backward-then-reverses": (
        "the runner moving forward from the fly-back on",
        _runner_forward_after_flyback,
    ),
    "sec5-1-potential-energy-maximal-at-point-5": (
        "the contacts' push largest 10 t_a after point 5",
        _push_peaks_after_point5,
    ),
    "sec5-1-spring-deformed-to-ux-max-after-flyback": (
        "slip shares of a half after the fly-back",
        lambda r: _edit(r, "fig8b_window_readings", lambda t: t.assign(slip_share_1=0.5, slip_share_2=0.5)),
    ),
    # Section 5.2, Fig. 9
    "fig9a-standard-position-552nm": (
        "saw-tooth positions doubled",
        _scale("fig9a", "settled_position_m", 2.0, waveform="sawtooth"),
    ),
    "fig9a-optimized-position-716nm": (
        "optimized positions a tenth",
        _scale("fig9a", "settled_position_m", 0.1, waveform="optimized"),
    ),
    "fig9a-step-increase-46.8pct": (
        "optimized periods equal to the saw-tooth's",
        _fig9a(_optimized_as_sawtooth),
    ),
    "fig9a-optimized-step-larger": (
        "optimized positions halved (equal steps would be a tie)",
        _scale("fig9a", "settled_position_m", 0.5, waveform="optimized"),
    ),
    "fig9b-optimized-faster-below-110khz": (
        "optimized 1 mm/s slower everywhere",
        _optimized_from_sawtooth(-1.0),
    ),
    "fig9b-max-gain-2.5mm_s": ("optimized velocity equal to the saw-tooth's", _optimized_from_sawtooth(0.0)),
    "abstract-velocity-gain-15pct": (
        "optimized velocity equal to the saw-tooth's",
        _optimized_from_sawtooth(0.0),
    ),
    "fig9b-optimized-decreases-above-110khz": (
        "optimized velocity rising to the grid's end (on the paper's whole grid: on part of it a missing "
        "frequency could hold the turning point)",
        _chain(_regrid("fig9b"), _series_values("fig9b", "velocity_mm_per_s", lambda f: f)),
    ),
    "fig9b-standard-increases-above-110khz": (
        "saw-tooth velocity falling above 110 kHz (on the paper's whole grid)",
        _chain(_regrid("fig9b"), _series_values("fig9b", "velocity_mm_per_s", lambda f: 200.0 - f,
                                                 variant="sawtooth")),
    ),
    "fig9b-step-decreases-with-frequency": (
        "saw-tooth step rising with frequency",
        _series_values("fig9b", "step_nm", lambda f: f, variant="sawtooth"),
    ),
    "study-fig9b-sawtooth-velocity-16.5mm_s-at-110khz": (
        "saw-tooth velocity 0",
        _scale("fig9b_readings", "velocity_mm_per_s", 0.0, variant="sawtooth"),
    ),
    "fig9b-no-time-to-settle-above-110khz": (
        "t_s fitting at every frequency",
        lambda r: _edit(r, "fig9b_readings", lambda t: t.assign(settling_fits=True)),
    ),
    # Section 5.2, Fig. 10 (on the paper's frequency grid: the quick one locates no reachable maximum)
    "fig10a-max-velocity-19mm_s": (
        "a maximum of 5 mm/s at 110 kHz",
        _chain(_regrid("fig10a"),
               _series_values("fig10a", "velocity_mm_per_s", _peak(110, 5.0), preload=0.4)),
    ),
    "fig10a-max-velocity-at-110khz": (
        "a maximum at 60 kHz",
        _chain(_regrid("fig10a"),
               _series_values("fig10a", "velocity_mm_per_s", _peak(60, 5.0), preload=0.4)),
    ),
    "fig10a-1n-slower": (
        "1 N peaking at 100 kHz above 0.4 N at 110 kHz",
        _chain(
            _regrid("fig10a"),
            _series_values("fig10a", "velocity_mm_per_s", _peak(110, 5.0), preload=0.4),
            _series_values("fig10a", "velocity_mm_per_s", _peak(100, 10.0), preload=1.0),
        ),
    ),
    "fig10a-1n-larger-back-step": (
        "1 N's back-step a tenth of 0.4 N's at their maxima",
        _chain(
            _regrid("fig10a"),
            _series_values("fig10a", "velocity_mm_per_s", _peak(110, 5.0), preload=0.4),
            _series_values("fig10a", "velocity_mm_per_s", _peak(100, 10.0), preload=1.0),
            _series_values("fig10a", "back_step_nm", lambda f: 10 + 0 * f, preload=0.4),
            _series_values("fig10a", "back_step_nm", lambda f: 1 + 0 * f, preload=1.0),
        ),
    ),
    "fig10a-0.1n-smaller-back-step": (
        "0.1 N's back-step 10 nm larger than 0.4 N's at their maxima",
        _chain(
            _regrid("fig10a"),
            _series_values("fig10a", "back_step_nm", lambda f: 5 + 0 * f, preload=0.4),
            _series_values("fig10a", "back_step_nm", lambda f: 15 + 0 * f, preload=0.1),
        ),
    ),
    "fig10a-0.1n-stick-lost-above-80khz": (
        "stick at every frequency at 0.1 N",
        lambda r: _edit(r, "fig10a_readings", lambda t: t.assign(stick_during_acceleration=True)),
    ),
    "fig10a-0.1n-slightly-slower": (
        "0.1 N peaking at 60 kHz above 0.4 N at 110 kHz",
        _chain(
            _regrid("fig10a"),
            _series_values("fig10a", "velocity_mm_per_s", _peak(110, 5.0), preload=0.4),
            _series_values("fig10a", "velocity_mm_per_s", _peak(60, 10.0), preload=0.1),
        ),
    ),
    "fig10a-0.1n-maximum-at-or-below-80khz": (
        "0.1 N peaking at 20 kHz, stick lost only above 100 kHz",
        _chain(
            _regrid("fig10a"),
            _series_values("fig10a", "velocity_mm_per_s", _peak(20, 5.0), preload=0.1),
            _series_values("fig10a", "stick_during_acceleration", lambda f: f <= 100.0 + 1e-9, preload=0.1),
        ),
    ),
    "fig10b-r1-faster": (
        "R = 1 mm 1 mm/s slower at every frequency",
        _chain(
            _regrid("fig10b"),
            _series_values("fig10b", "velocity_mm_per_s", _peak(60, 5.0), radius_mm=0.25),
            _series_values("fig10b", "velocity_mm_per_s", _peak(60, 4.0), radius_mm=1.0),
        ),
    ),
    "fig10b-r1-higher-max-frequency": (
        "R = 1 mm peaking at 60 kHz, R = 0.25 mm at 110 kHz (two peaks at one grid point would be a tie)",
        _chain(
            _regrid("fig10b"),
            _series_values("fig10b", "velocity_mm_per_s", _peak(110, 5.0), radius_mm=0.25),
            _series_values("fig10b", "velocity_mm_per_s", _peak(60, 6.0), radius_mm=1.0),
        ),
    ),
    "fig10b-r1-stiffer-contact": (
        "the R = 0.25 mm contact stiffer",
        lambda r: _edit(r, "closed_forms", lambda t: t.assign(tangential_stiffness_N_per_m=np.where(
            np.isclose(t["radius_mm"], 1.0), 1.0, 2.0) * t["tangential_stiffness_N_per_m"])),
    ),
    "fig10b-r1-smaller-back-step": (
        "R = 1 mm's back-step ten times R = 0.25 mm's",
        _chain(
            _regrid("fig10b"),
            _series_values("fig10b", "velocity_mm_per_s", _peak(110, 5.0), radius_mm=0.25),
            _series_values("fig10b", "velocity_mm_per_s", _peak(110, 6.0), radius_mm=1.0),
            _series_values("fig10b", "back_step_nm", lambda f: 1 + 0 * f, radius_mm=0.25),
            _series_values("fig10b", "back_step_nm", lambda f: 10 + 0 * f, radius_mm=1.0),
        ),
    ),
    "fig10c-youngs-modulus-negligible": (
        "molybdenum half as fast as steel at 110 kHz",
        _chain(
            _regrid("fig10c"),
            _series_values("fig10c", "velocity_mm_per_s", _peak(110, 10.0), runner="steel"),
            _series_values("fig10c", "velocity_mm_per_s", _peak(110, 5.0), runner="molybdenum"),
        ),
    ),
    "conclusion-youngs-modulus-weaker-than-preload-and-radius": (
        "a runner effect of 15 mm/s, preload and radius effects of 0.1 mm/s",
        _chain(
            _regrid("fig10a"), _regrid("fig10b"), _regrid("fig10c"),
            _series_values("fig10c", "velocity_mm_per_s", _peak(110, 20.0), runner="steel"),
            _series_values("fig10c", "velocity_mm_per_s", _peak(110, 5.0), runner="molybdenum"),
            _series_values("fig10a", "velocity_mm_per_s", _peak(110, 5.1), preload=0.4),
            _series_values("fig10a", "velocity_mm_per_s", _peak(100, 5.0), preload=1.0),
            _series_values("fig10b", "velocity_mm_per_s", _peak(110, 5.1), radius_mm=1.0),
            _series_values("fig10b", "velocity_mm_per_s", _peak(100, 5.0), radius_mm=0.25),
        ),
    ),
}


# ======================================================================================
# Tests
# ======================================================================================


def test_every_extractor_has_a_counter_example():
    """Every check can fail: each extractor but those of claims about the experiment has data on which
    it fails, the not-informative ones too (their data are results the model cannot produce, which is
    why they hold by construction)."""
    functions = evaluation.extractors()
    marked = {c for c, f in functions.items() if f.not_informative}
    checked = set(functions) - set(EXPERIMENT_CLAIMS)
    assert sorted(checked - set(COUNTER_EXAMPLES)) == [], "extractors without a counter-example"
    assert sorted(set(COUNTER_EXAMPLES) - checked) == [], "counter-examples for no extractor"
    assert marked == {
        "fig10b-r1-stiffer-contact",
        "fig8a-back-step",
        "fig8a-runner-moves-with-hemispheres-in-stick",
        "fig8a-runner-vibrates-after-slip",
        "sec5-1-spring-deformed-to-ux-max-after-flyback",
        "fig9b-standard-increases-above-110khz",
    }
    assert set(EXPERIMENT_CLAIMS) == evaluation.claim_functions().experiment
    assert all(len(functions[c].not_informative) > 40 for c in marked), (
        "a not-informative mark needs its reason"
    )


@pytest.mark.parametrize("claim_id", EXPERIMENT_CLAIMS)
def test_experiment_claims_are_inconclusive_for_want_of_data(claim_id):
    with pytest.raises(NotEvaluable, match=NO_MEASURED_DATA):
        evaluation.extractors()[claim_id]({})


def test_not_informative_reasons_hold():
    # closed-form identity: 2aG* ∝ R^(1/3) at every normal force, so the ratio is 4^(1/3) exactly
    table = reference.tangential_stiffness_table()
    k = {
        r: g.sort_values(["preload_N", "side"])["tangential_stiffness_N_per_m"].to_numpy()
        for r, g in table.groupby("radius_mm")
    }
    np.testing.assert_allclose(k[1.0] / k[0.25], 4 ** (1 / 3), rtol=1e-12)
    # the 202 nm fly-back is at least six times either side's presliding u_x,max (Eq. 10) at 0.4 N
    drive = section5_drive(**section5_fields())
    presliding = np.asarray(theory.drive_theory(drive)["presliding_m"])
    assert drive.actuator.full_stroke_amplitude > 6 * presliding.max()
    # the free runner on the slow 100 Hz ramp: the force its inertia needs, m_r·(A/T) within one cycle of
    # its micro-vibration (the fastest the contacts bring it to the ramp's speed), is over two orders of
    # magnitude below the contacts' sliding force μ(2F_N1 + 4F_N2) (Eq. 1)
    ramp_speed = drive.actuator.full_stroke_amplitude * 100.0
    inertia = drive.runner_mass * ramp_speed * theory.runner_frequency(drive)
    f1, f2 = theory.normal_forces(np.array([drive.preload]), contacts=6)
    sliding = drive.friction_coefficient * float(2 * f1[0] + 4 * f2[0])
    assert inertia < 1e-2 * sliding
    # a runner on contacts of finite tangential stiffness swings after an impulse: a finite natural frequency
    assert 0 < theory.runner_frequency(drive) < float("inf")


@pytest.fixture(scope="module")
def quick_results():
    return evaluation.collect_results(RunConfig(profile="quick"))


@pytest.fixture(scope="module")
def claims():
    return load_claims().set_index("id", drop=False)


@pytest.mark.slow
@pytest.mark.parametrize("claim_id", sorted(COUNTER_EXAMPLES))
def test_check_fails_on_its_counter_example(claim_id, quick_results, claims):
    description, build = COUNTER_EXAMPLES[claim_id]
    func = evaluation.extractors()[claim_id]
    results = build(quick_results)
    try:
        ours = func(results, readings.default_reading()) if func.claim_depends_on else func(results)
    except ClaimFails:
        return  # decided against the paper outright
    outcome = check_claim(claims.loc[claim_id], ours)
    assert not outcome.passed, (
        f"{claim_id} still holds on its counter-example ({description}): {outcome.detail}"
    )
    assert math.isnan(outcome.score) or outcome.score > 0


# ======================================================================================
# The pieces the counter-examples rely on
# ======================================================================================


def test_not_informative_must_be_a_reason():
    with pytest.raises(ValueError, match="not_informative = 1 is not allowed"):
        checks.extractor("fig8a-back-step", not_informative=1)
    assert checks.extractor("fig8a-back-step")(lambda results: 0).not_informative == ""


def test_a_study_quotes_nothing_and_names_a_claim_of_the_paper(tmp_path):
    """A row without a quotation is a study (passmd.ledger.rules): it must name, in ``study_of``, a claim
    of the file that is itself no study; a row quoting nothing without naming one is refused."""
    claims = load_claims()
    studies = claims[claims["study_of"] != ""]
    assert (studies["source_quote"] == "").all() and set(studies["study_of"]) <= set(claims["id"])
    assert "study-fig7-onsets-earlier-against-this-model" in set(studies["id"])
    bad = claims.drop(columns=["paper_value_num", "tolerance_num"])
    at = bad["id"] == "study-fig7-onsets-earlier-against-this-model"
    for value, message in (("no-such-claim", "must name a claim of this file that is not a study"),
                           ("study-fig7a-model-difference-115mn",
                            "must name a claim of this file that is not a study"),
                           ("", "source_quote is empty")):
        bad.loc[at, "study_of"] = value
        path = tmp_path / "claims.csv"
        bad.to_csv(path, index=False)
        for name in ("fig5b_closed_form.csv", "fig6a_closed_form.csv", "fig6b_closed_form.csv",
                     "fig6c_closed_form.csv"):
            (tmp_path / name).write_bytes((reference.REFERENCE_DIR / name).read_bytes())
        with pytest.raises(ValueError) as info:
            load_claims(path)
        assert message in str(info.value)


def _velocities(frequencies, velocities, stick=None, fits=None):
    return pd.DataFrame(
        {
            "frequency_kHz": np.asarray(frequencies, float),
            "velocity_mm_per_s": np.asarray(velocities, float),
            "stick_during_acceleration": np.ones(len(frequencies), bool) if stick is None else stick,
            "eq15_fits": np.ones(len(frequencies), bool) if fits is None else fits,
        }
    )


def test_a_maximum_is_located_to_the_grids_resolution():
    """On a coarse grid the largest velocity is only bracketed by its neighbours: a maximum at the
    1 kHz edge is decidedly not at 110 kHz, one at 100 kHz could move there. On the paper's grid the
    grid point is the location, edges included; the reachable maximum is the largest up to 110 kHz."""
    coarse = [1, 20, 60, 100, 110, 120, 130]
    edge = _velocities(coarse, [5.0, 3.0, 2.0, 1.0, 0.5, 0.4, 0.2])
    assert maximum_location(edge) == (1.0, 1.0, 20.0)
    assert _located(edge, 105, 115, "110 ± 5 kHz") == 1.0
    near = _velocities(coarse, [0.1, 1.0, 2.0, 5.0, 3.0, 0.4, 0.2])
    with pytest.raises(NotEvaluable, match="could move it into"):
        _located(near, 105, 115, "110 ± 5 kHz")
    paper = FREQUENCIES["paper"] / 1e3
    rising = _velocities(paper, paper)  # still rising at 130 kHz
    assert maximum_location(rising) == (130.0, 130.0, 130.0)
    assert controllable_maximum(rising)["frequency_kHz"] == 110.0
    with pytest.raises(NotEvaluable, match="lacks some of the paper's frequencies"):
        _maxima(near)


def test_a_decision_where_eq15_is_undefined_says_so():
    """The frequencies that decide a claim all lie where Eq. 15 does not fit the period: the verdict
    names it (a Scoped result); one of them where it fits is enough to rest on Eq. 15."""
    part = _velocities([1, 5, 10, 110], [1.0, 2.0, 3.0, 4.0], fits=np.array([1, 1, 0, 0], bool))
    assert eq15_scope(part, [1.0]) == ""
    assert eq15_scope(part, [10.0, 1.0]) == ""
    scope = eq15_scope(part, [110.0])
    assert scope.startswith("Eq. 15 is undefined") and "above 5 kHz" in scope
    scoped = _scoped({"lhs": 1.0, "rhs": 2.0}, scope)
    assert isinstance(scoped, checks.Scoped) and scoped.outside == scope
    assert _scoped(1.0, "", scope) == 1.0


def test_the_stick_edge_is_where_stick_is_lost_for_good():
    f = [1, 20, 60, 100, 110, 120]
    assert stick_edge(_velocities(f, f, stick=np.array([0, 1, 1, 1, 0, 0], bool))) == 100.0
    with pytest.raises(ClaimFails, match="still sticks"):
        stick_edge(_velocities(f, f, stick=np.array([0, 1, 1, 1, 1, 1], bool)))
    with pytest.raises(ClaimFails, match="every grid frequency"):
        stick_edge(_velocities(f, f, stick=np.zeros(6, bool)))
