"""MDR contact with memory (Section 3.2, Eqs. 4–6): discrete springs and their exact limit.

One ruby-hemisphere/runner contact at constant normal force F_N, reduced by the method
of dimensionality reduction (MDR, Popov) to a rigid 1-D parabola g(x) = x²/R (a 1-D
sphere of radius R₁ = R/2, Eq. 5) pressed into independent springs of normal stiffness
E*Δx and tangential stiffness G*Δx (Eq. 4). A spring sticks while its tangential force
is below μ times its normal force and slides at that limit otherwise; the friction
force is the sum of the spring forces (Eq. 6).

Two interchangeable models behind one interface:

``"discrete"``
    N springs exactly as in the paper. They sit at the midpoints of N equal cells over
    the Hertz contact width −a…a (Δx = 2a/N, x_i = −a + (i + ½)Δx), and the indentation
    d is solved so that Σ E*Δx (d − g(x_i))⁺ = F_N holds exactly for that grid, so full
    sliding gives exactly ±μF_N at every N. Cost O(N) per call.
``"exact"``
    The N → ∞ limit in closed form: the virgin Cattaneo–Mindlin curve
    φ(v) = μF_N [1 − (1 − v/u_max)^{3/2}], u_max = μ (E*/G*) d (Eq. 7), and
    Mindlin–Deresiewicz/Masing branches T = T_k ± 2φ(|u − u_k|/2) after every reversal,
    kept on a stack of reversal points with wipe-out of closed minor loops and erased by
    full sliding. O(1) amortised per call.

Conventions: ``u = x_a − x_r`` (hemisphere minus runner); the force ``T(u)`` acts ``+T``
on the runner and ``−T`` on the actuator. The paper writes u_x = x_r − x_a for the
spring deflection; that is −u here, and its spring forces are −T.

Hot loops (the integrator) call the numba kernels on plain float64 arrays:
:func:`contact_force`, :func:`contact_update`, :func:`contact_force_tangent` (T and dT/du,
for Newton solves), :func:`contact_slip_share`, :func:`contact_reset`,
:func:`contact_stiffness`, :func:`sliding_force`, with the arrays
made by :func:`contact_arrays` (one contact) or :func:`stack_contacts` (rows of a 2-D
array). Inside a hot loop over stacked contacts prefer :func:`contact_update_row`
``(P, S, g, u)`` and friends to ``contact_update(P[g], S[g], u)``: making the view
``P[g]`` in a numba loop costs two atomic reference-count updates (≈ 15 ns), more than the
exact contact itself. :class:`passmd.model.mdr_contact.MDRContact` wraps one contact for
interactive use.
"""

from __future__ import annotations

import numbers
from typing import TYPE_CHECKING

import numpy as np

from passmd.model.contact_kernels import (
    DISCRETE,
    EXACT,
    P_INDENT,
    P_MODEL,
    P_NORMAL,
    P_RADIUS,
    P_SIZE,
    P_SLIDING,
    P_SPACING,
    P_SPRING_K,
    P_STIFFNESS,
    P_UMAX,
    PARAMS_HEADER,
    S_BASE,
    S_DEPTH,
    S_DIR,
    S_FORCE,
    S_MAXDEPTH,
    S_OVERFLOW,
    S_REVERSALS,
    S_U,
    STATE_HEADER,
    contact_force,
    contact_force_row,
    contact_force_tangent,
    contact_force_tangent_row,
    contact_reset,
    contact_slip_share,
    contact_slip_share_row,
    contact_stiffness,
    contact_update,
    contact_update_row,
    sliding_force,
)
from passmd.model.hertz import _hertz_contact_radius
from passmd.model.parameters import Drive
from passmd.model.tables import Assumption
from passmd.runtime.validation import check_choice, check_positive

if TYPE_CHECKING:  # pandas is imported where a DataFrame is built (start-up time)
    pass

__all__ = [
    "DEFAULT_CAPACITY",
    "DISCRETE",
    "EXACT",
    "contact_arrays",
    "contact_force",
    "contact_force_row",
    "contact_force_tangent",
    "contact_force_tangent_row",
    "contact_reset",
    "contact_slip_share",
    "contact_slip_share_row",
    "contact_stiffness",
    "contact_update",
    "contact_update_row",
    "discrete_indentation",
    "drive_contact_arrays",
    "memory_diagnostics",
    "memory_mismatch",
    "sliding_force",
    "stack_contacts",
]

#: Reversal points the exact model keeps by default (memory of nested minor loops).
DEFAULT_CAPACITY = 1024
#: Bounds accepted for the number of springs and for the stack capacity.
MAX_SPRINGS = 10_000_000
MIN_CAPACITY, MAX_CAPACITY = 8, 10_000_000

