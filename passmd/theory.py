"""Closed-form results: Hertz, Cattaneo–Mindlin, and the paper's Eqs. 1 and 7–14.

Conventions (MDR, Popov 2013; see the model chapter):

* 1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂
* 1/G* = (2 − ν₁)/(4 G₁) + (2 − ν₂)/(4 G₂),  G = E / (2 (1 + ν))

This G* is four times Mindlin's "G", so the tangential stiffness of a sticking
Hertzian contact, 8aG in Mindlin's notation, is 2aG* here.

References: H. Hertz (1882); R.D. Mindlin, H. Deresiewicz, J. Appl. Mech. 20 (1953)
327; K.L. Johnson, *Contact Mechanics* (1985), §7.2; V.L. Popov, Friction 1 (2013) 41.

Every function is vectorised (NumPy broadcasting) and uses SI units.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from passmd._validation import check_array
from passmd.defaults import PROTOCOL

if TYPE_CHECKING:  # the closed forms read a drive's fields; parameters imports this module
    from passmd.parameters import Drive

SIN45 = np.sin(np.pi / 4)


def effective_youngs_modulus(E1, nu1, E2, nu2):
    """Effective modulus E* with 1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂ (Eq. 4)."""
    return 1.0 / ((1 - np.asarray(nu1) ** 2) / E1 + (1 - np.asarray(nu2) ** 2) / E2)


def effective_shear_modulus(E1, nu1, E2, nu2):
    """Effective shear modulus G* with 1/G* = Σ (2 − ν)/(4G), G = E/(2(1+ν)) (Eq. 4)."""
    G1 = np.asarray(E1) / (2 * (1 + np.asarray(nu1)))
    G2 = np.asarray(E2) / (2 * (1 + np.asarray(nu2)))
    return 1.0 / ((2 - np.asarray(nu1)) / (4 * G1) + (2 - np.asarray(nu2)) / (4 * G2))


def contact_moduli(drive: Drive) -> tuple[float, float]:
    """(E*, G*) of the hemisphere/runner pair of a drive, in Pa."""
    h, r = drive.hemisphere_material, drive.runner_material
    args = (h.youngs_modulus, h.poissons_ratio, r.youngs_modulus, r.poissons_ratio)
    return float(effective_youngs_modulus(*args)), float(effective_shear_modulus(*args))


def hertz_contact_radius(normal_force, radius, E_star):
    """Hertz contact radius a = (3 F_N R / (4 E*))^(1/3)."""
    F = check_array("normal_force", normal_force, 0.0)
    return np.cbrt(3.0 * F * radius / (4.0 * E_star))


def hertz_indentation(normal_force, radius, E_star):
    """Hertz indentation depth d = a² / R."""
    return hertz_contact_radius(normal_force, radius, E_star) ** 2 / radius


def hertz_normal_force(contact_radius, radius, E_star):
    """Hertz normal force F_N = (4/3) E* a³ / R."""
    return 4.0 / 3.0 * E_star * np.asarray(contact_radius) ** 3 / radius


def tangential_stiffness(normal_force, radius, E_star, G_star):
    """Initial tangential stiffness 2 a G* of a sticking Hertzian contact (8aG in Mindlin)."""
    return 2.0 * hertz_contact_radius(normal_force, radius, E_star) * G_star


def normal_forces(preload, contacts: int = 6):
    """Normal force per contact on each side of the runner (Eq. 1).

    Six contacts: F_N1 = F_p / (2 sin 45°) on each of the two right-hand contacts,
    F_N2 = F_p / (4 sin 45°) on each of the four left-hand ones. One contact: F_p.

    Returns
    -------
    tuple of arrays
        ``(F_N1, F_N2)`` for six contacts, ``(F_p,)`` for one.
    """
    F = check_array("preload", preload, 0.0, lower_open=True, unit="N")
    if contacts == 1:
        return (F,)
    if contacts == 6:
        return (F / 2.0 / SIN45, F / 4.0 / SIN45)
    raise ValueError(f"contacts = {contacts!r} is not allowed: must be one of 1, 6")


def presliding_displacement(normal_force, radius, E_star, G_star, friction_coefficient):
    """Presliding (full-slip) displacement u_x,max (Eq. 7, Eq. 10).

    u_x,max = 3μ/(4G*) · (4E*/3)^(1/3) · F_N^(2/3) / R^(1/3), which equals μ (E*/G*) d
    with the Hertz indentation d.
    """
    F = check_array("normal_force", normal_force, 0.0)
    return (
        3.0
        * friction_coefficient
        / (4.0 * G_star)
        * np.cbrt(4.0 * E_star / 3.0)
        * F ** (2.0 / 3.0)
        / np.cbrt(radius)
    )


def actuator_deformation(friction_coefficient, normal_force, actuator_stiffness, runner_mass,
                         actuator_mass):
    """Tangential deformation of the actuator by the friction force (Eq. 9, Eq. 14).

    u_x,a = μ F / k_p · (m_r + m_a) / m_r (van der Wulp 1997).
    """
    F = check_array("normal_force", normal_force, 0.0)
    return friction_coefficient * F / actuator_stiffness * (runner_mass + actuator_mass) / runner_mass


def harmonic_combination(u1, u2):
    """Teidelt's combination 2 u₁ u₂ / (u₁ + u₂) (Eq. 11, Eq. 12)."""
    u1, u2 = np.asarray(u1, dtype=float), np.asarray(u2, dtype=float)
    return 2.0 * u1 * u2 / (u1 + u2)


