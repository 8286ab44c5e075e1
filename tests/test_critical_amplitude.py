"""Critical amplitude (Figs. 5, 6): search, protocols, physics against Eqs. 7–12, quick-data snapshots.

The quick profile of every panel is computed once per session (through the sweep cache) and
locked with pytest-regressions; the physics tests run single searches at F_p = 0.4 N.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import snapshot_accuracy as snap

from passmd.experiments import figure_table
from passmd.experiments.critical_amplitude_one import facts, figures
from passmd.experiments.critical_amplitude_six.facts import (
    ac_at,
    ac_range,
    ac_span,
    deviation_at,
    deviation_table,
    fig6a_facts,
    fig6bc_facts,
    frequency_facts,
    prestrain_facts,
    side_prestrain,
    slew_facts,
    viscosity_facts,
)
from passmd.model import waveforms
from passmd.model.defaults import PROTOCOL
from passmd.model.theory import drive_theory, runner_frequency
from passmd.protocols import critical_amplitude
from passmd.report import evaluation
from passmd.runtime.config import RunConfig

PANELS = ("fig5a", "fig5b", "fig6a", "fig6b", "fig6c", "fig56_viscosity", "fig56_frequency")
NM = 1e9


@pytest.fixture(scope="module")
def quick():
    """Quick data of every panel (computed once; the sweep cache makes reruns cheap)."""
    return {name: figure_table.figure_data(name, RunConfig(profile="quick")) for name in PANELS}


# --------------------------------------------------------------------------------------
# The search
# --------------------------------------------------------------------------------------


def test_bisection_brackets_the_switch_and_counts_runs():
    switch = 37.3e-9
    calls = []

    def moves(a):
        calls.append(a)
        return a >= switch

    out = critical_amplitude.bisect_amplitude(moves, 202e-9, 0.1e-9)
    assert out["bracket_low_m"] < switch <= out["bracket_high_m"]
    assert out["bracket_high_m"] - out["bracket_low_m"] <= 0.1e-9
    assert out["critical_amplitude_m"] == pytest.approx(0.5 * (out["bracket_low_m"] + out["bracket_high_m"]))
    # one run opens the bracket at A_max, then one per halving: 202/2^11 < 0.1 nm
    assert out["runs"] == len(calls) == 1 + math.ceil(math.log2(202 / 0.1))
    assert 0.0 not in calls  # A = 0 is "no motion" by definition, never simulated


def test_guided_search_returns_bisections_bracket_with_fewer_runs():
    """Wherever the drive starts moving once on [0, A_max], the guided search's bracket is
    bisection's to the last bit, whatever the slope of the measure and however noisy it is; with
    several switches it still brackets one of them."""
    rng = np.random.default_rng(7)
    runs = []
    for _ in range(400):
        upper = float(rng.choice([202e-9, 96e-9, rng.uniform(10e-9, 160e-9)]))
        tolerance = float(rng.choice([0.1e-9, 0.2e-9, 0.5e-9, 2e-9]))
        switch, slope = rng.uniform(0.0, upper), rng.uniform(0.5, 2.0)

        def probe(a, switch=switch, slope=slope):
            moved = a >= switch
            return moved, slope * (a - switch) + rng.uniform(-1e-11, 1e-11) if moved else None

        found = critical_amplitude.search_amplitude(probe, upper, tolerance, slope=1.0)
        plain = critical_amplitude.bisect_amplitude(lambda a, switch=switch: a >= switch, upper, tolerance)
        assert found == {**plain, "runs": found["runs"]}
        runs.append(found["runs"] / plain["runs"])
    assert np.median(runs) < 0.6
    switches = (30e-9, 45e-9, 120e-9)

    def several(a):
        moved = switches[0] <= a < switches[1] or a >= switches[2]
        return moved, a - switches[2] if moved else None

    found = critical_amplitude.search_amplitude(several, 202e-9, 0.1e-9, slope=1.0)
    assert not several(found["bracket_low_m"])[0] and several(found["bracket_high_m"])[0]
    assert found["bracket_high_m"] - found["bracket_low_m"] <= 0.1e-9
    never = critical_amplitude.search_amplitude(lambda a: (False, None), 96e-9, 0.5e-9)
    assert math.isnan(never["critical_amplitude_m"])


def test_bisection_without_motion_at_full_stroke_reports_nan():
    out = critical_amplitude.bisect_amplitude(lambda a: False, 96e-9, 0.5e-9)
    assert math.isnan(out["critical_amplitude_m"]) and math.isnan(out["bracket_high_m"])
    assert out["bracket_low_m"] == 96e-9 and out["runs"] == 1


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"protocol": "last"}, "protocol"),
        ({"flyback": "slow"}, "flyback"),
        ({"periods": 1}, "periods"),
        ({"tolerance": 0.0}, "tolerance"),
        ({"threshold": -1e-9}, "threshold"),
        ({"frequency": -100.0}, "frequency"),
    ],
)
def test_bad_search_input_names_the_parameter(kwargs, name):
    drive = figures.paper_drive_for(1, "rigid", 1e-3, 0.4)
    with pytest.raises(ValueError, match=name):
        critical_amplitude.critical_amplitude(drive, **kwargs)


def test_bad_first_flyback_input_names_the_parameter():
    drive = figures.paper_drive_for(1, "rigid", 1e-3, 0.4)
    with pytest.raises(ValueError, match="amplitude"):
        critical_amplitude.first_flyback_slip(drive, 0.0)
    with pytest.raises(ValueError, match="amplitude"):
        critical_amplitude.first_flyback_slip(drive, 1e-6)  # beyond the 202 nm full stroke
    with pytest.raises(ValueError, match="frequency"):
        # a 0.4 µs fly-back is more than half a 0.5 µs period
        critical_amplitude.first_flyback_slip(drive, 40e-9, frequency=2e6)
    with pytest.raises(ValueError, match="profile"):
        figures.fig5b(RunConfig(profile="fast"))


# --------------------------------------------------------------------------------------
# Physics: the closed forms and what each protocol gives
# --------------------------------------------------------------------------------------

TOLERANCE = 0.1e-9  # bracket width of the physics searches (m)


def _startup_vibration(drive, amplitude, frequency):
    """Amplitude of the runner vibration the ramp's velocity jump leaves: A f / ω_r (m)."""
    return amplitude * frequency / (2 * np.pi * runner_frequency(drive))