ASSUMPTIONS: tuple[Assumption, ...] = (
    Assumption(
        key="mdr_spring_layout",
        symbol="x_i, N",
        value="midpoints of N equal cells over the Hertz width 2a; d solved so Σ E*Δx(d − g_i) = F_N",
        unit="–",
        rationale=(
            "Section 3.2 gives the spring stiffnesses (Eq. 4) and R₁ = R/2 (Eq. 5) but not "
            "where the springs sit nor how many there are. Equal cells over the contact "
            "width with the indentation solved for the discrete grid make full sliding "
            "exactly μF_N at every N; the discrete model converges to the exact one."
        ),
        sensitivity="MDR validation chapter: error vs N (convergence order) and cost vs N.",
    ),
    Assumption(
        key="reversal_stack_capacity",
        symbol="–",
        value=f"{DEFAULT_CAPACITY} reversal points; on overflow the newest minor loop is forgotten",
        unit="–",
        rationale=(
            "The exact contact stores the reversal points of nested minor loops. A full "
            "stack drops the newest (smallest) loop, the force stepping by at most that "
            "loop's height; overflows are counted in the contact state and reported."
        ),
        sensitivity="None while the reported overflow count is zero (the usual case).",
    ),
)


def discrete_indentation(heights, target):
    """Depth d with Σ (d − g_i)⁺ = target for spring heights g_i (water filling).

    Parameters
    ----------
    heights : array_like
        Profile heights g(x_i) of the springs, m.
    target : float
        F_N / (E*Δx), m: the required sum of normal spring deflections.

    Returns
    -------
    float
        The unique d (the sum is piecewise linear and increasing in d).
    """
    g = np.sort(np.asarray(heights, dtype=float))
    k = np.arange(1, g.size + 1)
    depth = (target + np.cumsum(g)) / k  # depth if exactly the k lowest springs touch
    upper = np.append(g[1:], np.inf)
    return float(depth[np.argmax(depth <= upper)])


def check_springs(springs) -> int:
    """The number of springs of a discrete contact, an integer from 2 to ``MAX_SPRINGS``."""
    if isinstance(springs, bool) or not isinstance(springs, numbers.Integral):
        raise ValueError(
            f"springs = {springs!r} is not allowed: must be None (exact model) or an integer "
            f"from 2 to {MAX_SPRINGS}"
        )
    if not 2 <= int(springs) <= MAX_SPRINGS:
        raise ValueError(f"springs = {springs!r} is out of range: must be an integer from 2 to {MAX_SPRINGS}")
    return int(springs)


def check_capacity(capacity) -> int:
    """The reversal-stack capacity of an exact contact, an integer from 8 to ``MAX_CAPACITY``."""
    ok = isinstance(capacity, numbers.Integral) and not isinstance(capacity, bool)
    if not ok or not MIN_CAPACITY <= int(capacity) <= MAX_CAPACITY:
        raise ValueError(
            f"capacity = {capacity!r} is out of range: must be an integer from {MIN_CAPACITY} "
            f"to {MAX_CAPACITY}"
        )
    return int(capacity)


def contact_arrays(model, normal_force, radius, E_star, G_star, mu, springs=None,
                   capacity=DEFAULT_CAPACITY) -> tuple[np.ndarray, np.ndarray]:
    """Parameter and (virgin) state arrays of one contact for the numba kernels.

    Parameters
    ----------
    model : {"exact", "discrete"}
        Closed-form N → ∞ limit with a reversal stack, or N springs (Eqs. 4–6).
    normal_force : float
        F_N, N (> 0).
    radius : float
        Hemisphere radius R, m (> 0); the MDR profile is g(x) = x²/R (R₁ = R/2, Eq. 5).
    E_star, G_star : float
        Effective moduli E*, G* in Pa (MDR convention, see :mod:`passmd.model.hertz`).
    mu : float
        Friction coefficient μ (> 0).
    springs : int or None
        Number of springs N (discrete model, 2 ≤ N); ignored by the exact model.
    capacity : int
        Reversal points the exact model can hold (≥ 8); ignored by the discrete model.

    Returns
    -------
    params, state : numpy.ndarray
        1-D float64 arrays (layout in :mod:`passmd.model.contact_kernels`); ``params[0]`` is
        the model code ``EXACT`` or ``DISCRETE`` (module constants).
    """
    check_choice("model", model, ("exact", "discrete"))
    F = check_positive("normal_force", normal_force, "N")
    R = check_positive("radius", radius, "m")
    E = check_positive("E_star", E_star, "Pa")
    G = check_positive("G_star", G_star, "Pa")
    mu = check_positive("mu", mu, "–")
    if model == "exact":
        return unchecked_contact_arrays(model, F, R, E, G, mu, None, check_capacity(capacity))
    return unchecked_contact_arrays(model, F, R, E, G, mu, check_springs(springs), capacity)


