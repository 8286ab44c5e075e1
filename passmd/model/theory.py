"""The paper's closed forms for a whole drive: Eq. 1's normal forces and Eqs. 7–14.

The normal force per contact (Eq. 1), the presliding displacement (Eqs. 7, 10), the actuator's
deformation (Eqs. 9, 14), Teidelt's combination of the two contact sides (Eqs. 11, 12), all of
them for one drive (:func:`drive_theory`, from the Eq. 1 layout and moduli the
:class:`~passmd.model.parameters.Drive` computed once), the runner's natural frequency on its
contacts, the total friction limit and the rigid Coulomb limit of a saw-tooth drive. They build on
the single-contact closed forms of :mod:`passmd.model.hertz` (its MDR conventions for E* and G*).
Every function is vectorised and uses SI units; the public ones check their arguments
(``ValueError``/``TypeError`` naming the parameter, its value and the allowed range) and refuse a
result that double precision cannot hold to its full relative precision (below the smallest
normal double, 2.2e-308). The drive's closed forms name the drive's parameters instead.
"""

from __future__ import annotations

import reprlib

import numpy as np

from passmd.model.arrangement import group_sides, preset_groups
from passmd.model.hertz import _TINY, _hertz_cube, _positive, _require_normal
from passmd.model.parameters import Drive
from passmd.runtime.validation import check_array

SIN45 = np.sin(np.pi / 4)


def _check_drive(drive) -> None:
    if not isinstance(drive, Drive):
        raise TypeError(f"drive = {reprlib.repr(drive)} is not allowed: "
                        "must be a passmd.model.parameters.Drive")


def _check_contacts(contacts) -> int:
    if isinstance(contacts, (bool, np.bool_)) or not isinstance(contacts, (int, np.integer)):
        raise TypeError(f"contacts = {contacts!r} is not allowed: must be the integer 1 or 6")
    if contacts not in (1, 6):
        raise ValueError(f"contacts = {contacts!r} is not allowed: must be one of 1, 6")
    return int(contacts)


def contact_moduli(drive: Drive) -> tuple[float, float]:
    """(E*, G*) of the hemisphere/runner pair of a drive, in Pa (Eq. 4), as the drive computed them.

    The drive's own :attr:`~passmd.model.parameters.Drive.contact_moduli`.
    """
    _check_drive(drive)
    return drive.contact_moduli


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
    if _check_contacts(contacts) == 1:
        return (F,)
    forces = _six_contact_forces(F)
    _require_normal(forces[1], "the normal force per contact F_p / (4 sin 45°)", "N", (("preload", F, "N"),))
    return forces


def _six_contact_forces(F):
    return (F / 2.0 / SIN45, F / 4.0 / SIN45)


def _presliding(F, radius, E_star, G_star, friction_coefficient):
    return (
        3.0
        * friction_coefficient
        / (4.0 * G_star)
        * np.cbrt(4.0 * E_star / 3.0)
        * F ** (2.0 / 3.0)
        / np.cbrt(radius)
    )


def presliding_displacement(normal_force, radius, E_star, G_star, friction_coefficient):
    """Presliding (full-slip) displacement u_x,max (Eq. 7, Eq. 10).

    u_x,max = 3μ/(4G*) · (4E*/3)^(1/3) · F_N^(2/3) / R^(1/3), which equals μ (E*/G*) d
    with the Hertz indentation d. F_N >= 0 in N, R > 0 in m, E* > 0 and G* > 0 in Pa,
    μ > 0 (``friction_coefficient``).
    """
    F = check_array("normal_force", normal_force, 0.0, unit="N")
    R, E = _positive("radius", radius, "m"), _positive("E_star", E_star, "Pa")
    G, mu = _positive("G_star", G_star, "Pa"), _positive("friction_coefficient", friction_coefficient, "")
    u = _presliding(F, R, E, G, mu)
    _require_normal(u, "the presliding displacement u_x,max", "m",
                    (("normal_force", F, "N"), ("friction_coefficient", mu, "")), where=F > 0)
    return u