def test_one_contact_rigid_first_flyback_onset_is_eq7():
    """Rigid actuator, virgin contact: full sliding starts when the fly-back reaches u_x,max (Eq. 7).

    Allowed error: half the final bracket, the start-up vibration of the runner A f/ω_r, and the
    runner's own motion during the fly-back, at most ½ (μF_N/m_r) t_fb².
    """
    drive = figures.paper_drive_for(1, "rigid", 1e-3, 0.4)
    eq7 = drive_theory(drive)["critical_amplitude_rigid_m"]
    out = critical_amplitude.critical_amplitude(drive, protocol="first", tolerance=TOLERANCE)
    t_fb = waveforms.flyback_time(eq7, drive)
    pull = 0.5 * drive.friction_coefficient * drive.preload / drive.runner_mass * t_fb**2
    allowed = TOLERANCE / 2 + _startup_vibration(drive, eq7, PROTOCOL.drive_frequency) + pull
    assert abs(out["critical_amplitude_m"] - eq7) <= allowed
    assert allowed / eq7 < 0.01  # i.e. Eq. 7 within 1 %


def test_one_contact_flexible_quasistatic_first_flyback_onset_is_eq8():
    """Flexible actuator with the 2 µs fly-back (six actuator periods, close to quasi-static): onset at Eq. 8.

    Allowed error: half the bracket, the start-up vibration, and the actuator ringing the
    fly-back's corners leave, at most the piezo speed over the actuator's angular frequency
    (A/t_fb)/ω_a ≈ 1.5 nm at 0.4 N: together 3.3 % of Eq. 8.
    """
    drive = figures.paper_drive_for(1, "flexible", 1e-3, 0.4)
    eq8 = drive_theory(drive)["critical_amplitude_flexible_m"]
    out = critical_amplitude.critical_amplitude(drive, protocol="first", flyback="fixed", tolerance=TOLERANCE)
    omega_a = np.sqrt(drive.actuator.stiffness / drive.actuator.mass)
    ringing = eq8 / drive.amplifier.full_stroke_time / omega_a
    allowed = TOLERANCE / 2 + _startup_vibration(drive, eq8, PROTOCOL.drive_frequency) + ringing
    assert abs(out["critical_amplitude_m"] - eq8) <= allowed
    assert allowed / eq8 < 0.035


