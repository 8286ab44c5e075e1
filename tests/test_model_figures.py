"""Figures and facts of the model, numerics and MDR-validation chapters (rows of
passmd.experiments.figure_table)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from passmd.experiments import figure_table
from passmd.experiments.mdr_validation.facts import (
    contact_facts,
    cost_facts,
    hysteresis_facts,
    normal_facts,
    virgin_facts,
)
from passmd.experiments.mdr_validation.figures import (
    HYSTERESIS_TURNS,
    mdr_convergence,
    mdr_cost,
    mdr_hysteresis,
    mdr_normal,
    mdr_virgin,
)
from passmd.experiments.model.facts import actuator_row, closed_form_rows
from passmd.experiments.model.figures import (
    MODEL_PRELOAD,
    SAWTOOTH_PERIODS,
    model_drive,
    model_mdr_loop,
    model_sawtooth,
    normal_force_balance,
)
from passmd.experiments.model_numerics.facts import (
    BENCHMARKS,
    CONTROLLED_FIT_COARSEST,
    TARGET_BASELINE_RATIO,
    TARGET_MS_PER_PERIOD,
    before_after_table,
    benchmark_facts,
    benchmark_results,
    benchmark_table,
    convergence_facts,
    coulomb_rising_gaps,
    coulomb_side,
    energy_facts,
    fitted_order_above_floor,
    missed_budgets,
    settle_facts,
    speed_budgets,
    step_plan_table,
)
from passmd.experiments.model_numerics.figures import (
    CONFIGURATIONS,
    REFERENCE_CONTROL,
    RIGID_STEP_CONTROLS,
    STEP_CONTROLS,
    convergence_study,
    energy_balance_table,
)
from passmd.model import theory
from passmd.model.defaults import PROTOCOL
from passmd.report import publish
from passmd.runtime.config import RunConfig

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

    data = figure_table.figure_data(name, QUICK)
    assert len(data) > 0
    fig = figure_table.figure_plot(name, data)
    assert fig.axes
    plt.close(fig)


def test_sawtooth_is_the_full_stroke_at_the_drive_frequency():
    wave = model_sawtooth(QUICK)
    drive = model_drive()
    assert wave["x_p_m"].max() == pytest.approx(drive.actuator.full_stroke_amplitude, rel=1e-12)
    assert wave["time_s"].max() == pytest.approx(SAWTOOTH_PERIODS / PROTOCOL.drive_frequency, rel=1e-12)
    # the fly-back is the amplifier's slew-limited time: 300 V at 150 V/µs = 2 µs at full stroke
    assert wave["flyback_time_s"].iloc[0] == pytest.approx(2e-6, rel=1e-9)
    assert 0 < wave["ramp_end_s"].iloc[0] < 1 / PROTOCOL.drive_frequency


def test_normal_forces_balance_the_preload_on_both_sides():
    """Eq. 1: 2 F_N1 sin 45° = 4 F_N2 sin 45° = F_p."""
    balance = normal_force_balance(model_drive())
    assert balance["balance_right_N"] == pytest.approx(MODEL_PRELOAD, rel=1e-12)
    assert balance["balance_left_N"] == pytest.approx(MODEL_PRELOAD, rel=1e-12)
    assert balance["normal_force_1_N"] == pytest.approx(2 * balance["normal_force_2_N"], rel=1e-12)


def test_mdr_loop_stays_within_the_sliding_force_and_matches_hertz():
    loop = model_mdr_loop(QUICK)
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
    drive = model_drive()
    rows = closed_form_rows(drive)
    th = theory.drive_theory(drive)
    assert rows["u_x,max,e rigid (nm), Eq. 11"] == f"{th['critical_amplitude_rigid_m'] * 1e9:.4g}"
    assert len(rows["F_N1, F_N2 (N)"].split(", ")) == 2
    assert actuator_row(drive)["drive"] == "R = 1 mm"
    assert actuator_row(model_drive(0.25e-3))["m_a (g)"] == "1.1e-05"  # Table 2 as printed


def test_hysteresis_turns_are_named_once_each():
    loop = mdr_hysteresis(QUICK)
    named = loop[loop["turn"] != ""]
    assert list(named["turn"]) == list(HYSTERESIS_TURNS)
    assert named["u_m"].iloc[0] > 0 > named["u_m"].iloc[1]  # A then −A


def test_mdr_convergence_has_the_midpoint_rules_order():
    conv = mdr_convergence(QUICK)
    assert conv["fitted_order"].iloc[0] == pytest.approx(2.0, abs=0.3)
    assert conv.loc[conv["springs"] < 100, "fit_rel"].isna().all()


def test_assumption_list_escapes_markup():
    assert publish.escape_markdown("a_b*c") == "a\\_b\\*c"
    text = publish.assumption_list()
    assert text.count("\n- ") + 1 == len(publish.assumptions_frame())
    assert "*Where its effect is shown:*" in text


def test_mdr_facts_come_from_the_figure_data():
    normal = mdr_normal(QUICK)
    facts = normal_facts(normal)
    # the midpoint rule's error falls with N: 20 springs worst, 1000 best, at every depth
    assert facts["normal_err_20"] > facts["normal_err_100"] > facts["normal_err_1000"] > 0
    assert facts["normal_err_end_1000"] <= facts["normal_err_1000"]
    virgin = virgin_facts(mdr_virgin(QUICK))
    assert virgin["virgin_err_exact"] < 1e-12  # rounding: the exact contact is Cattaneo-Mindlin
    assert virgin["virgin_err_20"] > virgin["virgin_err_1000"]
    loop = hysteresis_facts(mdr_hysteresis(QUICK))
    assert loop["loop_err_exact"] < 1e-12 and loop["loop_err_1000"] < 0.5  # % of μF_N
    cost = cost_facts(mdr_cost(QUICK))
    assert cost["ring_depth"] >= 1 and cost["per_spring_ns"] > 0 and cost["cost_ratio_1000"] > 1
    contact = contact_facts()
    assert contact["sliding_force_mN"] == pytest.approx(0.2 * contact["normal_force_N"] * 1e3, rel=1e-12)


def _synthetic_convergence(controlled_error):
    """A convergence table whose explicit errors fall exactly as h², with the error-controlled
    scheme's errors ``controlled_error(r)``; steps per control in fixed ratios."""
    rows = []
    per_step = {"controlled": 50, "adaptive": 100, "fixed": 1000, "quasi-static": 20}
    for label in ("six contacts, flexible", "six contacts, rigid"):
        controls = STEP_CONTROLS if "flexible" in label else RIGID_STEP_CONTROLS
        for control in controls:
            for r in (0.25, 0.5, 1.0, 2.0, 4.0):
                steps = per_step[control] * r
                error = controlled_error(r) if control == "controlled" else 1e-10 * r**-2.0
                rows.append({"configuration": label, "step_control": control, "resolution": r, "steps": steps,
                             "rejected_steps": 0.1 * steps if control == "controlled" else 0,
                             "final_position_m": 1e-6, "error_m": error})
    return pd.DataFrame(rows)


