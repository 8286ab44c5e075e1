"""What a simulation sets up before it integrates: the contact groups of a drive (Eq. 1) and
their parameter and state rows for the kernels (:func:`~passmd.solver.setup.contact_rows`), the contacts'
linear stiffness the error-controlled step integrates exactly (:func:`~passmd.solver.setup.linear_stiffness`),
and the steps a :class:`passmd.solver.steps.Scheme` takes on a drive
(:func:`~passmd.solver.setup.scheme_steps`, which refuses a given step above the Verlet stability limit).
:class:`passmd.solver.simulation.Simulation` calls these once per run.
"""

from __future__ import annotations

import functools
from typing import NamedTuple

import numpy as np

from passmd.model.contact import drive_contact_arrays, stack_contacts
from passmd.model.parameters import Drive
from passmd.solver.steps import Scheme, StepPlan

#: Verlet is stable for ω dt < 2; a given step (``Scheme.dt``) must keep
#: this margin below it.
STABILITY_MARGIN = 0.9


def _groups(drive: Drive, share_side_state: bool):
    """Normal force, multiplicity and radius of each group of the drive's layout (Eq. 1); with
    ``share_side_state=False`` every contact is a group of one."""
    forces, multiplicity, radii = drive.contact_layout
    if share_side_state:  # the drive's arrays are read-only; numba compiles the kernels for writable ones
        return forces, multiplicity.copy(), radii
    per = multiplicity.astype(int)
    return np.repeat(forces, per), np.ones(int(per.sum())), np.repeat(radii, per)


def contact_groups(drive: Drive, share_side_state: bool = True):
    """Normal force and multiplicity of each contact group (Eq. 1; any arrangement,
    :attr:`passmd.model.parameters.Drive.contact_layout`).

    With ``share_side_state=False`` every contact is a group of one, so that results do not
    rely on the by-symmetry sharing of one state per group.
    """
    return _groups(drive, share_side_state)[:2]


def contact_rows(drive: Drive, contact_model: str, springs: int, share_side_state: bool):
    """Contact parameters and (virgin) state of every group
    (:func:`passmd.model.contact.stack_contacts`) and the groups' multiplicities
    (:func:`contact_groups`): new arrays on every call, the parameters computed once per drive."""
    params, state, multiplicity = _contact_parameters(drive, contact_model, springs, share_side_state)
    return params.copy(), state.copy(), multiplicity.copy()


@functools.lru_cache(maxsize=32)
def _contact_parameters(drive: Drive, contact_model: str, springs: int, share_side_state: bool):
    """:func:`contact_rows` of the drives last used (a sweep or a fit simulates each drive many
    times); the caller copies them."""
    forces, multiplicity, radii = _groups(drive, share_side_state)
    discrete = springs if contact_model == "discrete" else None
    rows = [drive_contact_arrays(drive, F, R, discrete) for F, R in zip(forces, radii, strict=True)]
    params, state = stack_contacts(rows)
    return params, state, multiplicity


def linear_stiffness(drive: Drive, multiplicity: np.ndarray, k_contacts: np.ndarray) -> float:
    """Σ n_g k_g: the contacts' initial tangent stiffness, in series with k_p for flexible actuators
    (N/m); the part of the runner's force the error-controlled step integrates exactly."""
    if drive.actuator_model == "flexible":
        k_p = drive.actuator.stiffness
        k_contacts = k_p * k_contacts / (k_p + k_contacts)
    return float(np.sum(multiplicity * k_contacts))


class Steps(NamedTuple):
    """The steps a scheme takes on one drive (s), from :func:`scheme_steps`."""

    fine: float  # while flexible actuators ring; rigid actuators without error control throughout
    coarse: float  # explicit step once flexible actuators stop ringing (= fine when it does not grow)
    quasi_static: bool  # flexible actuators turn quasi-static once their ringing has decayed
    quiet: float  # step once the ringing has decayed: the quasi-static (first controlled) or coarse one
    controlled: bool  # error-controlled steps (rigid actuators; flexible ones while quasi-static)
    longest: float | None  # longest error-controlled step (None without error control)
    newton_balance: bool  # Scheme.newton_balance
    smooth_breakpoints: bool  # Scheme.smooth_breakpoints


def scheme_steps(drive: Drive, plan: StepPlan, scheme: Scheme) -> Steps:
    """The steps of ``scheme`` on ``drive`` under ``plan``.

    A scheme's ``dt`` replaces the fine step and must keep :data:`STABILITY_MARGIN` below the
    Verlet stability limit of the stiffest mode.
    """
    fine = coarse = plan.fine_step
    if scheme.dt is not None:
        limit = STABILITY_MARGIN * plan.stability_limit
        if scheme.dt > limit:
            raise ValueError(
                f"dt = {scheme.dt!r} is out of range: the stiffest mode "
                f"({plan.stiffest_frequency / 1e6:.3g} MHz) needs dt < {limit:.3g} s for the explicit "
                "integrator to stay stable"
            )
        fine = coarse = scheme.dt
    elif scheme.quiet_step != "fine":
        coarse = plan.coarse_step
    quasi_static = scheme.quiet_step == "quasi-static" and drive.actuator_model == "flexible"
    quiet = plan.quasi_step if quasi_static else coarse
    controlled = scheme.error_control
    return Steps(fine, coarse, quasi_static, quiet, controlled, plan.longest_step if controlled else None,
                 scheme.newton_balance, scheme.smooth_breakpoints)

