"""Checks of a command's results before they are printed (finite and physically bounded).

A result that fails raises :class:`ResultError` (exit status 1, one line): the same with
and without ``--json``.
"""

from __future__ import annotations

import numpy as np

from passmd.model.parameters import Drive

__all__ = ["EMPTY_BY_DESIGN", "ResultError", "check_run_bounds", "check_table"]


class ResultError(RuntimeError):
    """A result failed its finiteness or plausibility check (exit status 1)."""


def check_run_bounds(summary: dict, drive: Drive, amplitude: float) -> None:
    """A runner cannot move farther than the friction drive allows (Section 3, Eqs. 1, 7–14).

    Work bound (rigorous): the runner starts at rest and the only force pushing it is the
    contacts' friction, at most μ Σ F_N (Eq. 1; the load cell only pulls it back), so after
    a run of duration t it is within μ Σ F_N t² / (2 m_r) of its start.

    Stroke bound: in one period the runner can neither pass the contact tips' stroke ``A``
    nor lag or lead them by more than the contacts' elastic play (presliding u_x,max,
    Eq. 7/10, plus the actuator deformation u_x,a, Eq. 9/14); a step is at most
    ``A + 2 (u_x,max + u_x,a)``. The check allows twice that (inertial over-travel after the
    fly-back), and the final position ``periods`` such steps.
    """
    from passmd.model.theory import drive_theory, friction_limit

    duration = summary["periods"] / summary["frequency_Hz"]
    reach = friction_limit(drive) * duration**2 / (2.0 * drive.runner_mass)
    final = abs(float(summary["final_position_m"]))
    if final > reach * (1 + 1e-9) + 1e-15:
        raise ResultError(f"final position {final:.4g} m is farther than friction can push the runner in "
                          f"{duration:.4g} s (mu*sum(F_N)*t^2/(2 m_r) = {reach:.4g} m): the result is not "
                          "trustworthy")
    theory = drive_theory(drive)
    play = max(theory["presliding_m"]) + (max(theory["actuator_deformation_m"])
                                          if drive.actuator_model == "flexible" else 0.0)
    step_limit = 2.0 * (amplitude + 2.0 * play)
    steps = list(summary.get("step_sizes_m") or []) + list(summary.get("back_steps_m") or [])
    worst = max((abs(float(x)) for x in steps), default=0.0)
    if worst > step_limit:
        raise ResultError(f"a step of {worst:.4g} m exceeds what the stroke and the contacts' play allow "
                          f"({step_limit:.4g} m per period): the result is not trustworthy")
    if final > summary["periods"] * step_limit:
        raise ResultError(f"final position {final:.4g} m exceeds {summary['periods']} periods of the largest "
                          f"possible step ({step_limit:.4g} m): the result is not trustworthy")


# A critical-amplitude search that finds no step up to the full stroke has no critical amplitude
# and no upper bracket (Section 4.1: "no step up to the full stroke" is a result).
_NOT_FOUND = ("critical_amplitude_nm", "bracket_high_nm")
_CRITICAL = dict.fromkeys(_NOT_FOUND, "no step up to the full stroke")
_ONSET = dict.fromkeys(("onset_nm", "onset_high_nm"), "no force up to the full stroke")  # the same for Fig. 7
# A stall run's force still to come is withheld unless it approaches a limit below μΣF_N steadily.
_TAIL = {"remaining_force_mN": "no credible extrapolation below μΣF_N (passmd.protocols.stall)"}
# Fig. 9a is one tidy table of the time series (views full/zoom) and of the per-period rows.
_SERIES = ("time_s", "time_ms", "time_us", "piezo_position_m", "runner_position_m", "runner_velocity_m_per_s",
           "slip_share_1", "friction_force_1_N", "slip_share_2", "friction_force_2_N", "piezo_position_nm",
           "runner_position_nm")