def test_convergence_facts_on_a_second_order_table():
    """Synthetic errors falling exactly as h² (explicit) and h³ (error-controlled): the fitted
    orders are 2 and 3, the savings the step ratios."""
    facts = convergence_facts(_synthetic_convergence(lambda r: -2e-10 * r**-3.0))
    assert facts["conv_order"] == pytest.approx(2.0, rel=1e-9)
    assert facts["quasi_order"] == pytest.approx(2.0, rel=1e-9)
    assert facts["conv_max_err_nm"] == pytest.approx(0.1, rel=1e-9)
    assert facts["adaptive_saving"] == pytest.approx(10.0) and facts["quasi_saving"] == pytest.approx(5.0)
    assert facts["adaptive_vs_fixed_nm"] == 0.0
    assert facts["ctrl_order"] == pytest.approx(3.0, rel=1e-9)
    assert facts["ctrl_max_err_nm"] == pytest.approx(0.2, rel=1e-9)
    assert facts["ctrl_floor_nm"] == pytest.approx(0.2 / 64, rel=1e-9)  # the finest runs' (r = 4) error
    assert facts["ctrl_floor_rigid_nm"] == facts["ctrl_floor_flexible_nm"] == facts["ctrl_floor_nm"]
    assert facts["ctrl_rejected_pct"] == pytest.approx(10.0)
    assert facts["ctrl_saving_adaptive"] == pytest.approx(2.0)
    assert facts["ctrl_saving_fixed"] == pytest.approx(20.0)
    assert facts["ctrl_saving_rigid"] == pytest.approx(20.0)