def test_slew_rate_flyback_rings_the_actuator_and_lowers_the_onset():
    """A fly-back shorter than the actuator period (slew rate, 0.4 µs vs 0.33 µs) lowers A_c below Eq. 8."""
    drive = figures.paper_drive_for(1, "flexible", 1e-3, 0.4)
    slew = critical_amplitude.critical_amplitude(drive, protocol="first", flyback="slew", tolerance=0.5e-9)
    fixed = critical_amplitude.critical_amplitude(drive, protocol="first", flyback="fixed", tolerance=0.5e-9)
    assert slew["critical_amplitude_m"] < fixed["critical_amplitude_m"] - 2e-9


def test_six_contacts_rigid_first_flyback_onset_follows_the_stiffer_side():
    """From virgin contacts all six slide only when the more loaded side 1 does: u_x,max,1 (Eq. 10)."""
    drive = figures.paper_drive_for(6, "rigid", 1e-3, 0.4)
    u1, u2 = drive_theory(drive)["presliding_m"]
    out = critical_amplitude.critical_amplitude(drive, protocol="first", tolerance=TOLERANCE)
    allowed = TOLERANCE / 2 + _startup_vibration(drive, u1, PROTOCOL.drive_frequency) + 0.05e-9
    assert abs(out["critical_amplitude_m"] - u1) <= allowed  # 0.05 nm: runner motion in t_fb


def test_six_contacts_rigid_steady_state_is_closest_to_eq11(quick):
    """Done-when: the steady-state A_c of six rigid contacts lies nearer Eq. 11 than either Eq. 10 side."""
    table = figures.primary(quick["fig6a"], "rigid")
    ac = table["critical_amplitude_nm"].to_numpy()
    dev = {
        c: np.max(np.abs(ac / table[c].to_numpy() - 1))
        for c in ("u_x_max_e_nm", "u_x_max_1_nm", "u_x_max_2_nm")
    }
    assert dev["u_x_max_e_nm"] < min(dev["u_x_max_1_nm"], dev["u_x_max_2_nm"])
    # the threshold (0.5 nm) and half the bracket (0.25 nm) over the smallest A_c of the grid
    assert dev["u_x_max_e_nm"] < 0.1


def test_steady_state_runs_are_long_enough(quick):
    """Ten periods: below A_c the start-up creep has decayed under δ; above it the step has converged."""
    rows = quick["fig56_frequency"]
    rows = rows[(rows["protocol"] == "steady") & np.isclose(rows["frequency_Hz"], PROTOCOL.drive_frequency)]
    assert len(rows) == 4
    for row in rows.itertuples():
        drive = figures.paper_drive_for(row.contacts, row.actuator_model, 1e-3, row.preload_N)
        below = critical_amplitude.steady_step(drive, 0.8 * row.critical_amplitude_nm / NM)
        above = critical_amplitude.steady_step(drive, 1.2 * row.critical_amplitude_nm / NM)
        assert abs(below["last_step_m"]) < 0.2e-9, row
        steps = np.array(above["steps_m"])
        assert steps[-1] > critical_amplitude.STEP_THRESHOLD and abs(steps[-1] - steps[-2]) < 0.01e-9, row


