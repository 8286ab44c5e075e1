"""Figures and facts of the model, numerics and MDR-validation chapters (rows of passmd.figures)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from passmd import figures, publish, theory
from passmd.config import RunConfig
from passmd.defaults import PROTOCOL
from passmd.experiments import mdr, model, numerics

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


def test_mdr_facts_come_from_the_figure_data():
    normal = mdr.mdr_normal(QUICK)
    facts = mdr.normal_facts(normal)
    # the midpoint rule's error falls with N: 20 springs worst, 1000 best, at every depth
    assert facts["normal_err_20"] > facts["normal_err_100"] > facts["normal_err_1000"] > 0
    assert facts["normal_err_end_1000"] <= facts["normal_err_1000"]
    virgin = mdr.virgin_facts(mdr.mdr_virgin(QUICK))
    assert virgin["virgin_err_exact"] < 1e-12  # rounding: the exact contact is Cattaneo-Mindlin
    assert virgin["virgin_err_20"] > virgin["virgin_err_1000"]
    loop = mdr.hysteresis_facts(mdr.mdr_hysteresis(QUICK))
    assert loop["loop_err_exact"] < 1e-12 and loop["loop_err_1000"] < 0.5  # % of μF_N
    cost = mdr.cost_facts(mdr.mdr_cost(QUICK))
    assert cost["ring_depth"] >= 1 and cost["per_spring_ns"] > 0 and cost["cost_ratio_1000"] > 1
    contact = mdr.contact_facts()
    assert contact["sliding_force_mN"] == pytest.approx(0.2 * contact["normal_force_N"] * 1e3, rel=1e-12)


def test_convergence_facts_on_a_second_order_table():
    """Synthetic errors falling exactly as h²: the fitted order is 2, the savings the step ratios."""
    rows = []
    for label in ("six contacts, flexible", "one contact, rigid"):
        controls = ("adaptive", "fixed", "quasi-static") if "flexible" in label else ("fixed",)
        for control in controls:
            for r in (0.5, 1.0, 2.0, 4.0):
                steps = {"adaptive": 100, "fixed": 1000, "quasi-static": 20}[control] * r
                rows.append(
                    {
                        "configuration": label,
                        "step_control": control,
                        "resolution": r,
                        "steps": steps,
                        "final_position_m": 1e-6,
                        "error_m": 1e-10 * r**-2.0,
                    }
                )
    facts = numerics.convergence_facts(pd.DataFrame(rows))
    assert facts["conv_order"] == pytest.approx(2.0, rel=1e-9)
    assert facts["quasi_order"] == pytest.approx(2.0, rel=1e-9)
    assert facts["conv_max_err_nm"] == pytest.approx(0.1, rel=1e-9)
    assert facts["adaptive_saving"] == pytest.approx(10.0) and facts["quasi_saving"] == pytest.approx(5.0)
    assert facts["adaptive_vs_fixed_nm"] == 0.0


def test_settle_and_coulomb_texts():
    sens = pd.DataFrame(
        {
            "configuration": ["a", "a", "b", "b"],
            "settle_fraction": [0.1, 0.4] * 2,
            "mean_step_m": [100e-9, 101e-9, 50e-9, 50e-9],
        }
    )
    facts = numerics.settle_facts(sens)
    assert facts["settle_spread_nm"] == pytest.approx(1.0) and facts["settle_spread_rel"] == pytest.approx(
        100 / 100.5
    )
    gaps = pd.DataFrame(
        {"configuration": ["c"] * 3, "scale": [1.0, 4.0, 16.0], "difference_m": [-3e-9, -1e-9, -2e-9]}
    )
    assert numerics.coulomb_side(gaps) == "below"
    assert numerics.coulomb_rising_gaps(gaps) == ["c: 1.000 nm at k = 4 → 2.000 nm at k = 16"]


def test_step_plan_and_benchmark_facts():
    plan = numerics.step_plan_table()
    assert list(plan["configuration"]) == [c[0] for c in numerics.CONFIGURATIONS]
    assert (plan["fine step (ns)"] < plan["stability limit 2/ω (ns)"]).all()
    facts = numerics.benchmark_facts(numerics.benchmark_table())
    assert facts["bench_six_flex_ms"] > 0 and facts["bench_fixed_ns"] > 0
    assert facts["target_ms_per_period"] == numerics.TARGET_MS_PER_PERIOD