def test_convergence_plot_names_configurations_and_step_controls():
    """One legend entry per configuration (colour) and per step control (line style), the
    default scheme named as such; one curve per configuration and control."""
    import matplotlib.pyplot as plt

    from passmd.plots.numerics import plot_convergence

    conv = _synthetic_convergence(lambda r: 2e-10 * r**-3.0)
    fig = plot_convergence(conv)
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert labels[:2] == ["six contacts, flexible", "six contacts, rigid"]
    assert labels[2:6] == ["error-controlled (default)", "explicit adaptive", "quasi-static actuator",
                           "fixed fine step"]
    curves = len(conv.groupby(["configuration", "step_control"]))
    assert len(fig.axes[0].get_lines()) == curves + 3  # and the slope guides and the converged-accuracy line
    plt.close(fig)


def test_controlled_order_is_fitted_above_its_floor():
    """The error-controlled scheme's order leaves out the runs at its floor (within
    FLOOR_FACTOR of its finest runs' error) and those coarser than CONTROLLED_FIT_COARSEST:
    a h³ error that levels off at 1e-11 m and is flat below resolution 0.5 still fits as 3."""

    def error(r):
        if r < CONTROLLED_FIT_COARSEST:
            return 8e-10  # the longest step binds: no longer the tolerance's error
        return max(1e-10 * r**-3.0, 1e-11)

    conv = _synthetic_convergence(error)
    facts = convergence_facts(conv)
    assert facts["ctrl_order"] == pytest.approx(3.0, rel=1e-9)
    assert facts["ctrl_floor_nm"] == pytest.approx(0.01, rel=1e-9)
    # without those exclusions the same runs fit far from 3
    controlled = conv[conv["step_control"] == "controlled"]
    assert fitted_order_above_floor(controlled, factor=0.0, coarsest=0.0)[0] < 2.0
    flat = controlled.assign(error_m=1e-11)
    with pytest.raises(ValueError, match=r"only 0 resolution\(s\) with an error above 3 times the floor"):
        fitted_order_above_floor(flat)


def test_convergence_reference_is_the_reference_controls_finest_run():
    """Each configuration runs the applicable step controls plus its reference control, and its
    reference is that control's finest run, whatever order the controls are listed in."""
    conv = convergence_study(periods=1, resolutions=(1.0, 2.0), step_controls=("controlled",))
    for label, _, actuator_model in CONFIGURATIONS:
        rows = conv[conv["configuration"] == label]
        reference = REFERENCE_CONTROL[actuator_model]
        assert set(rows["step_control"]) == {"controlled", reference}
        zero = rows[rows["error_m"] == 0.0]
        assert list(zero["step_control"]) == [reference] and list(zero["resolution"]) == [2.0]
    assert (conv.loc[conv["step_control"] == "controlled", "rejected_steps"] > 0).all()
    with pytest.raises(ValueError, match=r"^step_controls = 'implicit'"):
        convergence_study(step_controls=("implicit",))


def test_energy_facts_compare_the_same_runs():
    energy = pd.DataFrame({"configuration": ["a", "a", "b"], "contact_model": ["exact", "discrete", "exact"],
                           "relative_residual": [-4e-7, 1e-6, 2e-7]})
    explicit = energy.assign(relative_residual=[2e-6, -1e-7, 4e-6])
    facts = energy_facts(energy, explicit)
    assert facts == pytest.approx({"energy_max_rel": 1e-6, "energy_exact_max_rel": 4e-7,
                                   "energy_discrete_max_rel": 1e-6, "energy_explicit_max_rel": 4e-6,
                                   "energy_tighter": 4.0, "energy_ratio_min": 0.05, "energy_ratio_max": 10.0})
    with pytest.raises(ValueError, match="explicit must list the same runs"):
        energy_facts(energy, explicit.iloc[::-1])