def _actuator_deformation(friction_coefficient, F, actuator_stiffness, runner_mass, actuator_mass):
    return friction_coefficient * F / actuator_stiffness * (runner_mass + actuator_mass) / runner_mass


def actuator_deformation(friction_coefficient, normal_force, actuator_stiffness, runner_mass,
                         actuator_mass):
    """Tangential deformation of the actuator by the friction force (Eq. 9, Eq. 14).

    u_x,a = μ F / k_p · (m_r + m_a) / m_r (van der Wulp 1997). μ > 0, F_N >= 0 in N,
    k_p > 0 in N/m, m_r > 0 and m_a >= 0 in kg.
    """
    mu = _positive("friction_coefficient", friction_coefficient, "")
    F = check_array("normal_force", normal_force, 0.0, unit="N")
    k = _positive("actuator_stiffness", actuator_stiffness, "N/m")
    m_r = _positive("runner_mass", runner_mass, "kg")
    m_a = check_array("actuator_mass", actuator_mass, 0.0, unit="kg")
    u = _actuator_deformation(mu, F, k, m_r, m_a)
    _require_normal(u, "the actuator deformation u_x,a", "m",
                    (("normal_force", F, "N"), ("friction_coefficient", mu, ""),
                     ("actuator_stiffness", k, "N/m")), where=F > 0)
    return u


def _harmonic(u1, u2):
    """2 u₁ u₂ / (u₁ + u₂) without underflow or overflow, for positive finite u₁, u₂.

    The paper's form wherever its product and sum are normal doubles (there it is accurate to
    a few units in the last place, and it is what every result was computed with); else the
    same value as m · 2 / (1 + m/M), m = min, M = max, whose factor lies in (1, 2]. The result
    lies between min(u₁, u₂) and twice it at every magnitude.
    """
    u1, u2 = np.asarray(u1, dtype=float), np.asarray(u2, dtype=float)
    with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
        product, total = 2.0 * u1 * u2, u1 + u2
        direct = product / total
        small, large = np.minimum(u1, u2), np.maximum(u1, u2)
        scaled = small * (2.0 / (1.0 + small / large))
    safe = np.isfinite(product) & (product >= _TINY) & np.isfinite(total)
    # the exact value lies in [m, 2m]; rounding could leave it one unit in the last place outside
    result = np.minimum(np.maximum(np.where(safe, direct, scaled), small), 2.0 * small)
    return result if result.ndim else result[()]


def harmonic_combination(u1, u2):
    """Teidelt's combination 2 u₁ u₂ / (u₁ + u₂) (Eq. 11, Eq. 12), u₁, u₂ > 0 in m.

    Finite and between min(u₁, u₂) and twice it for every positive finite u₁, u₂: computed
    where the product would underflow or overflow as m · 2 / (1 + m/M).
    """
    return _harmonic(_positive("u1", u1, "m"), _positive("u2", u2, "m"))


