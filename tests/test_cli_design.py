"""The command line for a designer: ``run --steady`` is the book's steady-velocity protocol,
the Eq. 15 design's parts can be set, and ``critical-amplitude`` names its reading."""

from __future__ import annotations

import json

import pytest

from passmd.cli import main
from passmd.model.parameters import Drive
from passmd.model.waveforms import sawtooth
from passmd.protocols import velocity
from passmd.solver.simulation import simulate

RIGID_ONE = ["--contacts", "1", "--actuator", "rigid"]


def run_json(capsys, *argv):
    status = main([*argv, "--json"])
    out = capsys.readouterr().out
    assert status == 0
    return json.loads(out)


def test_run_steady_is_the_books_steady_velocity(capsys):
    data = run_json(capsys, "run", *RIGID_ONE, "--steady", "--frequency", "20kHz", "--max-points", "100")
    drive = Drive(contacts=1, actuator_model="rigid")
    periods = velocity.steady_periods(20e3)
    assert data["periods"] == periods and data["protocol"] == "steady"
    expected = velocity.steady_velocity(simulate(drive, sawtooth(202e-9, 20e3, drive, periods=periods),
                                                 max_points=2))
    # the same run, so the same velocity; tolerance: the record length changes nothing but round-off
    assert data["steady"]["velocity_m_per_s"] == pytest.approx(expected["velocity_m_per_s"], rel=1e-9)
    assert data["steady"]["step_m"] == pytest.approx(expected["velocity_m_per_s"] / 20e3, rel=1e-9)
    plain = run_json(capsys, "run", *RIGID_ONE, "--frequency", "20kHz", "--max-points", "100")
    assert plain["periods"] == 3 and "steady" not in plain and plain["protocol"] == "from rest"


def test_run_steady_needs_four_periods(capsys):
    assert main(["run", *RIGID_ONE, "--steady", "--periods", "3"]) == 2
    assert "must be an integer >= 4" in capsys.readouterr().err


def test_eq15_overrides_replace_the_design(capsys):
    base_run = run_json(capsys, "run", "--waveform", "optimized", "--actuator", "rigid", "--periods", "2",
                        "--max-points", "100")
    base = base_run["design"]
    given_run = run_json(capsys, "run", "--waveform", "optimized", "--actuator", "rigid", "--periods", "2",
                         "--max-points", "100", "--acceleration-time", "0.5us", "--settling-time", "40us")
    given = given_run["design"]
    assert given["acceleration_time_s"] == 0.5e-6 and given["settling_time_s"] == 40e-6
    assert given["acceleration_amplitude_m"] == base["acceleration_amplitude_m"]  # not given: designed
    assert given_run["design_given_by_options"] == ["settling_time", "acceleration_time"]
    assert base_run["design_given_by_options"] == []


@pytest.mark.parametrize(("argv", "fragment"), [
    (["run", "--acceleration-time", "1us"], "--acceleration-time needs --waveform optimized"),
    (["run", "--waveform", "optimized", "--acceleration-amplitude", "300nm"],
     "--acceleration-amplitude = 300nm is out of range: must be < 202 nm"),
    (["run", "--waveform", "optimized", "--settling-time", "5"], "--settling-time = 5 has no unit"),
])
def test_eq15_overrides_are_checked_before_running(argv, fragment, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert fragment in err and err.count("\n") == 1


def test_critical_amplitude_names_its_reading_and_says_what_each_means(capsys):
    data = run_json(capsys, "critical-amplitude", *RIGID_ONE, "--protocol", "first", "--tolerance", "5nm")
    assert data["reading"] == "simulated first"
    assert main(["critical-amplitude", *RIGID_ONE, "--analytic-only"]) == 0
    out = capsys.readouterr().out
    for name in ("analytic", "steady", "first"):
        assert f"what the {name} reading means" in out