def cattaneo_mindlin_force(u, normal_force, presliding, friction_coefficient):
    """Virgin tangential force of a Hertzian contact at constant normal force.

    F(u) = sign(u) μF_N [1 − (1 − |u|/u_max)^(3/2)] for |u| ≤ u_max, ±μF_N beyond
    (Cattaneo 1938, Mindlin 1949). Initial slope (3/2) μF_N / u_max = 2aG*.
    """
    u = np.asarray(u, dtype=float)
    s = np.clip(np.abs(u) / presliding, 0.0, 1.0)
    return np.sign(u) * friction_coefficient * normal_force * (1.0 - (1.0 - s) ** 1.5)


def masing_branch_force(u, reversal_displacement, reversal_force, direction, normal_force,
                        presliding, friction_coefficient):
    """Force on an unloading/reloading branch after a reversal (Mindlin–Deresiewicz, Masing).

    F = F_r + direction · 2 φ(|u − u_r| / 2), φ the virgin curve, limited to ±μF_N
    (full sliding). ``direction`` is +1 for increasing u, −1 for decreasing u.
    """
    u = np.asarray(u, dtype=float)
    half = np.abs(u - reversal_displacement) / 2.0
    phi = cattaneo_mindlin_force(half, normal_force, presliding, friction_coefficient)
    limit = friction_coefficient * normal_force
    return np.clip(reversal_force + direction * 2.0 * phi, -limit, limit)


