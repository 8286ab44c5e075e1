"""Closed forms of one Hertzian contact: Hertz's normal contact and Cattaneo–Mindlin's tangential one.

The effective moduli of a material pair (Eq. 4), Hertz's contact radius, indentation and normal
force, the initial tangential stiffness 2aG* of a sticking contact, the virgin Cattaneo–Mindlin
force and the Mindlin–Deresiewicz/Masing branch after a reversal. Conventions (MDR, Popov 2013;
see the model chapter): 1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂ and 1/G* = (2 − ν₁)/(4 G₁) +
(2 − ν₂)/(4 G₂) with G = E / (2 (1 + ν)); this G* is four times Mindlin's "G", so the tangential
stiffness of a sticking Hertzian contact, 8aG in Mindlin's notation, is 2aG* here. References:
H. Hertz (1882); R.D. Mindlin, H. Deresiewicz, J. Appl. Mech. 20 (1953) 327; K.L. Johnson,
*Contact Mechanics* (1985), §7.2; V.L. Popov, Friction 1 (2013) 41. Every function is vectorised
(NumPy broadcasting), uses SI units, checks its arguments (``ValueError`` naming the parameter,
its value and the allowed range) and refuses a result below the smallest normal double
(2.2e-308), which keeps only a few significant digits. The drive's closed forms, which combine
these per contact, are in :mod:`passmd.model.theory`.
"""

from __future__ import annotations

import numpy as np

from passmd.runtime.validation import InputError, check_array, format_number

__all__ = [
    "cattaneo_mindlin_force",
    "effective_shear_modulus",
    "effective_youngs_modulus",
    "hertz_contact_radius",
    "hertz_indentation",
    "hertz_normal_force",
    "masing_branch_force",
    "tangential_stiffness",
]

#: Smallest normal double: below it a float keeps fewer than 53 significant bits.
_TINY = float(np.finfo(float).tiny)
#: Isotropic elasticity needs -1 < ν <= 1/2 (a positive bulk and shear modulus).
_NU_LOW, _NU_HIGH = -1.0, 0.5


def _positive(name: str, value, unit: str) -> np.ndarray:
    return check_array(name, value, 0.0, lower_open=True, unit=unit)


def _require_normal(value, what: str, unit: str, inputs, where=None) -> None:
    """Refuse ``value`` where it is below the smallest normal double (or not finite).

    ``inputs``: ``(name, value, unit)`` of the parameters that made it, the one a user most
    likely set first (the message leads with it); each is shown at the first refused element.
    ``where``: the elements that must be normal (default all).
    """
    v = np.asarray(value, dtype=float)
    bad = ~(np.isfinite(v) & (np.abs(v) >= _TINY))
    if where is not None:
        bad &= np.broadcast_to(np.asarray(where, dtype=bool), bad.shape)
    if not bad.any():
        return
    i = int(np.flatnonzero(bad.ravel())[0])
    shown = [f"{name} = {format_number(np.broadcast_to(np.asarray(x, dtype=float), v.shape).flat[i])}"
             + (f" {u}" if u else "") for name, x, u in inputs]
    context = f" (with {', '.join(shown[1:])})" if len(shown) > 1 else ""
    detail = (f"{what} = {format_number(v.flat[i])} {unit} is below the smallest normal double {_TINY:.4g} "
              "(hard limit: double precision; there a result keeps only a few significant digits)")
    # the inputs' names let an entry point name its own options (passmd.cli.drive.explain)
    raise InputError(f"{shown[0]}{context} is out of range: {detail}",
                     sources=tuple(name for name, _, _ in inputs), detail=detail)


def _youngs(E1, nu1, E2, nu2):
    return 1.0 / ((1 - np.asarray(nu1) ** 2) / E1 + (1 - np.asarray(nu2) ** 2) / E2)


def _shear(E1, nu1, E2, nu2):
    G1 = np.asarray(E1) / (2 * (1 + np.asarray(nu1)))
    G2 = np.asarray(E2) / (2 * (1 + np.asarray(nu2)))
    return 1.0 / ((2 - np.asarray(nu1)) / (4 * G1) + (2 - np.asarray(nu2)) / (4 * G2))


def _materials(E1, nu1, E2, nu2):
    """The four material constants, checked (E > 0, -1 < ν <= 1/2)."""
    return (_positive("E1", E1, "Pa"), check_array("nu1", nu1, _NU_LOW, _NU_HIGH, lower_open=True),
            _positive("E2", E2, "Pa"), check_array("nu2", nu2, _NU_LOW, _NU_HIGH, lower_open=True))


def effective_youngs_modulus(E1, nu1, E2, nu2):
    """Effective modulus E* with 1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂ (Eq. 4).

    E₁, E₂ > 0 in Pa; -1 < ν₁, ν₂ <= 1/2.
    """
    args = _materials(E1, nu1, E2, nu2)
    E_star = _youngs(*args)
    _require_normal(E_star, "E*", "Pa", (("E1", args[0], "Pa"), ("E2", args[2], "Pa")))
    return E_star


def effective_shear_modulus(E1, nu1, E2, nu2):
    """Effective shear modulus G* with 1/G* = Σ (2 − ν)/(4G), G = E/(2(1+ν)) (Eq. 4).

    E₁, E₂ > 0 in Pa; -1 < ν₁, ν₂ <= 1/2.
    """
    args = _materials(E1, nu1, E2, nu2)
    G_star = _shear(*args)
    _require_normal(G_star, "G*", "Pa", (("E1", args[0], "Pa"), ("E2", args[2], "Pa")))
    return G_star