def test_first_flyback_onset_does_not_depend_on_low_drive_frequencies(quick):
    """50–200 Hz: the first-fly-back onset moves by less than the start-up vibration plus the bracket."""
    rows = quick["fig56_frequency"]
    first = rows[rows["protocol"] == "first"]
    drive = figures.paper_drive_for(1, "rigid", 1e-3, 0.4)
    a = critical_amplitude.critical_amplitude(drive, protocol="first", frequency=50.0, tolerance=0.5e-9)
    b = critical_amplitude.critical_amplitude(drive, protocol="first", frequency=200.0, tolerance=0.5e-9)
    vib = _startup_vibration(drive, 40e-9, 200.0) + _startup_vibration(drive, 40e-9, 50.0)
    assert abs(a["critical_amplitude_m"] - b["critical_amplitude_m"]) <= 0.5e-9 + vib
    assert len(first) > 0


def test_larger_threshold_gives_larger_steady_amplitude():
    drive = figures.paper_drive_for(1, "rigid", 1e-3, 0.4)
    small = critical_amplitude.critical_amplitude(drive, threshold=0.5e-9, tolerance=0.2e-9)
    large = critical_amplitude.critical_amplitude(drive, threshold=3e-9, tolerance=0.2e-9)
    # above the onset the step grows ~1 nm per nm: 2.5 nm more threshold, ~2.5 nm more A_c
    assert large["critical_amplitude_m"] - small["critical_amplitude_m"] == pytest.approx(2.5e-9, abs=0.6e-9)


# --------------------------------------------------------------------------------------
# Figures: structure, registry, plots and snapshots of the quick data
# --------------------------------------------------------------------------------------


def test_every_panel_is_in_the_figure_table_with_its_chapter():
    names = figure_table.figure_names()
    for name in PANELS:
        assert name in names
        assert figure_table.figure_spec(name).chapter in ("critical_amplitude_one", "critical_amplitude_six")


def test_figures_are_listed_in_the_books_order():
    """Chapters follow book/_toc.yml; study panels of Figs. 5-6 (fig56_*) come after fig6c, before fig7a."""
    toc = (Path(__file__).resolve().parents[1] / "book" / "_toc.yml").read_text()
    files = re.findall(r"^\s*- file: (\w+)", toc, flags=re.M)
    names = figure_table.figure_names()
    positions = [files.index(figure_table.figure_spec(name).chapter) for name in names]
    assert positions == sorted(positions)
    assert names.index("fig6c") < names.index("fig56_frequency") < names.index("fig7a")
    assert names.index("fig9b") < names.index("fig10a")


def test_panels_are_reachable_from_the_command_line(quick, tmp_path, capsys):
    """`passmd figure NAME --profile quick` draws a panel (its data come from the sweep cache)."""
    from passmd import cli

    assert cli.main(["figure", "fig6a", "--profile", "quick", "--out", str(tmp_path)]) == 0
    written = pd.read_csv(tmp_path / "fig6a.csv", comment="#")  # "#" lines: version, commit, profile
    assert len(written) == len(quick["fig6a"]) and (tmp_path / "fig6a.png").stat().st_size > 0


def test_searches_report_brackets(quick):
    for name in ("fig5b", "fig6a", "fig6b", "fig6c", "fig56_viscosity", "fig56_frequency"):
        table = quick[name]
        assert table["critical_amplitude_nm"].notna().all(), name
        width = table["bracket_high_nm"] - table["bracket_low_nm"]
        tolerance_nm = figures.PROFILE_SETTINGS["quick"].tolerance * NM
        assert (width > 0).all() and (width <= tolerance_nm + 1e-9).all(), name
        assert (
            (table["bracket_low_nm"] < table["critical_amplitude_nm"])
            & (table["critical_amplitude_nm"] < table["bracket_high_nm"])
        ).all(), name


