"""``passmd sweep``: a quantity over --vary axes, as a user runs it.

The values must be the protocols' own (the command computes nothing itself): rows are
compared *exactly* with the point functions of passmd.protocols.maps called on the drive
the options describe (same deterministic code, same SI inputs; JSON round-trips floats).
"""

import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from test_cli import run_cli, run_json  # the command in this process, as the other CLI tests run it

from passmd.cli.commands.sweep import parse_vary
from passmd.model.parameters import Drive
from passmd.protocols import maps

#: A cheap drive for the map tests: one contact, rigid actuators (Tables 1–2 otherwise).
CHEAP = ("--contacts", "1", "--actuator", "rigid")


def test_vary_ranges_lists_and_bare_si_numbers():
    log = parse_vary("frequency=100Hz..110kHz:log:24")
    assert len(log.values) == 24 and log.spacing == "log"
    assert log.values[0] == 100.0 and log.values[-1] == 110e3  # the ends exactly as typed
    ratios = np.diff(np.log(log.values))
    assert np.allclose(ratios, ratios[0], rtol=1e-9)  # geometric: equal ratios (rounding only)
    lin = parse_vary("amplitude=50nm..200nm:4")
    assert lin.values == pytest.approx((50e-9, 100e-9, 150e-9, 200e-9), rel=1e-12)
    assert lin.spacing == "linear" and lin.column == "amplitude_m"
    assert parse_vary("preload=0.1N,0.4N,1N").values == (0.1, 0.4, 1.0)
    # bare numbers are SI: 0.3 is 0.3 N, 1e-7 is 100 nm, 1.5e-5 is 1.5e-5 kg (not grams)
    assert parse_vary("preload=0.3").values == (0.3,)
    assert parse_vary("amplitude=1e-7").values == (1e-7,)
    assert parse_vary("actuator-mass=1.5e-5").values == (1.5e-5,)
    assert parse_vary("actuator-mass=15mg").values == pytest.approx((1.5e-5,), rel=1e-15)
    assert parse_vary("actuator-mass=1.5e-5").column == "actuator_mass_kg"
    assert parse_vary("preload=0.1N..1N").values == pytest.approx(tuple(np.linspace(0.1, 1.0, 10)), rel=1e-12)


@pytest.mark.parametrize("vary, message", [
    ("foo=1,2", "--vary = 'foo=1,2': unknown parameter 'foo': must be one of amplitude, frequency, preload"),
    ("preload", "--vary = 'preload': must be NAME=LO..HI[:log][:N] or NAME=V1,V2,..."),
    ("frequency=1kHz..2kHz:1", "--vary = 'frequency=1kHz..2kHz:1': N = 1 is out of range: must be an integer "
                               "from 2 to 1000"),
    ("frequency=2kHz..1kHz", "the range 2kHz..1kHz is empty: LO must be below HI"),
    ("frequency=0Hz..1kHz:log", "a log range must start above 0, not at 0Hz"),
    ("frequency=1kHz..2kHz:cubic", "'cubic' is not an option of a range"),
    ("frequency=1kHz..300kHz:3",  # the fly-back must fit in half a period: checked before anything runs
     "--vary = 'frequency=1kHz..300kHz:3': 300 kHz is out of range: must be < 250 kHz (the fly-back of 2 µs"),
    ("amplitude=50nm..300nm:3",
     "--vary = 'amplitude=50nm..300nm:3': 300 nm is out of range: must be <= 202 nm, the actuator's full "
     "stroke"),
    ("amplitude=0nm,100nm", "--vary = 'amplitude=0nm,100nm': 0 nm is out of range: must be > 0 nm"),
    ("amplitude=1e-291nm,5nm",  # the fly-back it needs is shorter than a time step can resolve
     "--vary = 'amplitude=1e-291nm,5nm': 1e-291 nm is out of range: must be >= "),
    ("radius=0.5mm,0.2", "--vary = 'radius=0.5mm,0.2': 200 mm is out of range: must be <= 100 mm"),  # SI
    ("preload=1m", "--vary = 'preload=1m': '1m' has the wrong unit"),
    ("mu=0.1,x", "--vary = 'mu=0.1,x': 'x' is not a quantity"),
])
def test_bad_vary_is_one_line_naming_it_as_typed(vary, message, capsys, tmp_path):
    status, out = run_cli("sweep", "velocity", "--vary", vary, "--cache-dir", str(tmp_path / "c"))
    err = capsys.readouterr().err
    assert status == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("passmd sweep: error: "), err
    assert message in err, err
    assert not (tmp_path / "c").exists()  # refused before anything ran