def drive_contact_arrays(drive: Drive, normal_force: float, radius: float, springs: int | None = None
                         ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`contact_arrays` of one contact of ``drive`` (exact model without ``springs``).

    The :class:`~passmd.model.parameters.Drive` checked its contacts' force, radius, moduli and
    friction coefficient on construction, so only ``springs`` is checked here.
    """
    E_star, G_star = drive.contact_moduli
    model = "exact" if springs is None else "discrete"
    springs = None if springs is None else check_springs(springs)
    return unchecked_contact_arrays(model, float(normal_force), float(radius), E_star, G_star,
                                    drive.friction_coefficient, springs, DEFAULT_CAPACITY)


def unchecked_contact_arrays(model: str, F: float, R: float, E: float, G: float, mu: float,
                             springs: int | None, capacity: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`contact_arrays` of arguments its caller has checked (the public function, or a
    :class:`~passmd.model.parameters.Drive`'s contact: the drive checked its force, radius and moduli)."""
    a_array = _hertz_contact_radius(F, R, E)
    a = float(a_array)
    if model == "exact":
        cap = capacity
        d = float(a_array ** 2 / R)  # the Hertz indentation a²/R
        params = np.zeros(PARAMS_HEADER)
        params[P_MODEL] = EXACT
        params[P_UMAX] = mu * E / G * d  # Eq. 7
        params[P_STIFFNESS] = 2.0 * a * G
        params[P_SIZE] = cap
        params[P_SPRING_K] = 0.0
        params[P_SPACING] = 0.0
        state = np.zeros(STATE_HEADER + 2 * cap)
    else:
        n = springs
        dx = 2.0 * a / n
        x = -a + (np.arange(n) + 0.5) * dx
        g = x**2 / R
        d = discrete_indentation(g, F / (E * dx))
        limits = mu * E / G * np.maximum(d - g, 0.0)  # |u − p_i| ≤ μ E*/G* u_z,i
        params = np.zeros(PARAMS_HEADER + 2 * n)
        params[P_MODEL] = DISCRETE
        params[P_UMAX] = limits.max()
        params[P_STIFFNESS] = G * dx * np.count_nonzero(limits > 0)
        params[P_SIZE] = n
        params[P_SPRING_K] = G * dx
        params[P_SPACING] = dx
        params[PARAMS_HEADER : PARAMS_HEADER + n] = limits
        params[PARAMS_HEADER + n :] = x
        state = np.zeros(STATE_HEADER + n)
    params[P_SLIDING] = mu * F
    params[P_NORMAL] = F
    params[P_RADIUS] = a
    params[P_INDENT] = d
    return params, state


def stack_contacts(contacts) -> tuple[np.ndarray, np.ndarray]:
    """Pad several contacts' ``(params, state)`` into 2-D C-contiguous arrays (one row each).

    Rows are padded with zeros; the kernels read only what ``params`` describes, so the
    row views ``P[g]``, ``S[g]`` can be passed to them directly.
    """
    pairs = list(contacts)
    if not pairs:
        raise ValueError("contacts = [] is not allowed: must hold at least one (params, state) pair")
    width_p = max(p.size for p, _ in pairs)
    width_s = max(s.size for _, s in pairs)
    P = np.zeros((len(pairs), width_p))
    S = np.zeros((len(pairs), width_s))
    for g, (p, s) in enumerate(pairs):
        P[g, : p.size] = p
        S[g, : s.size] = s
    return P, S


def memory_diagnostics(params, state) -> dict:
    """Reversals recorded, deepest stack and overflows of one exact contact (zeros for discrete).

    ``params``/``state`` are one contact's arrays (a row of :func:`stack_contacts`).
    """
    if params[P_MODEL] != EXACT:
        return {"reversals": 0, "max_depth": 0, "overflows": 0}
    return {
        "reversals": int(state[S_REVERSALS]),
        "max_depth": int(state[S_MAXDEPTH]),
        "overflows": int(state[S_OVERFLOW]),
    }


def memory_mismatch(params, earlier, later, shift: float) -> float:
    """How far one contact's memory ``later`` is from ``earlier`` moved by ``shift`` (m).

    The runner moved on by ``shift`` while the hemisphere came back to where it was, so every
    stored displacement ``u = x_a − x_r`` of a repeated state lies ``shift`` lower and every stored
    force is the same. The mismatch is the largest departure, forces counted as displacements
    through the contact's largest tangent stiffness 2aG*; infinite when the memory's structure
    differs (virgin or sliding base, branch direction, number of reversal points), as no shift
    then makes the two memories alike.

    ``params``, ``earlier``, ``later``: one contact's arrays (rows of :func:`stack_contacts`).
    """
    if any(earlier[k] != later[k] for k in (S_BASE, S_DIR, S_DEPTH)):
        return float("inf")
    stiffness = params[P_STIFFNESS]
    worst = max(abs(later[S_U] - earlier[S_U] + shift), abs(later[S_FORCE] - earlier[S_FORCE]) / stiffness)
    if params[P_MODEL] == EXACT:
        depth = int(later[S_DEPTH])
        u = slice(STATE_HEADER, STATE_HEADER + 2 * depth, 2)
        force = slice(STATE_HEADER + 1, STATE_HEADER + 2 * depth, 2)
    else:  # each spring's slip p_i moves with u
        u, force = slice(STATE_HEADER, STATE_HEADER + int(params[P_SIZE])), slice(0, 0)
    if later[u].size:
        worst = max(worst, float(np.max(np.abs(later[u] - earlier[u] + shift))))
    if later[force].size:
        worst = max(worst, float(np.max(np.abs(later[force] - earlier[force]))) / stiffness)
    return float(worst)
