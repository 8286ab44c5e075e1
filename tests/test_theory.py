"""Closed forms of passmd.model.theory against hand arithmetic and against physics.

Tolerances: hand values are written with 6 significant digits, so they are compared
with rtol = 1e-5; identities between closed forms hold to rounding (rtol = 1e-12).
"""

import numpy as np
import pytest

from passmd.model import hertz, theory
from passmd.model.parameters import Drive
from passmd.model.tables import RUBY, STEEL

HAND = 1e-5  # 6 significant digits typed from the hand calculation
EXACT = 1e-12  # algebraic identities, floating-point rounding only


def test_effective_moduli_by_hand():
    """Table 1: E1 = 370 GPa, E2 = 210 GPa, ν1 = ν2 = 0.33.

    1 − ν² = 0.8911; 1/E* = 0.8911/370e9 + 0.8911/210e9 = 2.40838e-12 + 4.24333e-12
    = 6.65171e-12 /Pa  →  E* = 150.337 GPa.
    G1 = 370e9/2.66 = 139.098 GPa, G2 = 210e9/2.66 = 78.9474 GPa; (2 − ν)/4 = 0.4175;
    1/G* = 0.4175/139.098e9 + 0.4175/78.9474e9 = 3.00148e-12 + 5.28833e-12
    = 8.28981e-12 /Pa  →  G* = 120.630 GPa.
    """
    args = (RUBY.youngs_modulus, RUBY.poissons_ratio, STEEL.youngs_modulus, STEEL.poissons_ratio)
    assert hertz.effective_youngs_modulus(*args) == pytest.approx(150.337e9, rel=HAND)
    assert hertz.effective_shear_modulus(*args) == pytest.approx(120.630e9, rel=HAND)


def test_hertz_by_hand():
    """F_N = 0.4 N, R = 1 mm, E* = 150.337 GPa.

    a = (3·0.4·1e-3 / (4·150.337e9))^(1/3) = (1.99552e-15)^(1/3) = 12.5898 µm;
    d = a²/R = 1.58503e-7 m.
    """
    E = 150.337243e9
    assert hertz.hertz_contact_radius(0.4, 1e-3, E) == pytest.approx(12.5898e-6, rel=HAND)
    assert hertz.hertz_indentation(0.4, 1e-3, E) == pytest.approx(1.58503e-7, rel=HAND)


def test_hertz_force_recovered_from_radius():
    E, R = 150e9, 0.25e-3
    F = np.linspace(0.05, 1.0, 20)
    a = hertz.hertz_contact_radius(F, R, E)
    np.testing.assert_allclose(hertz.hertz_normal_force(a, R, E), F, rtol=EXACT)


def test_normal_forces_eq1_by_hand():
    """Eq. 1 at F_p = 0.4 N: F_N1 = 0.4/2/sin45° = 0.282843 N, F_N2 = 0.4/4/sin45° = 0.141421 N."""
    f1, f2 = theory.normal_forces(0.4, contacts=6)
    assert f1 == pytest.approx(0.282843, rel=HAND)
    assert f2 == pytest.approx(0.141421, rel=HAND)
    (f,) = theory.normal_forces(0.4, contacts=1)
    assert f == pytest.approx(0.4, rel=EXACT)


def test_presliding_eq7_by_hand():
    """Eq. 7, μ = 0.2, F_p = 0.4 N, R = 1 mm, E* = 150.337 GPa, G* = 120.630 GPa.

    3μ/(4G*) = 0.6/482.520e9 = 1.24347e-12; (4E*/3)^(1/3) = (200.450e9)^(1/3) = 5852.24;
    F^(2/3) = 0.542884; R^(1/3) = 0.1  →  u_x,max = 1.24347e-12·5852.24·0.542884/0.1
    = 39.5074 nm.
    """
    E, G = 150.337243e9, 120.629884e9
    u = theory.presliding_displacement(0.4, 1e-3, E, G, 0.2)
    assert u == pytest.approx(39.5074e-9, rel=HAND)


def test_presliding_equals_mu_ratio_times_indentation():
    E, G, R, mu = 150e9, 120e9, 1e-3, 0.3
    F = np.linspace(0.1, 1.0, 10)
    np.testing.assert_allclose(
        theory.presliding_displacement(F, R, E, G, mu),
        mu * E / G * hertz.hertz_indentation(F, R, E),
        rtol=EXACT,
    )


def test_actuator_deformation_eq9_by_hand():
    """Eq. 9: u_x,a = 0.2·0.4/6.5e6·(3e-3 + 2.2e-8)/3e-3 = 1.23077e-8·1.0000073 = 12.3078 nm."""
    u = theory.actuator_deformation(0.2, 0.4, 6.5e6, 3e-3, 2.2e-8)
    assert u == pytest.approx(12.3078e-9, rel=HAND)