def drive_theory(drive: Drive) -> dict:
    """The closed forms for one drive configuration, SI units.

    Keys: ``E_star_Pa``, ``G_star_Pa``, ``normal_force_N`` (per side),
    ``contact_radius_m``, ``indentation_m``, ``tangential_stiffness_N_per_m``,
    ``presliding_m`` (u_x,max per side, Eq. 7/10), ``actuator_deformation_m``
    (u_x,a per side, Eq. 9/14), ``critical_amplitude_rigid_m`` (Eq. 7 / Eq. 11),
    ``critical_amplitude_flexible_m`` (Eq. 8 / Eq. 12) and
    ``analytic_critical_amplitude_m`` (the one matching ``drive.actuator_model``).
    """
    E_star, G_star = contact_moduli(drive)
    R, mu = drive.hemisphere_radius, drive.friction_coefficient
    act = drive.actuator
    forces = np.array([float(f) for f in normal_forces(drive.preload, drive.contacts)])
    u_max = presliding_displacement(forces, R, E_star, G_star, mu)
    u_a = actuator_deformation(mu, forces, act.stiffness, drive.runner_mass, act.mass)
    if drive.contacts == 1:
        rigid, flexible = float(u_max[0]), float(u_max[0] + u_a[0])
    else:
        rigid = float(harmonic_combination(u_max[0], u_max[1]))
        flexible = float(harmonic_combination(u_max[0] + u_a[0], u_max[1] + u_a[1]))
    return {
        "E_star_Pa": E_star,
        "G_star_Pa": G_star,
        "normal_force_N": forces.tolist(),
        "contact_radius_m": hertz_contact_radius(forces, R, E_star).tolist(),
        "indentation_m": hertz_indentation(forces, R, E_star).tolist(),
        "tangential_stiffness_N_per_m": tangential_stiffness(forces, R, E_star, G_star).tolist(),
        "presliding_m": u_max.tolist(),
        "actuator_deformation_m": u_a.tolist(),
        "critical_amplitude_rigid_m": rigid,
        "critical_amplitude_flexible_m": flexible,
        "analytic_critical_amplitude_m": rigid if drive.actuator_model == "rigid" else flexible,
    }


def runner_frequency(drive: Drive) -> float:
    """Runner-on-contacts natural frequency √(Σ 2aG* / m_r) / (2π) in Hz (rigid actuators).

    Σ runs over all contacts (2 × side 1 + 4 × side 2 for six contacts), plus the
    load cell when engaged. This is the micro-vibration frequency's linear estimate.
    """
    E_star, G_star = contact_moduli(drive)
    forces = normal_forces(drive.preload, drive.contacts)
    multiplicity = (1,) if drive.contacts == 1 else PROTOCOL.contacts_per_side
    k_total = sum(
        m * float(tangential_stiffness(F, drive.hemisphere_radius, E_star, G_star))
        for m, F in zip(multiplicity, forces, strict=True)
    )
    k_total += drive.effective_load_cell_stiffness
    return float(np.sqrt(k_total / drive.runner_mass) / (2 * np.pi))


def friction_limit(drive: Drive) -> float:
    """Total Coulomb friction limit μ Σ F_N of all contacts on the runner (N, Eq. 1).

    Six contacts: μ (2 F_N1 + 4 F_N2) = 2√2 μ F_p; one contact: μ F_p.
    """
    forces = normal_forces(drive.preload, drive.contacts)
    multiplicity = (1,) if drive.contacts == 1 else PROTOCOL.contacts_per_side
    return float(drive.friction_coefficient * sum(m * float(F) for m, F in zip(multiplicity, forces,
                                                                                  strict=True)))


