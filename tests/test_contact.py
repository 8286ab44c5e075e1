"""MDR contact with memory (passmd.model.contact): closed forms, memory rules, discrete vs exact.

Tolerances (relative to the sliding force μF_N unless said):
* ROUND = 1e-12: identities that hold to floating-point rounding (the exact model against
  the closed forms of passmd.model.theory, mirror symmetry, sums of a few thousand springs).
* DISCRETE = 5e-3: the MDR validation chapter's acceptance bound for N ≥ 1000 springs against
  the exact model (0.5 % of μF_N).
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from passmd.model import contact, hertz, theory
from passmd.model.contact import contact_arrays, stack_contacts
from passmd.model.mdr_contact import MDRContact
from passmd.model.parameters import Drive

ROUND = 1e-12  # rounding only
DISCRETE = 5e-3  # discrete within 0.5 % of μF_N for N >= 1000 (see the module docstring)

DRIVE = Drive()  # R = 1 mm, F_p = 0.4 N, μ = 0.2, ruby on steel
E_STAR, G_STAR = theory.contact_moduli(DRIVE)
F_N = float(theory.normal_forces(0.4, 6)[0])
R, MU = 1e-3, 0.2
U_MAX = float(theory.presliding_displacement(F_N, R, E_STAR, G_STAR, MU))
F_S = MU * F_N


def exact(**kw):
    return MDRContact(F_N, R, E_STAR, G_STAR, MU, **kw)


def discrete(n=1000):
    return MDRContact(F_N, R, E_STAR, G_STAR, MU, springs=n)


def legs(points, per_leg=25):
    """Piecewise-linear path through ``points`` (fractions of u_max), from u = 0."""
    pts = np.r_[0.0, np.asarray(points, dtype=float)] * U_MAX
    pieces = [np.linspace(a, b, per_leg + 1)[1:] for a, b in zip(pts[:-1], pts[1:], strict=True)]
    return np.concatenate(pieces)


# ---------------------------------------------------------------------------------------
# Closed forms
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("model", ["exact", "discrete"])
def test_virgin_loading_is_cattaneo_mindlin(model):
    c = exact() if model == "exact" else discrete(2000)
    u = np.linspace(0.0, 1.3 * U_MAX, 400)
    expected = hertz.cattaneo_mindlin_force(u, F_N, U_MAX, MU)
    tol = ROUND if model == "exact" else DISCRETE
    np.testing.assert_allclose(c.path(u), expected, rtol=0, atol=tol * F_S)


@pytest.mark.parametrize("model", ["exact", "discrete"])
@pytest.mark.parametrize("turn", [0.3, 0.8, 1.5])  # below and beyond full sliding
def test_first_unloading_branch_is_masing(model, turn):
    c = exact() if model == "exact" else discrete(2000)
    up = np.linspace(0.0, turn * U_MAX, 200)
    c.path(up)
    u_r, f_r = up[-1], float(hertz.cattaneo_mindlin_force(up[-1], F_N, U_MAX, MU))
    down = np.linspace(u_r, u_r - 3.0 * U_MAX, 600)[1:]
    expected = hertz.masing_branch_force(down, u_r, f_r, -1, F_N, U_MAX, MU)
    if turn < 1:  # the branch reaches the virgin curve's mirror point and follows it
        beyond = down <= -u_r
        expected[beyond] = hertz.cattaneo_mindlin_force(down[beyond], F_N, U_MAX, MU)
    tol = ROUND if model == "exact" else DISCRETE
    np.testing.assert_allclose(c.path(down), expected, rtol=0, atol=tol * F_S)


def test_initial_stiffness_is_2aG():
    c = exact()
    h = 1e-6 * U_MAX
    slope = c.force(h) / h
    k = float(hertz.tangential_stiffness(F_N, R, E_STAR, G_STAR))
    assert slope == pytest.approx(k, rel=1e-5)  # one-sided difference, error ~ h/u_max
    assert c.stiffness == pytest.approx(k, rel=ROUND)
    assert discrete(1000).stiffness == pytest.approx(k, rel=1e-3)  # Σ G*Δx = 2aG* up to Δx


@pytest.mark.parametrize("n", [2, 3, 10, 101, 1000])
def test_full_sliding_is_exactly_mu_fn(n):
    for c in (exact(), discrete(n)):
        f = c.path(legs([2.5, -2.5, 3.0]))
        assert c.force(5 * U_MAX) == pytest.approx(F_S, rel=ROUND)
        assert f.max() == pytest.approx(F_S, rel=ROUND)
        assert f.min() == pytest.approx(-F_S, rel=ROUND)
        assert np.all(np.abs(f) <= F_S * (1 + ROUND))
        assert c.slip_share(5 * U_MAX) == 1.0


def test_discrete_indentation_balances_normal_force():
    for n in (2, 7, 100, 1000):
        params, _ = contact_arrays("discrete", F_N, R, E_STAR, G_STAR, MU, springs=n)
        c = discrete(n)
        springs = c.spring_states()
        assert springs["normal_force_N"].sum() == pytest.approx(F_N, rel=ROUND)
        assert params[0] == contact.DISCRETE
    d_hertz = float(hertz.hertz_indentation(F_N, R, E_STAR))
    assert discrete(1000).indentation == pytest.approx(d_hertz, rel=1e-5)  # midpoint rule, O(N^-2)


def test_discrete_indentation_water_filling():
    # heights 0, 1, 4: target 1 → only the lowest touches (d = 1); target 4 → d = 2.5;
    # target 10 → all three: 3d − 5 = 10, d = 5
    assert contact.discrete_indentation([4.0, 0.0, 1.0], 1.0) == pytest.approx(1.0, rel=ROUND)
    assert contact.discrete_indentation([4.0, 0.0, 1.0], 4.0) == pytest.approx(2.5, rel=ROUND)
    assert contact.discrete_indentation([4.0, 0.0, 1.0], 10.0) == pytest.approx(5.0, rel=ROUND)


# ---------------------------------------------------------------------------------------
# Memory
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("model", ["exact", "discrete"])
def test_minor_loop_is_wiped_out(model):
    """Up to 0.9, down to −0.5, minor loop 0.2 → −0.1 → 0.2, on to 0.9: the big branch resumes."""
    make = exact if model == "exact" else (lambda: discrete(500))
    with_loop, without = make(), make()
    with_loop.path(legs([0.9, -0.5, 0.2, -0.1, 0.2]))
    without.path(legs([0.9, -0.5, 0.2]))
    probe = np.linspace(0.2, 0.9, 50) * U_MAX
    np.testing.assert_allclose(with_loop.path(probe), without.path(probe), rtol=0, atol=ROUND * F_S)
    if model == "exact":
        assert with_loop.depth == without.depth == 0  # reaching 0.9 closes the big loop: virgin curve
        assert with_loop.max_depth == 4


def test_branch_rejoins_virgin_curve_and_sliding_erases_memory():
    c = exact()
    c.path(legs([0.6, -0.3, 0.1]))
    assert c.depth == 2  # reversals at 0.6 and −0.3
    c.update(-0.7 * U_MAX)  # one jump through −0.3 and the mirror point −0.6 onto the virgin curve
    assert c.depth == 0
    assert c.force(-0.7 * U_MAX) == pytest.approx(-F_S * (1 - 0.3**1.5), rel=ROUND)
    c.path(legs([0.5, -0.2, 0.4, 2.0]))  # full sliding
    assert c.depth == 0
    assert c.update(1.0 * U_MAX) == pytest.approx(F_S - 2 * F_S * (1 - (1 - 0.5) ** 1.5), rel=ROUND)


@pytest.mark.parametrize("model", ["exact", "discrete"])
def test_mirror_path_gives_mirror_force(model):
    rng = np.random.default_rng(7)
    path = legs(rng.uniform(-2.0, 2.0, 30) * rng.uniform(0, 1, 30) ** 2)
    a = exact() if model == "exact" else discrete(300)
    b = exact() if model == "exact" else discrete(300)
    np.testing.assert_array_equal(a.path(path), -b.path(-path))  # negation is exact in IEEE


def test_jitter_does_not_grow_the_stack():
    c = exact()
    c.path(legs([0.7, 0.4]))
    depth, base = c.depth, c.force(0.4 * U_MAX)
    eps = np.spacing(0.4 * U_MAX)
    for k in range(1, 2000):
        u = 0.4 * U_MAX + (eps if k % 2 else -eps) * (1 + k % 3)
        assert abs(c.update(u) - base) < 1e-9 * F_S  # 2aG* · 3 ulp ≈ 1e-14 F_S
        assert c.depth <= depth + 7  # 7 distinct values of u nest at most 7 deep
    assert c.overflow_count == 0


def test_overflow_is_counted_bounded_and_deterministic():
    """A decaying oscillation nests 60 loops; a stack of 8 must forget the newest ones."""
    turns = 0.9 * (-0.9) ** np.arange(60)
    small = exact(capacity=8)
    big = exact(capacity=1024)
    f_small, f_big = small.path(legs(turns, 10)), big.path(legs(turns, 10))
    assert big.overflow_count == 0 and big.max_depth == 59  # 59 reversals, the 60th point ends the path
    assert small.overflow_count > 0 and small.max_depth <= 8
    # the forgotten loops are the innermost: their height bounds the error, 2aG*·|loop| at most
    innermost = 2 * abs(turns[7]) * U_MAX
    assert np.max(np.abs(f_small - f_big)) <= small.stiffness * innermost
    again = exact(capacity=8)
    np.testing.assert_array_equal(again.path(legs(turns, 10)), f_small)


def test_reset_restores_virgin():
    for c in (exact(), discrete(50)):
        virgin_state = c.state.copy()
        first = c.path(legs([0.5, -1.5, 0.3]))
        c.reset()
        np.testing.assert_array_equal(c.state, virgin_state)
        np.testing.assert_array_equal(c.path(legs([0.5, -1.5, 0.3])), first)


# ---------------------------------------------------------------------------------------
# Discrete vs exact on random paths
# ---------------------------------------------------------------------------------------

turn_points = st.lists(st.floats(-3.0, 3.0, allow_nan=False), min_size=1, max_size=25)


@settings(max_examples=25, deadline=None)
@given(points=turn_points, shrink=st.floats(0.05, 1.0), per_leg=st.integers(1, 20),
       n=st.sampled_from([1000, 1500]))
def test_discrete_converges_to_exact_on_random_paths(points, shrink, per_leg, n):
    # geometric shrink factor makes nested minor loops; |x| up to 3 u_max includes full sliding
    pts = np.asarray(points) * shrink ** np.arange(len(points))
    path = np.r_[legs(points, per_leg), legs(pts, per_leg)]
    e, d = exact(), discrete(n)
    np.testing.assert_allclose(d.path(path), e.path(path), rtol=0, atol=DISCRETE * F_S)
    assert e.overflow_count == 0


@pytest.mark.parametrize("n", [1000, 4000])
def test_discrete_matches_exact_when_revisiting_reversal_points_exactly(n):
    # legs() ends each leg exactly on its point, so these hit older reversal points to the bit
    points = [0.5, -0.2, 0.5, -0.2, 0.3, -0.2, 0.5, 1.2, -0.4, 1.2, -1.2, 0.0, -1.2, 0.6, -0.6]
    path = legs(points, 15)
    e, d = exact(), discrete(n)
    np.testing.assert_allclose(d.path(path), e.path(path), rtol=0, atol=DISCRETE * F_S)


@settings(max_examples=25, deadline=None)
@given(points=turn_points, probe=st.floats(-3.0, 3.0), model=st.sampled_from(["exact", "discrete"]))
def test_force_and_slip_share_are_pure(points, probe, model):
    c = exact() if model == "exact" else discrete(200)
    c.path(legs(points, 3))
    before = c.state.copy()
    f = c.force(probe * U_MAX)
    c.slip_share(probe * U_MAX)
    c.force(np.array([probe, -probe, 0.0]) * U_MAX)
    np.testing.assert_array_equal(c.state, before)
    assert c.update(probe * U_MAX) == f  # update returns what force promised, bit for bit


@pytest.mark.parametrize("turn", [0.2, 0.6, 0.95])
def test_slip_share(turn):
    e, d = exact(), discrete(2000)
    u = np.linspace(0.0, turn * U_MAX, 50)
    np.testing.assert_allclose(e.slip_share(u), 1 - np.sqrt(1 - u / U_MAX), rtol=0, atol=ROUND)
    assert e.slip_share(0.0) == 0.0
    e.path(u)
    d.path(u)
    # after a reversal nothing slips; the slipping annulus then regrows as 1 − √(1 − v/u_max)
    assert e.slip_share(u[-1] - 1e-12 * U_MAX) == pytest.approx(0.0, abs=1e-6)
    back = u[-1] - 0.4 * turn * U_MAX
    v = 0.2 * turn * U_MAX
    assert e.slip_share(back) == pytest.approx(1 - np.sqrt(1 - v / U_MAX), rel=ROUND)
    for uu in (u[-1], back):
        assert d.slip_share(uu) == pytest.approx(e.slip_share(uu), abs=2e-3)  # 2 springs in 1000 pairs


# ---------------------------------------------------------------------------------------
# Kernel interface
# ---------------------------------------------------------------------------------------


def test_stacked_rows_behave_like_single_contacts():
    pairs = [
        contact_arrays("exact", F_N, R, E_STAR, G_STAR, MU, capacity=16),
        contact_arrays("discrete", F_N / 2, R, E_STAR, G_STAR, MU, springs=40),
        contact_arrays("exact", F_N / 2, 0.25e-3, E_STAR, G_STAR, 0.3),
    ]
    P, S = stack_contacts(pairs)
    P2, S2 = stack_contacts(pairs)
    assert P.flags.c_contiguous and S.flags.c_contiguous
    path = legs([0.5, -0.8, 0.1, 2.0, -0.2])
    for g, (p, s) in enumerate(pairs):
        s = s.copy()
        for u in path:
            expected = contact.contact_update(p, s, u)
            share = contact.contact_slip_share(p, s, u)
            assert contact.contact_slip_share(P[g], S[g], u) == share
            assert contact.contact_slip_share_row(P2, S2, g, u) == share
            assert contact.contact_force(P[g], S[g], u) == expected
            assert contact.contact_force_row(P2, S2, g, u) == expected
            assert contact.contact_update(P[g], S[g], u) == expected
            assert contact.contact_update_row(P2, S2, g, u) == expected
        np.testing.assert_array_equal(S[g], S2[g])
        np.testing.assert_array_equal(S[g, : s.size], s)
        assert contact.contact_stiffness(P[g]) == contact.contact_stiffness(p)
        assert contact.sliding_force(P[g]) == p[1]
        contact.contact_reset(P[g], S[g])
        np.testing.assert_array_equal(S[g, : s.size], 0.0)


def test_for_drive_uses_eq1_and_materials():
    c0 = MDRContact.for_drive(DRIVE, side=0)
    c1 = MDRContact.for_drive(DRIVE, side=1, springs=100)
    f1, f2 = theory.normal_forces(DRIVE.preload, 6)
    assert c0.normal_force == pytest.approx(float(f1), rel=ROUND)
    assert c1.normal_force == pytest.approx(float(f2), rel=ROUND)
    assert c0.presliding == pytest.approx(theory.drive_theory(DRIVE)["presliding_m"][0], rel=ROUND)
    one = MDRContact.for_drive(DRIVE.replace(contacts=1))
    assert one.normal_force == pytest.approx(0.4, rel=ROUND)
    with pytest.raises(ValueError, match="side = 1"):
        MDRContact.for_drive(DRIVE.replace(contacts=1), side=1)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"model": "spring"}, "model = 'spring'"),
        ({"normal_force": 0.0}, "normal_force = 0.0"),
        ({"normal_force": np.nan}, "normal_force"),
        ({"radius": -1e-3}, "radius = -0.001"),
        ({"E_star": 0}, "E_star = 0"),
        ({"G_star": np.inf}, "G_star"),
        ({"mu": -0.2}, "mu = -0.2"),
        ({"model": "discrete", "springs": None}, "springs = None"),
        ({"model": "discrete", "springs": 1}, "springs = 1"),
        ({"model": "discrete", "springs": 10.5}, "springs = 10.5"),
        ({"capacity": 2}, "capacity = 2"),
    ],
)
def test_bad_inputs_are_named(kwargs, message):
    args = {"model": "exact", "normal_force": F_N, "radius": R, "E_star": E_STAR, "G_star": G_STAR,
            "mu": MU} | kwargs
    with pytest.raises(ValueError, match=message.replace("(", r"\(")):
        contact_arrays(**args)


def test_bad_displacements_are_named():
    c = exact()
    with pytest.raises(ValueError, match="u = nan"):
        c.update(float("nan"))
    with pytest.raises(ValueError, match="us contains inf"):
        c.path([0.0, np.inf])
    with pytest.raises(ValueError, match="only defined for model = 'discrete'"):
        c.spring_states()
    with pytest.raises(ValueError, match="contacts = \\[\\]"):
        stack_contacts([])