def test_six_contact_critical_amplitude_eq11_by_hand():
    """Eq. 10 at F_N1 = 0.282843 N, F_N2 = 0.141421 N (F_p = 0.4 N, R = 1 mm, μ = 0.2):
    u_x,max scales as F^(2/3): u1 = 39.5074·(0.707107)^(2/3) = 39.5074·0.793701 = 31.3570 nm,
    u2 = 39.5074·(0.353553)^(2/3) = 39.5074·0.500000 = 19.7537 nm;
    Eq. 11: 2·31.3570·19.7537/(31.3570 + 19.7537) = 24.2382 nm.
    """
    d = Drive(preload=0.4, friction_coefficient=0.2, contacts=6, actuator_model="rigid")
    out = theory.drive_theory(d)
    assert out["presliding_m"][0] == pytest.approx(31.3570e-9, rel=HAND)
    assert out["presliding_m"][1] == pytest.approx(19.7537e-9, rel=HAND)
    assert out["critical_amplitude_rigid_m"] == pytest.approx(24.2382e-9, rel=HAND)
    assert out["analytic_critical_amplitude_m"] == out["critical_amplitude_rigid_m"]


def test_one_contact_critical_amplitude_eq8_by_hand():
    """Eq. 8 at 0.4 N, R = 1 mm: A_c = 39.5074 + 12.3078 = 51.8152 nm (flexible)."""
    d = Drive(preload=0.4, contacts=1, actuator_model="flexible")
    out = theory.drive_theory(d)
    assert out["critical_amplitude_flexible_m"] == pytest.approx(51.8152e-9, rel=HAND)
    assert out["critical_amplitude_rigid_m"] == pytest.approx(39.5074e-9, rel=HAND)


def test_harmonic_combination_between_sides():
    u1, u2 = np.array([3.0, 1.0]), np.array([2.0, 1.0])
    h = theory.harmonic_combination(u1, u2)
    assert np.all(h <= np.maximum(u1, u2)) and np.all(h >= np.minimum(u1, u2))
    assert h[1] == pytest.approx(1.0, rel=EXACT)


def test_cattaneo_mindlin_virgin_curve():
    """Reaches μF_N at u_x,max; initial slope (3/2)μF_N/u_x,max equals 2aG*."""
    d = Drive(preload=0.4, contacts=1)
    out = theory.drive_theory(d)
    F, mu, u_max = 0.4, d.friction_coefficient, out["presliding_m"][0]
    assert hertz.cattaneo_mindlin_force(u_max, F, u_max, mu) == pytest.approx(mu * F, rel=EXACT)
    assert hertz.cattaneo_mindlin_force(3 * u_max, F, u_max, mu) == pytest.approx(mu * F, rel=EXACT)
    assert hertz.cattaneo_mindlin_force(-u_max, F, u_max, mu) == pytest.approx(-mu * F, rel=EXACT)
    h = 1e-6 * u_max  # forward difference; slope error ~ h/u_max relative
    slope = hertz.cattaneo_mindlin_force(h, F, u_max, mu) / h
    assert slope == pytest.approx(out["tangential_stiffness_N_per_m"][0], rel=1e-5)


def test_masing_branch_closes_on_virgin_curve():
    """After a reversal at (u_r, F_r) on the virgin curve, the unloading branch meets
    the mirrored point (−u_r, −F_r) (Masing's rule) and reaches −μF_N at u_r − 2u_max."""
    F, mu, u_max = 0.4, 0.2, 40e-9
    u_r = 0.6 * u_max
    F_r = hertz.cattaneo_mindlin_force(u_r, F, u_max, mu)
    back = hertz.masing_branch_force(-u_r, u_r, F_r, -1, F, u_max, mu)
    assert back == pytest.approx(-F_r, rel=EXACT)
    full = hertz.masing_branch_force(u_r - 2 * u_max, u_r, F_r, -1, F, u_max, mu)
    assert full == pytest.approx(-mu * F, rel=EXACT)


def test_runner_frequency_matches_stiffness_sum():
    d = Drive(actuator_model="rigid")
    out = theory.drive_theory(d)
    k = 2 * out["tangential_stiffness_N_per_m"][0] + 4 * out["tangential_stiffness_N_per_m"][1]
    assert theory.runner_frequency(d) == pytest.approx(np.sqrt(k / 3e-3) / (2 * np.pi), rel=EXACT)


