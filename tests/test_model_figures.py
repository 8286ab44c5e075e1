"""Figures and facts of the model, numerics and MDR-validation chapters (rows of passmd.figures)."""

from __future__ import annotations

import numpy as np
import pytest

from passmd import figures, publish, theory
from passmd.config import RunConfig
from passmd.defaults import PROTOCOL
from passmd.experiments import mdr, model

QUICK = RunConfig(profile="quick")
CHEAP = (
    "model_sawtooth",
    "model_free_body",
    "model_cross_section",
    "model_mdr_loop",
    "mdr_springs",
    "mdr_normal",
    "mdr_virgin",
    "mdr_hysteresis",
    "mdr_convergence",
    "mdr_cost",
)


@pytest.mark.parametrize("name", CHEAP)
def test_cheap_figures_compute_and_draw(name):
    import matplotlib.pyplot as plt

    data = figures.figure_data(name, QUICK)
    assert len(data) > 0
    fig = figures.figure_plot(name, data)
    assert fig.axes
    plt.close(fig)


def test_sawtooth_is_the_full_stroke_at_the_drive_frequency():
    wave = model.model_sawtooth(QUICK)
    drive = model.model_drive()
    assert wave["x_p_m"].max() == pytest.approx(drive.actuator.full_stroke_amplitude, rel=1e-12)
    assert wave["time_s"].max() == pytest.approx(model.SAWTOOTH_PERIODS / PROTOCOL.drive_frequency, rel=1e-12)
    # the fly-back is the amplifier's slew-limited time: 300 V at 150 V/µs = 2 µs at full stroke
    assert wave["flyback_time_s"].iloc[0] == pytest.approx(2e-6, rel=1e-9)
    assert 0 < wave["ramp_end_s"].iloc[0] < 1 / PROTOCOL.drive_frequency


def test_normal_forces_balance_the_preload_on_both_sides():
    """Eq. 1: 2 F_N1 sin 45° = 4 F_N2 sin 45° = F_p."""
    balance = model.normal_force_balance(model.model_drive())
    assert balance["balance_right_N"] == pytest.approx(model.MODEL_PRELOAD, rel=1e-12)
    assert balance["balance_left_N"] == pytest.approx(model.MODEL_PRELOAD, rel=1e-12)
    assert balance["normal_force_1_N"] == pytest.approx(2 * balance["normal_force_2_N"], rel=1e-12)


def test_mdr_loop_stays_within_the_sliding_force_and_matches_hertz():
    loop = model.model_mdr_loop(QUICK)
    first = loop.iloc[0]
    assert np.abs(loop["force_exact_N"]).max() <= first["sliding_force_N"] * (1 + 1e-12)
    # 0.8 u_x,max never reaches full sliding: the exact loop stays strictly inside ±μF_N
    assert np.abs(loop["force_exact_N"]).max() < first["sliding_force_N"]
    assert first["contact_radius_m"] ** 2 == pytest.approx(
        first["hemisphere_radius_m"] * first["indentation_m"], rel=1e-9
    )  # a² = R d (Hertz)
    # 50 springs follow the exact limit to within 1 % of μF_N (midpoint rule, error ∝ N⁻²)
    assert np.abs(loop["force_discrete_N"] - loop["force_exact_N"]).max() < 0.01 * first["sliding_force_N"]


def test_closed_form_rows_are_drive_theory_formatted():
    drive = model.model_drive()
    rows = model.closed_form_rows(drive)
    th = theory.drive_theory(drive)
    assert rows["u_x,max,e rigid (nm), Eq. 11"] == f"{th['critical_amplitude_rigid_m'] * 1e9:.4g}"
    assert len(rows["F_N1, F_N2 (N)"].split(", ")) == 2
    assert model.actuator_row(drive)["drive"] == "R = 1 mm"
    assert model.actuator_row(model.model_drive(0.25e-3))["m_a (g)"] == "1.1e-05"  # Table 2 as printed


def test_hysteresis_turns_are_named_once_each():
    loop = mdr.mdr_hysteresis(QUICK)
    named = loop[loop["turn"] != ""]
    assert list(named["turn"]) == list(mdr.HYSTERESIS_TURNS)
    assert named["u_m"].iloc[0] > 0 > named["u_m"].iloc[1]  # A then −A


def test_mdr_convergence_has_the_midpoint_rules_order():
    conv = mdr.mdr_convergence(QUICK)
    assert conv["fitted_order"].iloc[0] == pytest.approx(2.0, abs=0.3)
    assert conv.loc[conv["springs"] < 100, "fit_rel"].isna().all()


def test_assumption_list_escapes_markup():
    assert publish.escape_markdown("a_b*c") == "a\\_b\\*c"
    text = publish.assumption_list()
    assert text.count("\n- ") + 1 == len(publish.assumptions_frame())
    assert "*Where its effect is shown:*" in text