_PERIODS = ("period", "settled_position_m", "back_step_m", "settled_position_nm", "back_step_nm")
# Section 5's tables hold saw-tooth rows beside optimized-waveform rows; only the latter have a design.
_DESIGN = dict.fromkeys(("flyback_time_s", "settling_time_s", "acceleration_time_s",
                         "acceleration_amplitude_m", "ramp_time_s", "max_slip_share_acceleration"),
                        "saw-tooth rows have no Eq. 15 design")

# The design chapter's example drive: a runner that does not ring after the fly-back has no ringing
# frequency or decay; where Eq. 15 gives no waveform (the row's note says why) it has no design or velocity.
_NO_RING = dict.fromkeys(("ringing_frequency_Hz", "ringing_decay_time_s"), "the runner does not ring")
_NO_EQ15 = dict.fromkeys(("optimized_velocity_m_per_s", "gain_m_per_s", "settling_time_s",
                          "acceleration_time_s", "acceleration_amplitude_m", "response_frequency_Hz",
                          "eq15_highest_frequency_Hz"), "Eq. 15 gives no waveform at this point")

#: Cells a figure leaves empty (NaN) by design, ``{figure: {column: why}}``: a quantity that does
#: not exist for that row. Every other numeric cell of a result table must be finite.
EMPTY_BY_DESIGN: dict[str, dict[str, str]] = {
    **{name: _CRITICAL
       for name in ("fig5b", "fig6a", "fig6b", "fig6c", "fig56_frequency", "fig56_viscosity")},
    **{name: {**_ONSET, **_TAIL} for name in ("fig7a", "fig7b", "fig7grid")},
    "fig7freq": _TAIL,
    "fig7_difference": dict.fromkeys(("onset_low_nm", "onset_high_nm"), "no force up to the full stroke"),
    "fig9a": {**dict.fromkeys(_SERIES, "per-period rows have no time series"),
              **dict.fromkeys(_PERIODS, "time-series rows have no period")},
    **{name: _DESIGN for name in ("fig9b", "fig10a", "fig10b", "fig10c")},
    # the ledger's readings of the same runs at every point of the assumption space
    **{f"{name}_readings": _CRITICAL for name in ("fig5b", "fig6a", "fig6b", "fig6c")},
    "fig7_readings": _TAIL,
    "fig9a_response": dict.fromkeys(("sawtooth_reversal_s", "response_reversal_s"),
                                    "the runner need not turn within t_s after the fly-back"),
    **{f"{name}_readings": _DESIGN for name in ("fig9b", "fig10a", "fig10b", "fig10c")},
    "design_critical_amplitude": {**dict.fromkeys(("steady_nm", "first_nm"), "no step up to the full stroke"),
                                  **_NO_RING},
    **dict.fromkeys(("design_step_map", "design_velocity_map"), _NO_RING),
    "design_gain_map": {**_NO_EQ15, **_NO_RING},
    "calibration_paper_mu": {"amplitude_nm": "a critical amplitude is measured over the amplitude, at none"},
    "mdr_convergence": {"fit_rel": "the power law is fitted on the larger spring counts only"},
    "mdr_cost": dict.fromkeys(("springs", "reversals", "max_depth", "overflows"),
                              "each contact model has its own cost parameters"),
}


def check_table(name: str, table) -> None:
    """Every numeric cell of a result table finite, except :data:`EMPTY_BY_DESIGN`'s (never ±inf).

    ``name`` is the figure (or result table) the message names. A NaN where the figure always
    computes a number comes from outside the computation, e.g. a damaged cache entry.
    """
    allowed = EMPTY_BY_DESIGN.get(name, {})
    for column in table.columns:
        values = table[column]
        if values.dtype.kind not in "iuf":  # numbers only: labels, flags and text are not results
            continue
        data = values.to_numpy(dtype=float, na_value=np.nan)
        bad = np.isinf(data) if column in allowed else ~np.isfinite(data)
        if bad.any():
            row = int(np.flatnonzero(bad)[0])
            raise ResultError(
                f"{name}: column {column} is not finite ({float(data[row])!r} in row {row}, "
                f"{int(bad.sum())} of {len(data)} rows): the result is not trustworthy (if it came from the "
                "cache, clear the cache to recompute it)"
            )
