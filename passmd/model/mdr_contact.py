"""One MDR contact with memory as an object (Eqs. 4–6), for interactive use, tests and the book.

:class:`MDRContact` holds one contact's parameter and state arrays
(:func:`passmd.model.contact.contact_arrays`) and evaluates the numba kernels of
:mod:`passmd.model.contact` on them: the friction force T(u) on the runner without and with
committing u to the memory, the slip share, the reversal-stack diagnostics, and (discrete model)
every spring's state for the Fig. 4 picture. The simulation does not use it: it works on the
stacked arrays directly.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from passmd.model.contact import (
    DEFAULT_CAPACITY,
    check_capacity,
    check_springs,
    contact_arrays,
    unchecked_contact_arrays,
)
from passmd.model.contact_kernels import (
    LIMIT_RTOL,
    P_INDENT,
    P_NORMAL,
    P_RADIUS,
    P_SLIDING,
    P_SPACING,
    P_SPRING_K,
    P_UMAX,
    PARAMS_HEADER,
    S_DEPTH,
    S_MAXDEPTH,
    S_OVERFLOW,
    S_REVERSALS,
    S_U,
    STATE_HEADER,
    contact_force,
    contact_reset,
    contact_slip_share,
    contact_stiffness,
    contact_update,
)
from passmd.model.parameters import Drive, check_contact_plausible, check_drive
from passmd.runtime.validation import check_array, check_range

if TYPE_CHECKING:  # pandas is imported where a DataFrame is built (start-up time)
    import pandas as pd

__all__ = ["MDRContact"]


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
        forces, _, radii = check_drive(drive).contact_layout
        if isinstance(side, bool) or side not in range(len(forces)):
            raise ValueError(
                f"side = {side!r} is out of range: must be one of {list(range(len(forces)))} "
                f"for a drive with {drive.contacts} contact(s)"
            )
        model = "exact" if springs is None else "discrete"
        if springs is None:
            capacity = check_capacity(capacity)
        else:
            springs = check_springs(springs)
        E_star, G_star = drive.contact_moduli
        F, R, mu = float(forces[side]), float(radii[side]), drive.friction_coefficient
        # the drive checked its contacts' force, radius and moduli (and a <= R/10): built unchecked
        contact = cls.__new__(cls)
        arrays = unchecked_contact_arrays(model, F, R, E_star, G_star, mu, springs, capacity)
        contact._set(model, arrays, springs, mu, R, E_star, G_star)
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