@pytest.mark.parametrize("argv, message", [
    (["critical-amplitude", "--vary", "amplitude=1nm,2nm"], "critical-amplitude searches over the amplitude"),
    (["velocity", "--vary", "preload=0.1N,0.2N", "--preload", "0.3N"],
     "--vary = 'preload=0.1N,0.2N' contradicts --preload 0.3N"),
    (["velocity", "--vary", "preload=0.1N", "--reading", "first"],
     "--reading first has no effect on velocity"),
    (["gain", "--vary", "preload=0.1N", "--waveform", "optimized"],
     "--waveform optimized has no effect on gain"),
    (["velocity", "--vary", "preload=0.1N", "--vary", "preload=0.2N"], "--vary preload is given 2 times"),
    (["velocity"], "the following arguments are required: --vary"),
])
def test_contradicting_options_are_refused(argv, message, capsys, tmp_path):
    status, out = run_cli("sweep", *argv, "--cache-dir", str(tmp_path / "c"))
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1 and message in err, err


def test_step_over_preload_is_the_protocols_value(tmp_path):
    data = run_json("sweep", "step", "--vary", "preload=0.2N,0.4N", "--frequency", "1kHz", *CHEAP,
                    "--executor", "serial", "--cache-dir", str(tmp_path / "c"))
    assert data["quantity"] == "step" and data["column"] == "step_m" and data["waveform"] == "sawtooth"
    assert [row["preload_N"] for row in data["rows"]] == [0.2, 0.4]
    for row in data["rows"]:
        drive = Drive(preload=row["preload_N"], contacts=1, actuator_model="rigid")
        expected = maps.steady_point(drive, drive.actuator.full_stroke_amplitude, 1e3)
        assert row["amplitude_m"] == drive.actuator.full_stroke_amplitude and row["frequency_Hz"] == 1e3
        for key in ("step_m", "velocity_m_per_s", "back_step_m"):
            assert row[key] == expected[key], key
    assert data["rows"][0]["step_m"] != data["rows"][1]["step_m"]
    assert data["provenance"]["passmd_version"] and data["provenance"]["git_commit"]
    assert data["sweep"] == {"points": 2, "cached": 0, "computed": 2}
    status, text = run_cli("sweep", "step", "--vary", "preload=0.2N,0.4N", "--frequency", "1kHz", *CHEAP,
                           "--executor", "serial", "--cache-dir", str(tmp_path / "c"))
    assert status == 0 and "2 (2 from the cache, 0 computed)" in text
    for row in data["rows"]:  # a short curve is listed in full, in nm
        assert re.search(rf"preload {row['preload_N']:.6g} N +{row['step_m'] / 1e-9:.6g} nm", text), text