def drive_theory(drive: Drive) -> dict:
    """The closed forms for one drive configuration, SI units.

    Keys: ``E_star_Pa``, ``G_star_Pa``, ``normal_force_N`` (per side),
    ``contact_radius_m``, ``indentation_m``, ``tangential_stiffness_N_per_m``,
    ``presliding_m`` (u_x,max per side, Eq. 7/10), ``actuator_deformation_m``
    (u_x,a per side, Eq. 9/14), ``critical_amplitude_rigid_m`` (Eq. 7 / Eq. 11),
    ``critical_amplitude_flexible_m`` (Eq. 8 / Eq. 12) and
    ``analytic_critical_amplitude_m`` (the one matching ``drive.actuator_model``).
    """
    _check_drive(drive)
    E_star, G_star = drive.contact_moduli
    mu = drive.friction_coefficient
    act = drive.actuator
    forces, _, R = drive.contact_layout
    preload = ("preload", drive.preload, "N")
    a = _drive_contact_radius(drive, forces, E_star, R)
    u_max = _presliding(forces, R, E_star, G_star, mu)
    _require_normal(u_max, "the presliding displacement u_x,max", "m",
                    (preload, ("friction_coefficient", mu, "")))
    u_a = _actuator_deformation(mu, forces, act.stiffness, drive.runner_mass, act.mass)
    _require_normal(u_a, "the actuator deformation u_x,a", "m",
                    (preload, ("friction_coefficient", mu, ""), ("actuator.stiffness", act.stiffness, "N/m")))
    rigid, flexible = _combined(u_max), _combined(u_max + u_a)
    return {
        "E_star_Pa": E_star,
        "G_star_Pa": G_star,
        "normal_force_N": forces.tolist(),
        "contact_radius_m": a.tolist(),
        "indentation_m": (a ** 2 / R).tolist(),
        "tangential_stiffness_N_per_m": (2.0 * a * G_star).tolist(),
        "presliding_m": u_max.tolist(),
        "actuator_deformation_m": u_a.tolist(),
        "critical_amplitude_rigid_m": rigid,
        "critical_amplitude_flexible_m": flexible,
        "analytic_critical_amplitude_m": rigid if drive.actuator_model == "rigid" else flexible,
    }


def _combined(u: np.ndarray) -> float:
    """Eqs. 7/8 (one group), Teidelt's Eqs. 11/12 (two), their generalisation (k groups).

    The paper's combination of two sides, 2u₁u₂/(u₁ + u₂), is the harmonic mean of the sides'
    presliding displacements: the amplitude at which the runner, held by the sides in parallel,
    is pulled loose. Any number k of groups generalises it as the harmonic mean
    k / Σ 1/u_g, unweighted by the contacts per group as Eq. 11 is; one group gives Eq. 7.
    For two groups of any counts, forces and radii it is Eq. 11 itself; for k >= 3 it is an
    estimate (a three-group drive's simulated steady A_c lay 11 % above it), whereas the first
    fly-back's onset generalises exactly (:func:`first_flyback_critical_amplitude`).
    """
    if u.size == 1:
        return float(u[0])
    if u.size == 2:
        return float(_harmonic(u[0], u[1]))
    return float(u.size / np.sum(1.0 / u))


def first_flyback_critical_amplitude(drive: Drive) -> float:
    """The first fly-back's onset of full sliding, rigid actuators: max_g u_x,max,g (m).

    From virgin contacts every contact slides only when the one with the largest presliding
    displacement does (Eq. 7 for one contact, Eq. 10's side 1 for the paper's six); for any
    arrangement it is the largest u_x,max,g of its groups (each with its own F_N and R).
    """
    return float(np.max(drive_theory(drive)["presliding_m"]))


def _drive_contact_radius(drive: Drive, forces: np.ndarray, E_star: float, radii) -> np.ndarray:
    """Hertz contact radius per group of a (validated) drive; its cube a normal double (else refused)."""
    cube = _hertz_cube(forces, radii, E_star)
    _require_normal(cube, "the Hertz contact radius cubed, 3 F_N R / (4 E*),", "m^3",
                    (("preload", drive.preload, "N"), ("hemisphere_radius", drive.hemisphere_radius, "m"),
                     ("E*", E_star, "Pa")))
    return np.cbrt(cube)


def contact_arrangement(drive: Drive) -> list[dict]:
    """Each contact group of a drive with its side, contact angle and normal force (Eq. 1).

    The paper's arrangements are written as their groups
    (:func:`passmd.model.arrangement.preset_groups`). One dict per group: ``side``, ``count``,
    ``contact_angle_rad``, ``radius_m``, ``normal_force_N`` (per contact), ``force_from``
    (``"normal_force"``, ``"load_share"`` or ``"Eq. 1"``: the side's balance) and
    ``preload_share_N`` (n F_N sin α, what the group carries of its side's F_p).
    """
    _check_drive(drive)
    groups = drive.contact_groups or preset_groups(drive.contacts)
    forces, counts, radii = drive.contact_layout
    rows = []
    for g, side, F, n, R in zip(groups, group_sides(groups), forces, counts, radii, strict=True):
        source = ("normal_force" if g.normal_force is not None else
                  "load_share" if g.load_share is not None else "Eq. 1")
        rows.append({"side": side, "count": int(n), "contact_angle_rad": g.contact_angle,
                     "radius_m": float(R), "normal_force_N": float(F), "force_from": source,
                     "preload_share_N": float(n * F * np.sin(g.contact_angle))})
    return rows


