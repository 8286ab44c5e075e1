"""Whether a run has become periodic: its state at the end of two periods, compared.

A drive forced by a periodic waveform repeats itself once its state at the end of a period
(runner, actuators, contact memory) is the state at the end of the period before, moved on by
the step the runner took: from then on every period is the last one again, and every later step
is that shift. :func:`mismatch` measures how far two end-of-period states
(:meth:`passmd.solver.simulation.Simulation.boundary_state`) are from that, in metres: positions
directly, velocities over the angular frequency of their mode (the runner on its contacts; the
actuator on k_p and its contact), forces over the stiffness that carries them. A load cell pulls
the runner back in proportion to its position, so such a drive repeats itself only in place:
its shift counts as mismatch.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from passmd.model.contact import memory_mismatch

__all__ = ["BoundaryState", "mismatch"]


@dataclass(frozen=True)
class BoundaryState:
    """A run's state at the end of a period, with the scales :func:`mismatch` weighs it by.

    Attributes
    ----------
    y : ndarray
        [x_r, v_r, x_a (per contact row), v_a (per contact row)] (m, m/s).
    memory : ndarray
        The contact rows' memory (rows of :func:`passmd.model.contact.stack_contacts`).
    params : ndarray
        The contact rows' constants (shared, not copied).
    runner_omega, actuator_omega : float
        Angular frequencies (rad/s) of the runner on its contacts and of a flexible actuator on
        k_p and its contact; ``actuator_omega`` is 0 for rigid actuators (their state is x_p's).
    translates : bool
        False with a load cell: the state repeats only in place.
    """

    y: np.ndarray
    memory: np.ndarray
    params: np.ndarray
    runner_omega: float
    actuator_omega: float
    translates: bool


def mismatch(earlier: BoundaryState, later: BoundaryState) -> tuple[float, float]:
    """(mismatch, shift) of two end-of-period states of one run (m; module docstring).

    ``shift`` is the runner's advance x_r(later) − x_r(earlier); ``mismatch`` the largest
    departure of ``later`` from ``earlier`` moved on by it (in place with a load cell), infinite
    when a contact's memory differs in structure (:func:`passmd.model.contact.memory_mismatch`).
    """
    y0, y1 = earlier.y, later.y
    shift = float(y1[0] - y0[0])
    moved = shift if later.translates else 0.0
    rows = later.memory.shape[0]
    worst = max(abs(shift - moved), abs(y1[1] - y0[1]) / later.runner_omega)
    if later.actuator_omega > 0.0:
        worst = max(worst, float(np.max(np.abs(y1[2:2 + rows] - y0[2:2 + rows]))),
                    float(np.max(np.abs(y1[2 + rows:] - y0[2 + rows:]))) / later.actuator_omega)
    for g in range(rows):
        worst = max(worst, memory_mismatch(later.params[g], earlier.memory[g], later.memory[g], moved))
        if math.isinf(worst):
            break
    return float(worst), shift