def test_closed_form_columns_are_the_committed_reference_curves(quick):
    from passmd.ledger import reference

    for name, curve in (
        ("fig5b", "fig5b_closed_form"),
        ("fig6a", "fig6a_closed_form"),
        ("fig6b", "fig6b_closed_form"),
        ("fig6c", "fig6c_closed_form"),
    ):
        committed = reference.load_reference_curve(curve).set_index("preload_N")
        ours = quick[name].drop_duplicates("preload_N").set_index("preload_N")[committed.columns]
        # the committed CSV keeps 10 significant digits
        pd.testing.assert_frame_equal(ours, committed.loc[ours.index], rtol=1e-8, check_names=False)


@pytest.mark.parametrize("name", PANELS)
def test_plots_draw_every_panel(quick, name):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = figure_table.figure_plot(name, quick[name])
    assert fig.axes and all(ax.has_data() for ax in fig.axes)
    plt.close(fig)


#: Columns that record how the search got its result (its bracket and number of runs), not the result.
SEARCH_COLUMNS = ("bracket_low_nm", "bracket_high_nm", "runs", "wall_time_s")


def locked(frame: pd.DataFrame) -> pd.DataFrame:
    """The snapshot table of a panel: its numbers, without the search's bookkeeping and labels."""
    return snap.numeric(frame.drop(columns=[c for c in SEARCH_COLUMNS if c in frame]))


def check(dataframe_regression, name, table):
    """Critical amplitudes to one quick bracket width (plus the position accuracy), steps to the
    position accuracy, closed forms and inputs exactly (``snapshot_accuracy``)."""
    tolerances = snap.tolerances(table.columns, amplitudes=("critical_amplitude_nm",),
                                 bracket_width=figures.PROFILE_SETTINGS["quick"].tolerance)
    for col in table.columns:
        closed_form = col.startswith("u_x_") or col.endswith(("closed_form_nm", "threshold_nm"))
        if closed_form or col == "amplitude_nm":
            tolerances[col] = snap.EXACT  # closed forms (Eqs. 7–12) and the amplitude grid
    dataframe_regression.check(table, basename=f"test_quick_data_snapshot_{name}_",
                               default_tolerance=snap.EXACT, tolerances=tolerances)


@pytest.mark.parametrize("name", PANELS)
def test_quick_data_snapshot(quick, name, dataframe_regression):
    check(dataframe_regression, name, locked(quick[name]))


@pytest.mark.slow
def test_finer_run_passes_the_snapshots(tmp_path_factory, dataframe_regression):
    """Every panel run with the step halved (``snapshot_accuracy.finer_run``) passes every
    snapshot check: the snapshots lock the physics to the stated accuracy, not one scheme."""
    config = snap.finer_config(tmp_path_factory.mktemp("finer-cache"))
    with snap.finer_run():
        finer = {name: figure_table.figure_data(name, config) for name in PANELS}
    for name in PANELS:
        check(dataframe_regression, name, locked(finer[name]))


# --------------------------------------------------------------------------------------
# Ledger: the Fig. 5/6 claims are all evaluated, and none fails without being explained
# --------------------------------------------------------------------------------------


