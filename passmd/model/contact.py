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
:func:`contact_force`, :func:`contact_update`, :func:`contact_slip_share`,
:func:`contact_reset`, :func:`contact_stiffness`, :func:`sliding_force`, with the arrays
made by :func:`contact_arrays` (one contact) or :func:`stack_contacts` (rows of a 2-D
array). Inside a hot loop over stacked contacts prefer :func:`contact_update_row`
``(P, S, g, u)`` and friends to ``contact_update(P[g], S[g], u)``: making the view
``P[g]`` in a numba loop costs two atomic reference-count updates (≈ 15 ns), more than the
exact contact itself. :class:`MDRContact` wraps one contact for interactive use.
"""

from __future__ import annotations

import numbers
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from passmd.model.contact_kernels import (
    DISCRETE,
    EXACT,
    LIMIT_RTOL,
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
    S_DEPTH,
    S_MAXDEPTH,
    S_OVERFLOW,
    S_REVERSALS,
    S_U,
    STATE_HEADER,
    contact_force,
    contact_force_row,
    contact_reset,
    contact_slip_share,
    contact_slip_share_row,
    contact_stiffness,
    contact_update,
    contact_update_row,
    sliding_force,
)
from passmd.model.hertz import _hertz_contact_radius
from passmd.model.parameters import Drive, check_contact_plausible, check_drive
from passmd.model.tables import Assumption
from passmd.model.theory import contact_layout, contact_moduli
from passmd.runtime.validation import check_array, check_choice, check_positive, check_range

if TYPE_CHECKING:  # pandas is imported where a DataFrame is built (start-up time)
    import pandas as pd

__all__ = [
    "DEFAULT_CAPACITY",
    "DISCRETE",
    "EXACT",
    "MDRContact",
    "contact_arrays",
    "contact_force",
    "contact_force_row",
    "contact_reset",
    "contact_slip_share",
    "contact_slip_share_row",
    "contact_stiffness",
    "contact_update",
    "contact_update_row",
    "discrete_indentation",
    "drive_contact_arrays",
    "memory_diagnostics",
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


def _check_springs(springs) -> int:
    if isinstance(springs, bool) or not isinstance(springs, numbers.Integral):
        raise ValueError(
            f"springs = {springs!r} is not allowed: must be None (exact model) or an integer "
            f"from 2 to {MAX_SPRINGS}"
        )
    if not 2 <= int(springs) <= MAX_SPRINGS:
        raise ValueError(f"springs = {springs!r} is out of range: must be an integer from 2 to {MAX_SPRINGS}")
    return int(springs)


def _check_capacity(capacity) -> int:
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
        return _contact_arrays(model, F, R, E, G, mu, None, _check_capacity(capacity))
    return _contact_arrays(model, F, R, E, G, mu, _check_springs(springs), capacity)


def drive_contact_arrays(drive: Drive, normal_force: float, radius: float, springs: int | None = None
                         ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`contact_arrays` of one contact of ``drive`` (exact model without ``springs``).

    The :class:`~passmd.model.parameters.Drive` checked its contacts' force, radius, moduli and
    friction coefficient on construction, so only ``springs`` is checked here.
    """
    E_star, G_star = contact_moduli(drive)
    model = "exact" if springs is None else "discrete"
    springs = None if springs is None else _check_springs(springs)
    return _contact_arrays(model, float(normal_force), float(radius), E_star, G_star,
                           drive.friction_coefficient, springs, DEFAULT_CAPACITY)


def _contact_arrays(model: str, F: float, R: float, E: float, G: float, mu: float, springs: int | None,
                    capacity: int) -> tuple[np.ndarray, np.ndarray]:
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


@njit(cache=True)
def _force_many(params, state, us):
    out = np.empty(us.size)
    for i in range(us.size):
        out[i] = contact_force(params, state, us[i])
    return out


@njit(cache=True)
def _path(params, state, us):
    out = np.empty(us.size)
    for i in range(us.size):
        out[i] = contact_update(params, state, us[i])
    return out


@njit(cache=True)
def _slip_many(params, state, us):
    out = np.empty(us.size)
    for i in range(us.size):
        out[i] = contact_slip_share(params, state, us[i])
    return out


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