def test_energy_balance_of_the_default_scheme_is_as_tight_as_the_explicit_ones():
    """The error-controlled step takes far longer steps than the explicit schemes but must
    not close the energy balance worse: its largest residual on the model-numerics chapter's
    runs is at most theirs (and both stay far inside the 1e-3 the integrator tests allow).
    Simpson's rule for the work terms of a long step makes that possible; with the
    trapezoidal rule the default's largest residual was several times theirs."""
    default = energy_balance_table(periods=2)["relative_residual"].abs()
    explicit = energy_balance_table(periods=2, scheme="adaptive")["relative_residual"].abs()
    assert default.max() <= explicit.max(), (default.max(), explicit.max())
    assert explicit.max() < 1e-3


def test_settle_and_coulomb_texts():
    sens = pd.DataFrame(
        {
            "configuration": ["a", "a", "b", "b"],
            "settle_fraction": [0.1, 0.4] * 2,
            "mean_step_m": [100e-9, 101e-9, 50e-9, 50e-9],
        }
    )
    facts = settle_facts(sens)
    assert facts["settle_spread_nm"] == pytest.approx(1.0) and facts["settle_spread_rel"] == pytest.approx(
        100 / 100.5
    )
    gaps = pd.DataFrame(
        {"configuration": ["c"] * 3, "scale": [1.0, 4.0, 16.0], "difference_m": [-3e-9, -1e-9, -2e-9]}
    )
    assert coulomb_side(gaps) == "below"
    assert coulomb_rising_gaps(gaps) == ["c: 1.000 nm at k = 4 → 2.000 nm at k = 16"]


def test_step_plan_and_benchmark_facts():
    plan = step_plan_table()
    assert list(plan["configuration"]) == [c[0] for c in CONFIGURATIONS]
    assert (plan["fine step (ns)"] < plan["stability limit 2/ω (ns)"]).all()
    # the error-controlled step may grow far beyond the explicit steps (the runner mode is exact)
    assert (plan["longest controlled step (ns)"] > plan["coarse step (ns)"]).all()
    facts = benchmark_facts(benchmark_table())
    assert facts["bench_six_flex_ms"] > 0 and facts["bench_fixed_ns"] > 0
    # the default (error-controlled) row, not the explicit adaptive one it replaced
    assert facts["bench_six_flex_ms"] < facts["bench_six_flex_adaptive_ms"]
    assert facts["bench_periods"] >= 1
    assert facts["bench_processes"] >= 1 and facts["bench_six_flex_processes_ms"] > 0
    assert facts["target_ms_per_period"] == TARGET_MS_PER_PERIOD


def test_speed_budgets_hold_only_within_their_budget():
    records = {name: benchmark_results(name) for name in BENCHMARKS}
    stored = speed_budgets(records)
    assert stored.equals(speed_budgets())  # the package's records by default
    assert set(stored["unit"]) == {"× faster", "s", "MB"}
    # each check can fail: a fit over its budget, a speed-up below its target, a map within its budget
    fit = {**records["fit"], "wall_time_s": records["fit"]["budget_s"] * 1.01}
    head = {**records["dynamics"]["headline"],
            "ratios": {"loop": {"baseline_over_default": TARGET_BASELINE_RATIO * 0.99}}}
    sweep = {**records["sweep_map"], "cold": {**records["sweep_map"]["cold"],
                                               "wall_s": records["sweep_map"]["cold"]["target_s"]}}
    changed = speed_budgets({**records, "fit": fit, "dynamics": {**records["dynamics"], "headline": head},
                             "sweep_map": sweep}).set_index("measurement")["holds"]
    assert not changed.iloc[0] and not changed.iloc[1] and changed.iloc[2]
    # the ledger and book rows are the last cold paper runs, not a later quick one
    quick = {**records["ledger"][-1], "profile": "quick", "wall_time_s": 1e6}
    rows = speed_budgets({**records, "ledger": [*records["ledger"], quick]})
    assert rows.equals(stored)


def test_missed_budgets_names_exactly_the_budgets_that_do_not_hold():
    records = {name: benchmark_results(name) for name in BENCHMARKS}
    table = speed_budgets(records)
    every = table.assign(holds=True)
    assert missed_budgets(every) == "none"
    one = every.copy()
    one.loc[1, ["measured", "holds", "load"]] = [32.29, False, 1.19]
    assert missed_budgets(one) == "the fit: μ, k_p from 15 steps (32.3 s against 20 s, load 1.19)"
    two = one.copy()
    two.loc[6, "holds"] = False
    text = missed_budgets(two)
    assert text.startswith("the fit: μ") and " and the paper book (" in text and text.count(" and ") == 1
    assert missed_budgets(table).count("(") == int((~table["holds"]).sum())  # the stored records'