def test_ledger_rows_of_figs_5_and_6():
    """Every Section 4.1 claim is evaluated at every point of the axes that change its runs (fly-back
    rule, A_c protocol, drive frequency, μ and, for flexible actuators, ζ): the quick profile computes
    the whole product too. A point it leaves undecided is one where its coarser grid cannot decide
    (the coarse-grid rule of passmd.ledger.rules: a check holding on part of the paper's grid, or a
    deviation over the whole curve); every failure on it is a failure at a preload of the paper's grid.
    The experiment row has no measured data in the paper's text."""
    keys = ["fig5a", "fig5b", "fig6a", "fig6b", "fig6c"]
    claims = evaluation.claims_for(evaluation.load_claims(), keys)
    assert len(claims) == 13
    figures_read = [*keys, *(f"{k}_readings" for k in keys)]
    results = evaluation.collect_results(RunConfig(profile="quick"), figures_read)
    evaluated = evaluation.evaluate(claims, results)
    experiment = evaluated["claim"] == "fig6b-experiment-agreement"
    assert evaluated.loc[experiment, "verdict"].str.contains("no measured data").all()
    simulated = evaluated[~experiment]
    assert set(simulated["readings"]) == {2 * 2 * 3 * 2, 2 * 2 * 3 * 3 * 2}  # rigid, flexible
    points = [p for p in evaluated.attrs["points"] if p["claim"] != "fig6b-experiment-agreement"]
    undecided = [p for p in points if p["state"] == "inconclusive"]
    # undecided only where the coarser grid cannot decide, or where two A_c tie within the search's bracket
    assert all("part of the grid" in p["detail"] or p["detail"].startswith("tied: ") for p in undecided), (
        undecided[:3])
    assert sum(p["state"] == "fails" for p in points) > len(points) // 4
    joint = evaluated.attrs["joint"]
    assert joint["covered_points"] == joint["points"]
    status = dict(zip(evaluated["claim"], evaluated["status"], strict=True))
    # a deviation over the whole curve is not decided on three of the paper's ten preloads
    assert status["fig6a-rigid-ac-not-eq10"] == "inconclusive"


# --------------------------------------------------------------------------------------
# Facts the chapters quote, from the figure data
# --------------------------------------------------------------------------------------


def test_step_onset_is_where_the_step_stays_above_the_threshold():
    rows = pd.DataFrame({"amplitude_nm": [0.0, 10.0, 20.0, 30.0, 40.0],
                         "steady_step_nm": [0.0, 0.6, 0.1, 0.7, 1.5], "threshold_nm": 0.5})
    assert facts.step_onset(rows) == 30.0  # 10 nm is above δ once, but the step falls back
    assert math.isnan(facts.step_onset(rows.assign(steady_step_nm=0.0)))


def test_fig5a_facts(quick):
    found = facts.fig5a_facts(quick["fig5a"])
    assert found["onset_rigid"] <= found["eq7_04"] + 20  # the quick grid's 20 nm step
    assert found["onset_flex_fixed"] >= found["onset_flex_slew"]  # the slew-rate fly-back rings the actuator
    assert found["eq8_04"] > found["eq7_04"]
    assert found["slope_rigid"] == pytest.approx(1.0, abs=0.2)  # ~1 nm of step per nm of amplitude


def test_deviations_from_the_closed_forms(quick):
    closed = {"rigid": "u_x_max_nm", "flexible": "u_x_max_plus_u_x_a_nm"}
    dev = facts.closed_form_deviations(quick["fig5b"], closed)
    largest, mean = facts.series_deviation(dev, "rigid", "first", "slew")
    assert largest < 2.0 and abs(mean) <= largest  # first-fly-back onset of a rigid actuator: Eq. 7
    assert facts.side_of(-3.25) == "3.2 % below" and facts.side_of(1.0) == "1.0 % above"
    assert math.isnan(facts.band_spread(quick["fig5b"], "rigid"))  # the quick profile runs 100 Hz only
    columns = {"Eq. 11": "u_x_max_e_nm", "Eq. 10, side 1": "u_x_max_1_nm"}
    six = deviation_table(quick["fig6a"], columns)
    assert deviation_at(six, "steady", "slew", "Eq. 11: largest |dev| (%)") < deviation_at(
        six, "steady", "slew", "Eq. 10, side 1: largest |dev| (%)")


def test_spans_and_values_of_the_sensitivity_panels(quick):
    freq = quick["fig56_frequency"]
    low, high = ac_span(freq, 6, "first", actuator_model="rigid")
    assert low <= high and ac_range(freq, 6, "first", actuator_model="rigid") == high - low
    at_drive = ac_at(freq, 6, "rigid", "steady", PROTOCOL.drive_frequency)
    primary = figures.primary(freq, "rigid").query("contacts == 6")
    assert low > 0 and at_drive == float(primary["critical_amplitude_nm"].iloc[0])
    visc = quick["fig56_viscosity"]
    lo, hi = ac_span(visc, 6, "steady", flyback="fixed")
    assert 0 < lo <= hi


