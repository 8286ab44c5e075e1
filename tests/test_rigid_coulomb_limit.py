"""The simulator against an independent limit: the rigid Coulomb drive (infinitely stiff contacts).

Scaling the contact moduli E*, G* by k shrinks the presliding u_x,max ∝ k^(−2/3) (Eq. 7 with the
Hertz indentation d ∝ E*^(−2/3)); the rigid-actuator drive must then approach the closed-form
step of :func:`passmd.model.theory.coulomb_sawtooth_step`, which no part of the simulator computes.
"""

import numpy as np
import pytest

from passmd.experiments.model_numerics import figures
from passmd.model import theory
from passmd.model.parameters import Drive


@pytest.fixture(scope="module")
def limit():
    table = figures.rigid_coulomb_limit()
    return table, figures.coulomb_limit_rates(table).set_index("configuration")


def test_stiffened_drive_scales_both_moduli_exactly():
    base = Drive(actuator_model="rigid")
    E, G = theory.contact_moduli(base)
    E64, G64 = theory.contact_moduli(figures.stiffened_drive(base, 64.0))
    assert E64 == pytest.approx(64.0 * E, rel=1e-12) and G64 == pytest.approx(64.0 * G, rel=1e-12)
    # the presliding length (Eq. 7) falls as k^(−2/3): 64^(2/3) = 16
    u, u64 = (theory.drive_theory(d)["presliding_m"][0] for d in (base, figures.stiffened_drive(base, 64.0)))
    assert u / u64 == pytest.approx(16.0, rel=1e-12)
    with pytest.raises(ValueError, match="scale"):
        figures.stiffened_drive(base, 0.0)


def test_paper_flyback_difference_decreases_monotonically(limit):
    """With the paper's 1.5 µs fly-back (impulsive against the runner's ≥ 11 kHz mode) the gap
    to the Coulomb step shrinks at every fourfold stiffening, for six contacts and one."""
    table, _ = limit
    for label, g in table[table["flyback"] == "paper slew rate"].groupby("configuration"):
        gap = np.abs(g.sort_values("scale")["difference_m"].to_numpy())
        assert np.all(np.diff(gap) < 0), (label, gap)
        assert gap[-1] < 0.01 * gap[0], (label, gap)  # three decades of scale: > 100× closer


def test_observed_rate_matches_presliding_scaling(limit):
    """|difference| ∝ k^(−rate) with rate = 2/3 expected (numerics.EXPECTED_COULOMB_RATE).

    Band [0.5, 5/6]: the midpoints between 2/3 and its nearest alternatives, 1/3 (an error set by
    the runner's time scale, ∝ 1/ω_runner ∝ k^(−1/3)) and 1 (the elastic play ∝ 1/E* with a fixed
    contact radius); a fitted rate inside it is closer to 2/3 than to either. The fit over
    three decades of k absorbs the next-order terms that bend the local slope."""
    _, rates = limit
    assert figures.EXPECTED_COULOMB_RATE == pytest.approx(2.0 / 3.0)
    for label, rate in rates["rate"].items():
        assert 0.5 < rate < 5.0 / 6.0, (label, rate)


def test_slow_flyback_checks_the_formulas_flyback_term(limit):
    """With the slow fly-back the Coulomb loss a t_f² is half of A: the limit is far below A, and
    at the stiffest scale the simulator reproduces it to better than 1 % of that loss (the gap is
    not monotone here: the 30–50 µs fly-back is comparable with the runner's vibration period, so
    the gap oscillates under its k^(−2/3) envelope)."""
    table, _ = limit
    slow = table[table["flyback"] == "slow"]
    for label, g in slow.groupby("configuration"):
        g = g.sort_values("scale")
        A = 150e-9  # rigid_coulomb_limit's default amplitude
        drive = Drive(contacts=int(g["contacts"].iloc[0]), actuator_model="rigid")
        loss = theory.friction_limit(drive) / drive.runner_mass * g["flyback_time_s"].iloc[0] ** 2
        assert loss == pytest.approx(0.5 * A, rel=1e-12)  # the slow fly-back's design
        assert g["coulomb_step_m"].iloc[0] < 0.6 * A, label
        assert abs(g["difference_m"].iloc[-1]) < 0.01 * loss, (label, g["difference_m"].iloc[-1], loss)
        assert abs(g["difference_m"].iloc[-1]) < 0.1 * abs(g["difference_m"].iloc[0]), label
