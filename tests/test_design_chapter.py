"""The data and fact functions of the chapter "Design your own drive" (experiments/design_your_drive)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from passmd.experiments import figure_table
from passmd.experiments.design_your_drive import facts, figures
from passmd.model.drive_file import DRIVE_KEYS, DriveFileError, load_drive
from passmd.runtime.config import RunConfig


def test_example_drive_is_the_chapter_drive_with_sources():
    drive, sources = figures.example_drive()
    assert figures.EXAMPLE_DRIVE_FILE.is_file()  # package data: an installed wheel has it too
    assert (drive.hemisphere_radius, drive.preload, drive.friction_coefficient) == (0.5e-3, 0.6, 0.25)
    assert (drive.actuator.stiffness, drive.actuator.mass, drive.runner_mass) == (5e6, 2e-6, 5e-3)
    assert drive.contacts == 6 and drive.actuator_model == "flexible" and not drive.allow_extrapolation
    assert sources["preload"] == "given in example_drive.toml"
    assert sources["actuator.full_stroke_amplitude"].startswith("Table 2 interpolated")
    assert sources["actuator.viscosity"].startswith("derived from ζ")


def test_example_mass_is_inside_the_plausible_range_and_a_heavier_one_is_not(tmp_path):
    """The example needs no allow_extrapolation; the benchmark's 1.5e-5 kg would."""
    text = figures.EXAMPLE_DRIVE_FILE.read_text(encoding="utf-8")
    heavy = tmp_path / "heavy.toml"
    heavy.write_text(text.replace('mass = "2e-6 kg"', 'mass = "1.5e-5 kg"'), encoding="utf-8")
    with pytest.raises(DriveFileError, match="actuator.mass.*out of range"):
        load_drive(heavy)


def test_parameter_table_has_every_drive_show_row():
    drive, sources = figures.example_drive()
    table = figures.parameter_table(drive, sources).set_index("key")
    assert list(table.index) == list(DRIVE_KEYS)
    assert table.loc["hemisphere_radius", ["value", "unit"]].tolist() == ["0.5", "mm"]
    assert table.loc["actuator.full_stroke_amplitude", "value"] == "131.3"  # Table 2 at 0.5 mm
    assert table.loc["contacts", "value"] == "6"  # derived from the groups
    assert table.loc["contact_groups", "value"] == "2 at 45° (side 1); 4 at 45° (side 2)"


@pytest.mark.parametrize("profile", ["quick", "paper"])
def test_map_grid_runs_frequency_slow_amplitude_fast(profile):
    drive, _ = figures.example_drive()
    s = figures.PROFILE_SETTINGS[profile]
    points = figures.map_points(drive, profile)
    assert len(points) == s.map_frequencies * s.map_amplitudes
    f = np.array([p["frequency_Hz"] for p in points]).reshape(s.map_frequencies, s.map_amplitudes)
    a = np.array([p["amplitude_m"] for p in points]).reshape(s.map_frequencies, s.map_amplitudes)
    assert np.all(f == f[:, :1]) and np.all(np.diff(f[:, 0]) > 0)
    assert np.all(a == a[:1, :]) and np.all(np.diff(a[0]) > 0)
    np.testing.assert_allclose([f[0, 0], f[-1, 0]], figures.MAP_FREQUENCY_RANGE, rtol=1e-12)  # round-off
    np.testing.assert_allclose([a[0, 0], a[0, -1]], [figures.MAP_AMPLITUDE_LOW,
                                                     drive.actuator.full_stroke_amplitude], rtol=1e-12)


@pytest.mark.parametrize("profile", ["quick", "paper"])
def test_stall_curve_holds_the_drives_own_preload(profile):
    """The chapter quotes the stall force at the example drive's preload: every profile computes it."""
    drive, _ = figures.example_drive()
    assert drive.preload in figures.PROFILE_SETTINGS[profile].stall_preloads


def test_profile_executor_applies_only_where_none_was_chosen():
    assert figures.run_config(RunConfig(), "quick").executor == "serial"
    assert figures.run_config(RunConfig(executor="process"), "quick").executor == "process"
    assert figures.run_config(RunConfig(), "paper").executor is None
    with pytest.raises(ValueError, match="profile = 'fast'"):
        figures.run_config(RunConfig(), "fast")


def _map_table(velocities, frequencies, amplitudes):
    grid = [(f, a) for f in frequencies for a in amplitudes]
    f = [f for f, _ in grid]
    return pd.DataFrame({"frequency_Hz": f, "amplitude_m": [a for _, a in grid],
                         "velocity_m_per_s": velocities, "step_m": np.array(velocities) / f})


def test_map_facts_find_the_fastest_point_and_the_top_row():
    # amplitudes 5 nm apart: only the largest is the top row (an absolute tolerance of 1e-8 m would
    # take both)
    table = _map_table([1e-4, 2e-4, 5e-3, 4e-3], [100.0, 1e4], [95e-9, 100e-9])
    found = facts.map_facts(table)
    assert found["v_max_mm_s"] == pytest.approx(5.0) and found["v_max_f_kHz"] == pytest.approx(10.0)
    assert found["v_max_A_nm"] == pytest.approx(95.0) and found["A_top_nm"] == pytest.approx(100.0)
    assert found["step_low_f_nm"] == pytest.approx(2e-4 / 100 * 1e9)  # largest amplitude, lowest f
    assert found["step_high_f_nm"] == pytest.approx(4e-3 / 1e4 * 1e9)
    assert found["map_points"] == 4