def coulomb_sawtooth_step(amplitude, frequency, flyback_time, friction_force, runner_mass):
    """Step per period of a rigid-actuator saw-tooth drive with Coulomb friction.

    The limit of the drive of Eqs. 2–6 when the contact stiffness goes to infinity: the
    presliding (Eq. 7) vanishes and every contact becomes a rigid Coulomb contact, so the
    drive is the idealised inertia (stick–slip) drive of M. Hunstig, "Piezoelectric
    Inertia Motors—A Critical Review of History, Concepts, Design, Applications, and
    Perspectives", Actuators 6 (2017) 7, Sections 2–3 (see also M. Hunstig, T. Hemsel,
    W. Sextro, Sens. Actuators A 200 (2013) 90, the paper's ref. 21). The closed form
    below is derived here for the saw-tooth of :func:`passmd.waveforms.sawtooth`.

    Assumptions: rigid actuators (the hemispheres follow x_p exactly); one runner of mass
    m_r, no load cell; Coulomb friction with one coefficient for sticking and sliding,
    total limit F_c = μ Σ F_N, so the runner's friction acceleration is at most
    a = F_c / m_r; no presliding, no elastic play; x_p(t) a saw-tooth of amplitude A,
    period T = 1/f: a linear ramp 0 → A of duration t_r = T − t_f (velocity
    v_r = A / t_r) and a linear fly-back A → 0 of duration t_f (velocity v_f = −A / t_f),
    with t_f < t_r; periodic steady state.

    Derivation. On a linear piece x_p has zero acceleration, so a runner moving with the
    piezo needs no friction force and sticks. At each corner the piezo velocity jumps
    while the runner's cannot: the runner slips and friction, of magnitude F_c against
    the relative velocity, changes its velocity at the rate a until it matches the
    piezo's, when it sticks again. Start a period at the corner ramp → fly-back with the
    runner stuck (velocity v_r). Its relative velocity v − v_f = v_r − v_f − a t > 0
    falls linearly; two cases:

    1. a t_f < v_r − v_f, i.e. a t_f² < A + v_r t_f = A T / t_r: the runner slides
       through the whole fly-back, relative slip (v_r − v_f) t_f − a t_f²/2, and leaves
       it at v_r − a t_f < v_r. On the ramp it is accelerated at +a and re-sticks after
       exactly t_f (< t_r), relative slip −a t_f²/2. Net step per period (x_p returns
       to where it started, so the step is the total relative slip)::

           s = (v_r − v_f) t_f − a t_f² = A T / t_r − a t_f²  (> 0 in this case).

    2. a t_f ≥ v_r − v_f: the runner reaches v_f after t* = (v_r − v_f)/a ≤ t_f and
       sticks for the rest of the fly-back (relative slip (v_r − v_f)²/(2a)). At the
       corner back to the ramp the jump v_f → v_r is the same size, the slip lasts t*
       again and is (v_r − v_f)²/(2a) backwards: s = 0, the runner only follows.

    Both cases together: s = max(A T / t_r − a t_f², 0), continuous at the boundary.
    The first, from rest, corner (0 → v_r) only offsets the runner by −v_r²/(2a) and
    the runner sticks again after v_r/a; from the first fly-back on every period is the
    steady state above. For t_f → 0 the step tends to A (the ideal saw-tooth).

    Parameters
    ----------
    amplitude : array_like
        Saw-tooth amplitude A in m, ≥ 0.
    frequency : array_like
        Driving frequency f = 1/T in Hz, > 0.
    flyback_time : array_like
        Fly-back duration t_f in s, 0 < t_f < T/2 (so that t_f < t_r).
    friction_force : array_like
        Total Coulomb friction limit F_c = μ Σ F_N in N, > 0 (:func:`friction_limit`).
    runner_mass : array_like
        Runner mass m_r in kg, > 0.

    Returns
    -------
    ndarray
        Net runner step per period s in m (forward, in the ramp's direction), ≥ 0.
    """
    A = check_array("amplitude", amplitude, 0.0, unit="m")
    f = check_array("frequency", frequency, 0.0, lower_open=True, unit="Hz")
    t_f = check_array("flyback_time", flyback_time, 0.0, lower_open=True, unit="s")
    F_c = check_array("friction_force", friction_force, 0.0, lower_open=True, unit="N")
    m_r = check_array("runner_mass", runner_mass, 0.0, lower_open=True, unit="kg")
    T = 1.0 / f
    if np.any(t_f >= 0.5 * T):
        bad = np.broadcast_arrays(t_f, T)
        i = int(np.flatnonzero((bad[0] >= 0.5 * bad[1]).ravel())[0])
        raise ValueError(
            f"flyback_time = {float(bad[0].ravel()[i])!r} is out of range: must be < half the period "
            f"{float(0.5 * bad[1].ravel()[i])!r} s (the runner must re-stick on the ramp)"
        )
    t_r = T - t_f
    a = F_c / m_r
    return np.maximum(A * T / t_r - a * t_f**2, 0.0)