#: The secant stiffness μF_N / u_x,max of a Cattaneo–Mindlin contact loaded to full slip, as a share of
#: its initial 2aG* (the virgin curve's slope at zero is (3/2) μF_N / u_x,max).
FULL_SLIP_SECANT = 2.0 / 3.0


def runner_frequency(drive: Drive, *, in_series: bool = False, full_slip: bool = False) -> float:
    """Runner-on-contacts natural frequency √(Σ k / m_r) / (2π) in Hz, k = 2aG* per contact.

    Σ runs over all contacts (2 × side 1 + 4 × side 2 for six contacts), plus the
    load cell when engaged: the micro-vibration frequency's linear estimate with rigid actuators.
    ``in_series=True``: each contact's 2aG* in series with its actuator's k_p, k = 2aG* k_p /
    (2aG* + k_p), as the runner of a drive with flexible actuators rings (the actuator's mass,
    10⁻⁵–10⁻⁶ of the runner's, moves with the contact at the runner's frequency, far below its
    own); for rigid actuators both are the same. The ringing's first swings micro-slip, which
    softens the contacts: the simulated ringing (:func:`passmd.protocols.ringing.stick_ringing`)
    runs a few % below this linear estimate. ``full_slip=True``: each contact at the secant
    stiffness of a swing reaching full slip, :data:`FULL_SLIP_SECANT` × 2aG*, the softest a
    sticking contact gets: a swing within the presliding rings between the two.
    """
    _check_drive(drive)
    E_star, G_star = drive.contact_moduli
    forces, counts, radii = drive.contact_layout
    stiffness = 2.0 * _drive_contact_radius(drive, forces, E_star, radii) * G_star  # 2aG* per group
    if full_slip:
        stiffness = FULL_SLIP_SECANT * stiffness
    if in_series and drive.actuator_model == "flexible":
        k_p = drive.actuator.stiffness
        stiffness = stiffness * k_p / (stiffness + k_p)
    k_total = sum(int(m) * float(k) for m, k in zip(counts, stiffness, strict=True))
    k_total += drive.effective_load_cell_stiffness
    return float(np.sqrt(k_total / drive.runner_mass) / (2 * np.pi))


def friction_limit(drive: Drive) -> float:
    """Total Coulomb friction limit μ Σ F_N of all contacts on the runner (N, Eq. 1).

    Six contacts: μ (2 F_N1 + 4 F_N2) = 2√2 μ F_p; one contact: μ F_p.
    """
    _check_drive(drive)
    forces, counts, _ = drive.contact_layout
    return float(drive.friction_coefficient * sum(int(m) * float(F) for m, F in zip(counts, forces,
                                                                                       strict=True)))


def coulomb_sawtooth_step(amplitude, frequency, flyback_time, friction_force, runner_mass):
    """Step per period of a rigid-actuator saw-tooth drive with Coulomb friction.

    The limit of the drive of Eqs. 2–6 when the contact stiffness goes to infinity: the
    presliding (Eq. 7) vanishes and every contact becomes a rigid Coulomb contact, so the
    drive is the idealised inertia (stick–slip) drive of M. Hunstig, "Piezoelectric
    Inertia Motors—A Critical Review of History, Concepts, Design, Applications, and
    Perspectives", Actuators 6 (2017) 7, Sections 2–3 (see also M. Hunstig, T. Hemsel,
    W. Sextro, Sens. Actuators A 200 (2013) 90, the paper's ref. 21). The closed form
    below is derived here for the saw-tooth of :func:`passmd.model.waveforms.sawtooth`.

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