def test_gain_facts_count_missing_waveforms_and_signs():
    table = pd.DataFrame({"frequency_Hz": [1e3, 1e3, 1e4, 1e4], "amplitude_m": [5e-8, 1e-7, 5e-8, 1e-7],
                          "gain_m_per_s": [None, -1e-3, 2e-3, 5e-4]})
    found = facts.gain_facts(table)
    counts = (found["gain_points"], found["gain_designed"], found["gain_none"], found["gain_faster"])
    assert counts == (4, 3, 1, 2)
    assert found["gain_max_mm_s"] == pytest.approx(2.0) and found["gain_max_f_kHz"] == pytest.approx(10.0)
    assert found["gain_min_mm_s"] == pytest.approx(-1.0)
    none = facts.gain_facts(table.assign(gain_m_per_s=[None] * 4))
    assert none["gain_designed"] == 0 and "gain_max_mm_s" not in none


def test_contact_table_is_eq1_for_the_example_guide():
    """The example writes the paper's guide as groups: F_p/(2 sin 45°) and F_p/(4 sin 45°) per contact."""
    drive, _ = figures.example_drive()
    table = figures.contact_table(drive)
    assert table["side"].tolist() == [1, 2] and table["contacts"].tolist() == [2, 4]
    assert table["contact angle α [°]"].tolist() == pytest.approx([45.0, 45.0])
    sin45 = np.sin(np.pi / 4)
    assert table["F_N per contact [N]"].tolist() == [drive.preload / 2 / sin45, drive.preload / 4 / sin45]
    assert table["n F_N sin α [N]"].tolist() == pytest.approx([drive.preload] * 2, rel=1e-15)


def _curve(steady, closed=(30.0, 50.0, 70.0, 90.0), left=(2.0, 0.1, 3.0, 4.0)):
    return pd.DataFrame({"preload_N": [0.2, 0.4, 0.6, 0.8], "closed_form_nm": closed, "steady_nm": steady,
                         "first_nm": [25.0, 45.0, 65.0, 85.0], "ringing_left_nm": left,
                         "ringing_affects": [v > 0.5 for v in left]})


def test_curve_facts_say_where_the_closed_form_is_exceeded_and_how_often_the_curve_turns():
    below = facts.curve_facts(_curve([20.0, 40.0, 60.0, 80.0]))
    assert below["ca_closed_above"] == 4 and below["ca_turns"] == 0 and below["ca_ringing_points"] == 3
    # a drive whose steady A_c exceeds the closed form at one preload and turns twice
    jagged = facts.curve_facts(_curve([20.0, 55.0, 52.0, 80.0]))
    assert jagged["ca_closed_above"] == 3 and jagged["ca_excess_nm"] == pytest.approx(5.0)
    assert jagged["ca_excess_at_N"] == 0.4 and jagged["ca_turns"] == 2
    assert jagged["ca_ringing_left_nm"] == 4.0
    # a dip within the measurable step is no turn
    assert facts.curve_facts(_curve([20.0, 40.0, 39.8, 80.0]))["ca_turns"] == 0


def test_ringing_facts_read_the_probe():
    probe = {"ringing_frequency_Hz": 5e3, "ringing_amplitude_m": 40e-9, "ringing_decay_time_s": 3e-3,
             "ringing_hold_s": 20e-3, "flyback_time_s": 1e-6,
             "swing_times_s": np.array([1e-4, 5e-3, 9.999e-3, 15e-3]),
             "swing_amplitudes_m": np.array([40e-9, 10e-9, 5e-9, 0.4e-9])}
    found = facts.ringing_facts(probe, 100.0)
    assert found["ring_f_kHz"] == 5.0 and found["ring_amp_nm"] == pytest.approx(40.0)
    assert found["ring_left_nm"] == pytest.approx(5.0, rel=1e-3)
    assert found["ring_quiet_ms"] == pytest.approx(15.0)
    assert found["ring_next_ms"] == pytest.approx(9.999)


@pytest.mark.slow
@pytest.mark.parametrize("name", [spec.name for spec in figure_table.FIGURES
                                  if spec.chapter in ("design_your_drive", "calibration")])
def test_every_row_of_the_design_and_calibration_pages_is_a_passmd_figure(name, tmp_path):
    """`passmd figure NAME --profile quick` computes each row's table (finite, but for the cells its
    row leaves empty by design) and draws it; the table holds what its plot reads."""
    from passmd import cli

    assert cli.main(["figure", name, "--profile", "quick", "--out", str(tmp_path)]) == 0
    written = pd.read_csv(tmp_path / f"{name}.csv", comment="#")
    assert len(written) > 0 and (tmp_path / f"{name}.png").stat().st_size > 0


def _found(*shares):
    causes = [{"cause": f"c{k}", "changed": "x", "counterfactual_value": None if s is None else 1e-8,
               "share": s} for k, s in enumerate(shares)]
    named = [c["cause"] for c in causes if c["share"] is not None and c["share"] >= 0.5]
    return {"values": [30e-9], "expected": [20e-9], "causes": causes, "named": named}


def test_diagnosis_facts_give_the_naming_shares_that_name_the_same_causes():
    """The sensitivity of assumption diagnosis_thresholds, from the shares the diagnosis computed."""
    assert facts.diagnosis_facts(_found(1.05, 0.2, None))["why_naming_range"] == \
        "for any naming share above 20 % and up to 105 %"
    assert facts.diagnosis_facts(_found(0.6, 0.55))["why_naming_range"] == "for any naming share up to 55 %"
    assert facts.diagnosis_facts(_found(0.3))["why_naming_range"] == "for any naming share above 30 %"
    assert facts.diagnosis_facts(_found(None))["why_naming_range"] == "whatever the naming share"
    # a cause whose removal widens the departure (a negative share) bounds no threshold
    assert facts.diagnosis_facts(_found(0.9, -0.05))["why_naming_range"] == "for any naming share up to 90 %"
