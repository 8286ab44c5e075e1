"""Checks of a command's results before they are printed (finite and physically bounded).

A result that fails raises :class:`ResultError` (exit status 1, one line): the same with
and without ``--json``.
"""

from __future__ import annotations

from passmd.parameters import Drive

__all__ = ["ResultError", "check_force_bound", "check_run_bounds", "friction_limit"]


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
    from passmd.theory import drive_theory

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


def friction_limit(drive: Drive) -> float:
    """μ Σ F_N: the largest friction force all contacts together can exert (Eq. 1)."""
    from passmd.theory import normal_forces

    forces = normal_forces(drive.preload, drive.contacts)
    total = float(forces[0]) if drive.contacts == 1 else float(2 * forces[0] + 4 * forces[1])
    return drive.friction_coefficient * total


def check_force_bound(found: dict, drive: Drive) -> None:
    """At stall the load cell's mean force is held by friction: |F| <= μ Σ F_N (Section 4.2).

    Averaged over a period the runner's inertia contributes m_r Δv / T, negligible at stall;
    5 % of margin covers it.
    """
    limit = friction_limit(drive)
    force = abs(float(found["generated_force_N"]))
    if force > 1.05 * limit:
        raise ResultError(f"generated force {force:.4g} N exceeds what friction can hold (mu*sum(F_N) = "
                          f"{limit:.4g} N): the result is not trustworthy")