def test_slew_and_protocol_facts():
    slew = slew_facts()
    # 2 µs full-stroke time over A_max: 202 nm (R = 1 mm) and 96 nm (R = 0.25 mm)
    assert slew["ns_per_nm_b"] == pytest.approx(2000 / 202, rel=1e-9)
    assert slew["ns_per_nm_c"] == pytest.approx(2000 / 96, rel=1e-9)
    found = facts.protocol_facts(RunConfig(profile="quick"))
    assert found["tol_nm"] == pytest.approx(0.5) and found["periods"] == critical_amplitude.STEADY_PERIODS
    assert found["flyback_us_40"] == pytest.approx(40 / 202 * 2, rel=1e-9)
    assert facts.band_text(RunConfig(profile="paper"))["band_here"] == "as in this build"


def test_continued_operation_strains_the_sides_against_each_other(quick):
    """Below the steady-state A_c the two sides end every period pushing against each other."""
    prestrain = side_prestrain(quick["fig56_frequency"])
    assert len(prestrain) == critical_amplitude.STEADY_PERIODS
    last = prestrain.iloc[-1]
    assert last["side 1: T_1 / μF_N1"] < 0 < last["side 2: T_2 / μF_N2"]


def test_flyback_steps_ratchet_below_eq7():
    steps = figures.fig5_flyback_steps(RunConfig(profile="quick"))
    first = steps.iloc[0]
    assert first["steady_ac_nm"] < first["u_x_max_nm"]
    below = steps[steps["amplitude_nm"] == steps["amplitude_nm"].unique()[0]]
    assert below["step_nm"].iloc[-1] < first["threshold_nm"]  # 2 nm below A_c: no steady step
    import matplotlib.pyplot as plt

    fig = figure_table.figure_plot("fig5_flyback_steps", steps)
    assert fig.axes[0].has_data()
    plt.close(fig)


def test_paragraph_facts_of_both_chapters(quick):
    """Every fact function the chapters glue returns finite numbers or a sentence, on the quick data."""
    quick_config = RunConfig(profile="quick")
    found = facts.fig5b_facts(quick["fig5b"], quick_config)
    assert found["first_rigid_max"] < 2.0 and found["steady_rigid_mean"].endswith(("below", "above"))
    assert "quick profile runs 100 Hz only" in found["band_rigid"]
    columns = {"Eq. 11": "u_x_max_e_nm", "Eq. 10, side 1": "u_x_max_1_nm", "Eq. 10, side 2": "u_x_max_2_nm"}
    six = fig6a_facts(deviation_table(quick["fig6a"], columns), quick_config)
    assert six["a_e"] < min(six["a_1"], six["a_2"]) and six["a_band"].startswith("(the quick profile")
    flexible = {"Eq. 12": "u_x_max_e_star_nm", "Eq. 13, side 1": "u_x_max_1_star_nm"}
    dev6 = pd.concat([deviation_table(quick[n], flexible).assign(figure=n)
                      for n in ("fig6b", "fig6c")])
    bc = fig6bc_facts(dev6)
    assert set(bc) == {f"{k}_{s}" for k in "bc" for s in ("slew", "fixed", "first_fixed")}
    visc = viscosity_facts(quick["fig56_viscosity"])
    assert visc["v6_fixed_lo"] <= visc["v6_fixed_hi"] and visc["eq8_04"] > visc["eq12_04"]
    freq = frequency_facts(quick["fig56_frequency"], quick_config)
    assert freq["f_hi"] == 1000.0 and freq["first_span"] >= 0
    assert freq["first_band"].endswith("Figs. 5b and 6.)")
    table = pd.DataFrame({"side 1: T_1 / μF_N1": [-0.1], "side 2: T_2 / μF_N2": [0.1]})
    table.attrs["amplitude_nm"] = 23.9
    expected = {"prestrain_amplitude": 23.9, "prestrain_1": -0.1, "prestrain_2": 0.1}
    assert prestrain_facts(table) == expected