def _hertz_cube(F, radius, E_star):
    """a³ = 3 F_N R / (4 E*), the cube of the Hertz contact radius."""
    return 3.0 * F * radius / (4.0 * E_star)


def _contact_args(normal_force, radius, E_star):
    """normal_force >= 0, radius > 0, E_star > 0, checked (as arrays)."""
    F = check_array("normal_force", normal_force, 0.0, unit="N")
    return F, _positive("radius", radius, "m"), _positive("E_star", E_star, "Pa")


def _hertz_contact_radius(F, R, E):
    """a = (3 F_N R / (4 E*))^(1/3) of F_N >= 0, R > 0, E* > 0 its caller has checked (the public
    :func:`hertz_contact_radius`, or a drive's contact, which :class:`~passmd.model.parameters.Drive`
    checked); a³ is refused where F_N > 0 and it is below the smallest normal double."""
    cube = _hertz_cube(F, R, E)
    _require_normal(cube, "the Hertz contact radius cubed, 3 F_N R / (4 E*),", "m^3",
                    (("normal_force", F, "N"), ("radius", R, "m"), ("E_star", E, "Pa")), where=F > 0)
    return np.cbrt(cube)


def hertz_contact_radius(normal_force, radius, E_star):
    """Hertz contact radius a = (3 F_N R / (4 E*))^(1/3).

    F_N >= 0 in N, R > 0 in m, E* > 0 in Pa.
    """
    return _hertz_contact_radius(*_contact_args(normal_force, radius, E_star))


def hertz_indentation(normal_force, radius, E_star):
    """Hertz indentation depth d = a² / R."""
    F, R, E = _contact_args(normal_force, radius, E_star)
    return _hertz_contact_radius(F, R, E) ** 2 / R


def hertz_normal_force(contact_radius, radius, E_star):
    """Hertz normal force F_N = (4/3) E* a³ / R (a >= 0 in m, R > 0 in m, E* > 0 in Pa)."""
    a = check_array("contact_radius", contact_radius, 0.0, unit="m")
    R, E = _positive("radius", radius, "m"), _positive("E_star", E_star, "Pa")
    force = 4.0 / 3.0 * E * a ** 3 / R
    _require_normal(force, "the Hertz normal force", "N", (("contact_radius", a, "m"),), where=a > 0)
    return force


def tangential_stiffness(normal_force, radius, E_star, G_star):
    """Initial tangential stiffness 2 a G* of a sticking Hertzian contact (8aG in Mindlin).

    F_N >= 0 in N, R > 0 in m, E* > 0 and G* > 0 in Pa.
    """
    a = _hertz_contact_radius(*_contact_args(normal_force, radius, E_star))
    return 2.0 * a * _positive("G_star", G_star, "Pa")


def cattaneo_mindlin_force(u, normal_force, presliding, friction_coefficient):
    """Virgin tangential force of a Hertzian contact at constant normal force.

    F(u) = sign(u) μF_N [1 − (1 − |u|/u_max)^(3/2)] for |u| ≤ u_max, ±μF_N beyond
    (Cattaneo 1938, Mindlin 1949). Initial slope (3/2) μF_N / u_max = 2aG*. u finite
    in m, F_N >= 0 in N, u_max > 0 in m (``presliding``), μ > 0.
    """
    return _cattaneo_mindlin(check_array("u", u, unit="m"),
                             check_array("normal_force", normal_force, 0.0, unit="N"),
                             _positive("presliding", presliding, "m"),
                             _positive("friction_coefficient", friction_coefficient, ""))


def _cattaneo_mindlin(u, normal_force, presliding, friction_coefficient):
    s = np.clip(np.abs(u) / presliding, 0.0, 1.0)
    return np.sign(u) * friction_coefficient * normal_force * (1.0 - (1.0 - s) ** 1.5)


def masing_branch_force(u, reversal_displacement, reversal_force, direction, normal_force,
                        presliding, friction_coefficient):
    """Force on an unloading/reloading branch after a reversal (Mindlin–Deresiewicz, Masing).

    F = F_r + direction · 2 φ(|u − u_r| / 2), φ the virgin curve, limited to ±μF_N
    (full sliding). ``direction`` is +1 for increasing u, −1 for decreasing u; u and u_r
    finite in m, F_r finite in N, the rest as in :func:`cattaneo_mindlin_force`.
    """
    u = check_array("u", u, unit="m")
    u_r = check_array("reversal_displacement", reversal_displacement, unit="m")
    F_r = check_array("reversal_force", reversal_force, unit="N")
    if isinstance(direction, (bool, np.bool_)) or direction not in (1, -1):
        raise ValueError(f"direction = {direction!r} is not allowed: must be one of 1, -1")
    F = check_array("normal_force", normal_force, 0.0, unit="N")
    u_max = _positive("presliding", presliding, "m")
    mu = _positive("friction_coefficient", friction_coefficient, "")
    half = np.abs(u - u_r) / 2.0
    phi = _cattaneo_mindlin(half, F, u_max, mu)
    limit = mu * F
    return np.clip(F_r + direction * 2.0 * phi, -limit, limit)