class MDRContact:
    """One MDR contact with memory (Eqs. 4–6) for interactive use, tests and the book.

    Parameters
    ----------
    normal_force : float
        F_N, N.
    radius : float
        Hemisphere radius R, m.
    E_star, G_star : float
        Effective moduli E*, G*, Pa.
    mu : float
        Friction coefficient μ.
    springs : int or None
        None for the exact (N → ∞) model, else the number of springs N.
    capacity : int
        Reversal-stack capacity of the exact model.

    Notes
    -----
    Displacements are u = x_a − x_r in m; forces are on the runner, in N.
    """

    def __init__(self, normal_force, radius, E_star, G_star, mu, springs=None,
                 capacity=DEFAULT_CAPACITY):
        model = "exact" if springs is None else "discrete"
        arrays = contact_arrays(model, normal_force, radius, E_star, G_star, mu, springs, capacity)
        # Hertz and the MDR need a contact small against the sphere (hard limit a <= R/10)
        check_contact_plausible(normal_force, radius, E_star, names="normal_force, radius, E_star",
                                allow_extrapolation=True)
        self._set(model, arrays, springs, mu, radius, E_star, G_star)

    def _set(self, model, arrays, springs, mu, radius, E_star, G_star) -> None:
        self.model = model
        self.params, self.state = arrays
        self.springs = None if springs is None else int(springs)
        self.friction_coefficient = float(mu)
        self.hemisphere_radius = float(radius)
        self.E_star, self.G_star = float(E_star), float(G_star)

    @classmethod
    def for_drive(cls, drive: Drive, side: int = 0, springs=None, capacity=DEFAULT_CAPACITY):
        """Contact of one side of a drive: F_N from Eq. 1, (E*, G*) from the materials.

        ``side`` 0 is the two-contact side (F_N1), 1 the four-contact side (F_N2); a
        one-contact drive has side 0 only; a drive with ``contact_groups`` has one side per group
        (its own F_N and radius).
        """
        forces, _, radii = contact_layout(check_drive(drive))
        if isinstance(side, bool) or side not in range(len(forces)):
            raise ValueError(
                f"side = {side!r} is out of range: must be one of {list(range(len(forces)))} "
                f"for a drive with {drive.contacts} contact(s)"
            )
        model = "exact" if springs is None else "discrete"
        if springs is None:
            capacity = _check_capacity(capacity)
        else:
            springs = _check_springs(springs)
        E_star, G_star = contact_moduli(drive)
        F, R, mu = float(forces[side]), float(radii[side]), drive.friction_coefficient
        # the drive checked its contacts' force, radius and moduli (and a <= R/10): built unchecked
        contact = cls.__new__(cls)
        contact._set(model, _contact_arrays(model, F, R, E_star, G_star, mu, springs, capacity), springs, mu,
                     R, E_star, G_star)
        return contact

    # -- constants -------------------------------------------------------------------
    @property
    def normal_force(self) -> float:
        """F_N, N."""
        return float(self.params[P_NORMAL])

    @property
    def sliding_force(self) -> float:
        """μF_N, N."""
        return float(self.params[P_SLIDING])

    @property
    def presliding(self) -> float:
        """Displacement from rest to full sliding, m (exact: u_max of Eq. 7; discrete: largest w_i)."""
        return float(self.params[P_UMAX])

    @property
    def contact_radius(self) -> float:
        """Hertz contact radius a, m."""
        return float(self.params[P_RADIUS])

    @property
    def indentation(self) -> float:
        """Indentation d, m (exact: Hertz a²/R; discrete: solved for the spring grid)."""
        return float(self.params[P_INDENT])

    @property
    def stiffness(self) -> float:
        """Largest tangent stiffness, N/m (2aG* exact; Σ G*Δx in contact discrete)."""
        return float(contact_stiffness(self.params))

    # -- memory diagnostics ----------------------------------------------------------
    @property
    def displacement(self) -> float:
        """Last committed displacement u, m."""
        return float(self.state[S_U])

    @property
    def depth(self) -> int:
        """Reversal points currently on the stack (exact model; 0 for discrete)."""
        return int(self.state[S_DEPTH]) if self.model == "exact" else 0

    @property
    def max_depth(self) -> int:
        """Deepest stack reached since the last reset (exact model)."""
        return int(self.state[S_MAXDEPTH]) if self.model == "exact" else 0

    @property
    def reversal_count(self) -> int:
        """Reversals recorded since the last reset (exact model)."""
        return int(self.state[S_REVERSALS]) if self.model == "exact" else 0

    @property
    def overflow_count(self) -> int:
        """Reversals the full stack had to forget since the last reset (exact model)."""
        return int(self.state[S_OVERFLOW]) if self.model == "exact" else 0

    # -- evaluation ------------------------------------------------------------------
    def force(self, u):
        """Friction force T(u) on the runner given the memory (pure: memory unchanged).

        ``u`` may be a scalar or an array; each element is evaluated independently.
        """
        if np.ndim(u) == 0:
            return float(contact_force(self.params, self.state, check_range("u", u, unit="m")))
        us = check_array("u", u, unit="m")
        return _force_many(self.params, self.state, us.ravel()).reshape(us.shape)

    def update(self, u) -> float:
        """Move to ``u`` (committing it to the memory) and return T(u)."""
        return float(contact_update(self.params, self.state, check_range("u", u, unit="m")))

    def path(self, us) -> np.ndarray:
        """Forces along a sequence of displacements, committing each in turn."""
        arr = check_array("us", us, unit="m")
        return _path(self.params, self.state, np.ascontiguousarray(arr.ravel())).reshape(arr.shape)

    def slip_share(self, u):
        """Fraction of the springs in contact that slip at ``u`` (pure; scalar or array)."""
        if np.ndim(u) == 0:
            return float(contact_slip_share(self.params, self.state, check_range("u", u, unit="m")))
        us = check_array("u", u, unit="m")
        return _slip_many(self.params, self.state, us.ravel()).reshape(us.shape)

    def reset(self) -> None:
        """Back to virgin: u = 0, all springs unstrained, empty reversal stack."""
        contact_reset(self.params, self.state)

    def spring_states(self, u=None) -> pd.DataFrame:
        """State of every spring (discrete model), for the Fig. 4 picture.

        Parameters
        ----------
        u : float or None
            Evaluate as if moved to ``u`` (memory unchanged); None: the committed state.

        Returns
        -------
        pandas.DataFrame
            One row per spring: ``position_m`` x_i, ``profile_m`` g(x_i),
            ``normal_deflection_m`` (d − g)⁺, ``normal_force_N`` E*Δx(d − g)⁺,
            ``slip_m`` p_i, ``tangential_deflection_m`` clip(u − p_i, ±w_i),
            ``tangential_force_N`` G*Δx times that, ``slipping`` (at its limit).
        """
        if self.model != "discrete":
            raise ValueError("spring_states is only defined for model = 'discrete' (springs = an integer)")
        n = self.springs
        u = self.displacement if u is None else check_range("u", u, unit="m")
        limits = self.params[PARAMS_HEADER : PARAMS_HEADER + n]
        x = self.params[PARAMS_HEADER + n : PARAMS_HEADER + 2 * n]
        slip = self.state[STATE_HEADER : STATE_HEADER + n].copy()
        trial = u - slip
        deflection = np.clip(trial, -limits, limits)
        slip = u - deflection
        profile = x**2 / self.hemisphere_radius
        normal = np.maximum(self.indentation - profile, 0.0)
        import pandas as pd

        return pd.DataFrame(
            {
                "position_m": x,
                "profile_m": profile,
                "normal_deflection_m": normal,
                "normal_force_N": self.E_star * self.params[P_SPACING] * normal,
                "slip_m": slip,
                "tangential_deflection_m": deflection,
                "tangential_force_N": self.params[P_SPRING_K] * deflection,
                "slipping": (limits > 0) & (np.abs(trial) >= limits * (1 - LIMIT_RTOL)),
            }
        )

    def __repr__(self) -> str:
        n = "" if self.springs is None else f", springs={self.springs}"
        return (f"MDRContact({self.model}, F_N={self.normal_force:g} N, μF_N={self.sliding_force:g} N, "
                f"u_max={self.presliding:g} m{n})")