def test_before_after_table_reads_both_sides():
    data = {"date": "d", "before": "a" * 40, "after": "b" * 40, "benchmarks": {"fit": {
        "before": {"wall_time_s": 80.0, "load_average_before": [0.5, 0, 0]},
        "after": {"wall_time_s": 40.0, "load_average_before": [0.7, 0, 0]}, "ratio_before_over_after": 2.0}}}
    table = before_after_table(data)
    assert table.iloc[0].to_dict() == {"benchmark": "fit", "before (s)": 80.0, "after (s)": 40.0,
                                       "before / after": 2.0, "load before": 0.5, "load after": 0.7}
    assert table.attrs["before"] == "a" * 40


def test_hemisphere_mass_is_half_a_ruby_sphere():
    from passmd.experiments.model_numerics.figures import RUBY_DENSITY, actuator_masses, hemisphere_mass

    assert hemisphere_mass(1e-3) == pytest.approx(2 / 3 * np.pi * 1e-9 * RUBY_DENSITY, rel=1e-12)
    masses = actuator_masses("quick")  # the printed 22 µg to 22 mg, and the hemisphere's 8.3 mg
    assert masses[0] == pytest.approx(2.2e-8) and masses[-1] == pytest.approx(2.2e-5)
    assert any(np.isclose(masses, hemisphere_mass()))


def _mass_table(ac_fixed_nm: dict) -> pd.DataFrame:
    """A study table (figures.actuator_mass_study's columns) with the fixed fly-back's A_c per mass (µg)."""
    from passmd.experiments.model_numerics.figures import hemisphere_mass

    rows = []
    for mass_ug, ac in ac_fixed_nm.items():
        for f, v in ((100.0, 2e-5), (110e3, 0.02 if mass_ug < 1e3 else -0.005)):
            rows.append({"actuator_mass": mass_ug * 1e-9, "critical_amplitude_slew_m": 15e-9,
                         "critical_amplitude_fixed_m": ac * 1e-9, "eq12_m": 30e-9, "eq12_tolerance_rel": 0.1,
                         "actuator_frequency_Hz": 8.65e4 * (22000 / mass_ug) ** 0.5,
                         "actuator_on_contact_1_Hz": 1.0e5 * (22000 / mass_ug) ** 0.5,
                         "actuator_on_contact_2_Hz": 0.99e5 * (22000 / mass_ug) ** 0.5,
                         "ringing_frequency_Hz": 9e3, "frequency_Hz": f, "velocity_m_per_s": v,
                         "printed": mass_ug == 22.0,
                         "hemisphere": np.isclose(mass_ug * 1e-9, hemisphere_mass())})
    return pd.DataFrame(rows)


def test_mass_study_sentence_follows_the_data():
    from passmd.experiments.model_numerics.facts import mass_study_facts
    from passmd.experiments.model_numerics.figures import hemisphere_mass

    heavy = hemisphere_mass() * 1e9
    # the printed mass matches Eq. 12 and a hemisphere's does not: the book keeps the printed value
    found = mass_study_facts(_mass_table({22.0: 30.3, 220.0: 29.0, heavy: 16.7, 22000.0: 16.2}))
    assert found["mass_verdict"].startswith("So the printed m_a is consistent")
    assert "22 µg and 220 µg" in found["mass_ac_text"] and "outside" in found["mass_hypothesis"]
    assert "(the runner moves backwards)" in found["mass_velocity_text"]
    assert found["mass_ratio"] == pytest.approx(heavy / 22.0)
    # counter-examples: a hemisphere's mass matching too, or the printed one failing, say so
    both = mass_study_facts(_mass_table({22.0: 30.3, heavy: 29.0, 22000.0: 28.0}))
    assert both["mass_verdict"].startswith("Both the printed m_a and a hemisphere's")
    assert "within" in both["mass_hypothesis"]
    neither = mass_study_facts(_mass_table({22.0: 20.0, heavy: 16.7, 22000.0: 16.2}))
    assert neither["mass_verdict"].startswith("The printed m_a is not consistent")