def test_coulomb_sawtooth_step_by_hand():
    """A = 100 nm, f = 1 kHz (T = 1 ms), F_c = 0.3 N, m_r = 3 g, so a = F_c/m_r = 100 m/s².

    t_f = 20 µs: t_r = 980 µs, A T/t_r = 100·1000/980 = 102.041 nm, a t_f² = 100·4e-10 m
    = 40 nm → s = 62.0408 nm (case 1: a t_f² < A T/t_r, the runner slides all fly-back).
    t_f = 40 µs: A T/t_r = 100/0.96 = 104.167 nm < a t_f² = 160 nm → s = 0 (case 2).
    """
    s = theory.coulomb_sawtooth_step(100e-9, 1e3, [20e-6, 40e-6], 0.3, 3e-3)
    assert s[0] == pytest.approx(62.0408e-9, rel=HAND)
    assert s[1] == 0.0


def test_coulomb_sawtooth_step_limits_and_bad_input():
    """t_f → 0 recovers the ideal saw-tooth's full step A; the two cases meet continuously."""
    A, f, F, m = 150e-9, 100.0, 0.2263, 3e-3
    assert theory.coulomb_sawtooth_step(A, f, 1e-12, F, m) == pytest.approx(A, rel=1e-9)
    # boundary a t_f² = A T/t_r, solved for t_f by bisection: the step is 0 there from both sides
    lo, hi = 1e-9, 0.4 / f
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if theory.coulomb_sawtooth_step(A, f, mid, F, m) > 0 else (lo, mid)
    assert theory.coulomb_sawtooth_step(A, f, lo, F, m) < 1e-6 * A
    with pytest.raises(ValueError, match="flyback_time"):
        theory.coulomb_sawtooth_step(A, f, 0.5 / f, F, m)
    with pytest.raises(ValueError, match="runner_mass"):
        theory.coulomb_sawtooth_step(A, f, 1e-6, F, -1.0)


def _coulomb_runner_ode(amplitude, n_period, n_flyback, dt, accel, periods=3):
    """Brute force: the rigid Coulomb runner under the saw-tooth, integrated step by step.

    Time stepping for set-valued Coulomb friction (Moreau's velocity update): each step the
    friction can change the runner's velocity by at most a·dt; if that reaches the piezo
    velocity the runner sticks (v = v_p), otherwise it slides (v ← v ∓ a·dt). Positions are
    advanced with the mean velocity of the step, exact while sliding or sticking; the corners
    of x_p fall on step boundaries. Vectorised over parameter sets (one per array element),
    each with its own fly-back of ``n_flyback`` steps at the end of a period of ``n_period``.
    Returns x_r − x_p at the end of every ramp (shape (periods, sets); the runner is stuck).
    """
    n_ramp = n_period - n_flyback
    v_ramp, v_fly = amplitude / (n_ramp * dt), -amplitude / (n_flyback * dt)
    x = np.zeros(n_flyback.shape)  # x_r − x_p (x_p returns to 0 every period)
    v = np.zeros(n_flyback.shape)  # runner velocity, from rest
    ends = np.empty((periods, n_flyback.size))
    for k in range(periods):
        for n in range(n_period):
            v_p = np.where(n < n_ramp, v_ramp, v_fly)
            w = v - v_p
            v_new = np.where(np.abs(w) <= accel * dt, v_p, v - np.sign(w) * accel * dt)
            x += (0.5 * (v + v_new) - v_p) * dt
            v = v_new
            ends[k] = np.where(n == n_ramp - 1, x, ends[k])
    return ends


def test_coulomb_sawtooth_step_against_brute_force_ode():
    """The closed form against the integrated rigid Coulomb ODE, in both cases.

    Parameter sets: a = 100 m/s², A = 100 nm, T = 1 ms at dt = 50 ns (20 000 steps per period);
    fly-backs from 2 µs to 100 µs span case 1 (step > 0) and case 2 (no step). The step is
    x_r − x_p at the end of the third ramp minus the second (both stuck). Tolerance: the scheme
    is exact while sliding or sticking; only a step in which the runner re-sticks errs, by at
    most a·dt²/2 (the slip ends inside the step), and a period has two re-sticks: a·dt².
    """
    dt, n_period, accel = 50e-9, 20_000, 100.0
    n_fly = np.array([40, 200, 400, 600, 800, 1000, 2000])
    A = np.full(n_fly.shape, 100e-9)
    ends = _coulomb_runner_ode(A, n_period, n_fly, dt, accel)
    steps = ends[2] - ends[1]
    expected = theory.coulomb_sawtooth_step(A, 1.0 / (n_period * dt), n_fly * dt, accel * 3e-3, 3e-3)
    assert np.any(expected == 0.0) and np.any(expected > 0.5 * A)  # both cases are exercised
    np.testing.assert_allclose(steps, expected, rtol=0, atol=accel * dt**2)