def test_a_map_writes_csv_json_png_in_grid_order_and_reruns_from_the_cache(tmp_path):
    cache, prefix = str(tmp_path / "c"), str(tmp_path / "map")
    argv = ("sweep", "velocity", "--vary", "frequency=500Hz..4kHz:log:3", "--vary", "amplitude=60nm..180nm:4",
            *CHEAP, "--workers", "2", "--cache-dir", cache, "--out", prefix)
    status, text = run_cli(*argv)
    assert status == 0, text
    assert "12 (0 from the cache, 12 computed)" in text and "map.png" in text
    lines = Path(prefix + ".csv").read_text().splitlines()
    assert lines[0].startswith("# passmd_version: ") and lines[1].startswith("# git_commit: ")
    assert lines[2].startswith("# arguments: ") and '"frequency=500Hz..4kHz:log:3"' in lines[2]
    table = pd.read_csv(prefix + ".csv", comment="#")
    assert list(table.columns[:2]) == ["frequency_Hz", "amplitude_m"]
    assert table["frequency_Hz"].tolist() == pytest.approx(np.repeat([500.0, 500.0 * 8**0.5, 4000.0], 4))
    assert table["amplitude_m"].tolist() == pytest.approx(np.tile([60e-9, 100e-9, 140e-9, 180e-9], 3))
    drive = Drive(contacts=1, actuator_model="rigid")
    corner = maps.steady_point(drive, 180e-9, 4000.0)
    # CSV text: pandas reads back the repr, within one unit in the last place
    assert table["velocity_m_per_s"].iloc[-1] == pytest.approx(corner["velocity_m_per_s"], rel=1e-15)
    record = json.loads(Path(prefix + ".json").read_text())
    assert [a["name"] for a in record["axes"]] == ["frequency", "amplitude"]
    assert record["axes"][0]["spacing"] == "log"
    assert record["axes"][0]["typed"] == "frequency=500Hz..4kHz:log:3"
    assert record["rows"][-1]["velocity_m_per_s"] == corner["velocity_m_per_s"]
    assert record["files"]["png"] == prefix + ".png"
    assert Path(prefix + ".png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # the same map again (its files are never replaced: refused before any work), to a new prefix,
    # and a step map (same runs): every point from the cache
    status, text = run_cli(*argv)
    assert status == 2 and text == ""  # (one line on stderr naming map.csv)
    status, text = run_cli(*argv[:-1], prefix + "-again")
    assert status == 0 and "12 (12 from the cache, 0 computed)" in text
    data = run_json("sweep", "step", "--vary", "frequency=500Hz..4kHz:log:3",
                    "--vary", "amplitude=60nm..180nm:4", *CHEAP, "--executor", "serial", "--cache-dir", cache)
    assert data["sweep"]["cached"] == 12
    # a larger map reuses the points it shares with the first
    data = run_json("sweep", "velocity", "--vary", "frequency=500Hz..4kHz:log:3",
                    "--vary", "amplitude=60nm,100nm,140nm,180nm,200nm", *CHEAP, "--executor", "serial",
                    "--cache-dir", cache)
    assert data["sweep"]["cached"] == 12 and data["sweep"]["computed"] == 3


def test_critical_amplitude_names_its_reading_and_carries_the_closed_form(tmp_path):
    data = run_json("sweep", "critical-amplitude", "--reading", "first", "--vary", "preload=0.2N,0.4N",
                    *CHEAP, "--executor", "serial", "--cache-dir", str(tmp_path / "c"),
                    "--out", str(tmp_path / "ac"))
    assert data["reading"] == "first" and "amplitude_m" not in data["rows"][0]
    for row in data["rows"]:
        drive = Drive(preload=row["preload_N"], contacts=1, actuator_model="rigid")
        expected = maps.critical_amplitude_point(drive, 100.0, "first")
        assert row["critical_amplitude_m"] == expected["critical_amplitude_m"]
        assert row["analytic_critical_amplitude_m"] == expected["analytic_critical_amplitude_m"]
    steady = run_json("sweep", "critical-amplitude", "--vary", "preload=0.4N", *CHEAP, "--executor", "serial",
                      "--cache-dir", str(tmp_path / "c"))
    assert steady["reading"] == "steady"
    assert steady["rows"][0]["critical_amplitude_m"] != data["rows"][1]["critical_amplitude_m"]
    assert Path(tmp_path / "ac.png").is_file()


def test_gain_is_missing_where_eq15_gives_no_waveform(tmp_path):
    """A cell has no value, and its note says why, where Eq. 15 gives no waveform at the amplitude or
    its period does not fit: above the highest fitting frequency, a column of every designed cell."""
    from passmd.model.optimized_waveform import highest_fitting_frequency
    from passmd.protocols import eq15

    drive = Drive(contacts=1, actuator_model="rigid")
    f_max = highest_fitting_frequency(eq15.optimized_design(202e-9, drive), 202e-9, drive)
    low_f, high_f = f_max / 2, 2 * f_max
    axes = ("--vary", "amplitude=20nm,202nm", "--vary", f"frequency={low_f!r},{high_f!r}")
    data = run_json("sweep", "gain", *axes, *CHEAP, "--executor", "serial", "--cache-dir",
                    str(tmp_path / "c"), "--out", str(tmp_path / "g"))
    by = {(round(r["amplitude_m"] * 1e9), r["frequency_Hz"]): r for r in data["rows"]}
    for f in (low_f, high_f):
        assert by[20, f]["gain_m_per_s"] is None
        assert "no Eq. 15 waveform at this amplitude" in by[20, f]["note"]
    fits, too_fast = by[202, low_f], by[202, high_f]
    expected = maps.gain_point(drive, 202e-9, low_f)
    assert fits["gain_m_per_s"] == expected["gain_m_per_s"] and fits["note"] is None
    assert fits["gain_m_per_s"] == fits["optimized_velocity_m_per_s"] - fits["sawtooth_velocity_m_per_s"]
    assert fits["eq15_highest_frequency_Hz"] == pytest.approx(f_max, rel=1e-12)
    assert fits["response_frequency_Hz"] == 100.0 and data["design_response"] == "paper"
    assert too_fast["gain_m_per_s"] is None and too_fast["sawtooth_velocity_m_per_s"] is not None
    assert too_fast["note"].startswith("Eq. 15 does not fit the period") and f"{f_max / 1e3:.4g} kHz" in \
        too_fast["note"]
    assert data["missing_values"] == 3
    status, text = run_cli("sweep", "gain", *axes, *CHEAP, "--executor", "serial", "--cache-dir",
                           str(tmp_path / "c"))
    assert status == 0 and "3 points: 1 where Eq. 15 does not fit the period, 2 where Eq. 15 gives no " \
        "waveform at the amplitude (see the note column)" in text, text
    assert f"from the saw-tooth response at 100 Hz; fits up to {f_max / 1e3:.4g} kHz" in text, text


def test_stall_force_over_preload(tmp_path):
    data = run_json("sweep", "stall-force", "--vary", "preload=0.2N,0.4N", "--frequency", "1kHz", *CHEAP,
                    "--executor", "serial", "--cache-dir", str(tmp_path / "c"))
    for row in data["rows"]:
        drive = Drive(preload=row["preload_N"], contacts=1, actuator_model="rigid")
        assert row["generated_force_N"] == maps.stall_point(drive, drive.actuator.full_stroke_amplitude,
                                                            1e3)["generated_force_N"]
        assert row["generated_force_N"] <= row["coulomb_bound_N"]


def test_a_drive_axis_rederives_the_actuator_as_the_options_do(tmp_path):
    """--vary radius takes Table 2's actuator for each radius, as --radius does."""
    data = run_json("sweep", "velocity", "--vary", "radius=0.25mm,1mm", "--frequency", "2kHz",
                    "--contacts", "6", "--actuator", "flexible", "--executor", "serial",
                    "--cache-dir", str(tmp_path / "c"))
    amplitudes = [row["amplitude_m"] for row in data["rows"]]
    for radius, amplitude in zip((0.25, 1), amplitudes, strict=True):
        single = run_json("run", "--radius", f"{radius}mm", "--contacts", "6", "--actuator", "flexible",
                          "--frequency", "2kHz", "--periods", "2")
        assert amplitude == single["drive"]["full_stroke_amplitude_m"]
    assert amplitudes[0] != amplitudes[1]


def _default_signals():  # in the child before exec: an inherited SIG_IGN would survive exec
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def test_ctrl_c_keeps_finished_points_and_the_rerun_computes_only_the_rest(tmp_path):
    """A map interrupted by Ctrl-C (exit 130) resumes from the cache: nothing finished is recomputed.

    The two lowest frequencies are computed; every other point waits at a gate
    (``tests/gates.py``) until the test has seen both of them cached and both workers at the
    gate, and Ctrl-C goes to the process group (as a terminal sends it) at that state.
    """
    cache, gates = tmp_path / "c", tmp_path / "gates"
    gates.mkdir()
    argv = ["sweep", "velocity", "--vary", "frequency=100Hz..400Hz:8", *CHEAP, "--workers", "2",
            "--cache-dir", str(cache)]
    env = {**os.environ, "MPLBACKEND": "Agg", "CI": "true", "GATE_ABOVE_HZ": "150"}  # 100 and 142.9 Hz pass
    gated = [sys.executable, str(Path(__file__).with_name("gates.py")), str(gates), "point", *argv]
    proc = subprocess.Popen(gated, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                            preexec_fn=_default_signals, start_new_session=True)
    try:
        deadline = time.monotonic() + 240  # (only detects a hang)
        while len(list(gates.glob("point-*"))) < 2 or len(list(cache.rglob("*.pmc"))) < 2:
            assert time.monotonic() < deadline and proc.poll() is None, proc.communicate()
            time.sleep(0.05)
        os.killpg(proc.pid, signal.SIGINT)
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()
    assert (proc.returncode, out, err) == (130, "", "passmd sweep: interrupted\n")
    assert len(list(cache.rglob("*.pmc"))) == 2
    done = subprocess.run([sys.executable, "-m", "passmd", *argv, "--json"], capture_output=True, text=True,
                          env=env, timeout=600)
    assert done.returncode == 0, done.stderr
    counts = json.loads(done.stdout)["sweep"]
    assert counts == {"points": 8, "cached": 2, "computed": 6}
    assert all(math.isfinite(row["velocity_m_per_s"]) for row in json.loads(done.stdout)["rows"])


def test_help_explains_the_drift_and_its_limit():
    from passmd.cli.commands.sweep import STEADY_DRIFT_PERCENT
    from passmd.protocols.velocity import STEADY_DRIFT_LIMIT

    assert STEADY_DRIFT_PERCENT / 100 == STEADY_DRIFT_LIMIT
    _, text = run_cli("sweep", "--help")
    assert "velocity_drift" in text and f"beyond {STEADY_DRIFT_PERCENT} %" in text


@pytest.mark.parametrize(("typed", "values"), [
    ("preload=0.1N..1N:10", (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0)),
    ("amplitude=40nm..250nm:8", (4e-08, 7e-08, 1e-07, 1.3e-07, 1.6e-07, 1.9e-07, 2.2e-07, 2.5e-07)),
    ("mu=0.1..0.3:5", (0.1, 0.15, 0.2, 0.25, 0.3)),
])
def test_grid_values_are_written_as_typed(typed, values):
    """A linear grid in decimal: the CSV holds 0.4 for 0.1..1:10, not 0.39999999999999997."""
    assert parse_vary(typed).values == values
    log = parse_vary("frequency=100Hz..110kHz:log:6").values
    assert log[0] == 100.0 and log[-1] == 110e3 and all(len(repr(v)) <= 14 for v in log)
    np.testing.assert_allclose(log, np.geomspace(100.0, 110e3, 6), rtol=1e-11)
