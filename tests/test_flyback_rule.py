"""The fly-back rule is part of the drive (Section 2: V_pp and SR; the rule itself is an assumption):
the amplifier record holds it, a drive file reads and writes it, ``--flyback`` sets it on every
command that simulates, ``drive show`` says where it came from, and a library function's
``flyback=`` argument overrides it (default: the drive's own rule)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from passmd import cli
from passmd.model import waveforms
from passmd.model.drive_file import drive_toml, load_drive
from passmd.model.parameters import Drive
from passmd.model.tables import Amplifier
from passmd.protocols import critical_amplitude, fit, velocity


def run(argv, capsys):
    status = cli.main(list(argv))
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def with_rule(rule, drive: Drive | None = None) -> Drive:
    drive = Drive() if drive is None else drive
    return drive.replace(amplifier=Amplifier(flyback=rule))


@pytest.mark.parametrize("rule", ["slew", "fixed", 1.7e-6, 2.5e-7])
def test_the_rule_reads_back_from_a_drive_file(rule, tmp_path):
    drive = with_rule(rule)
    path = tmp_path / "d.toml"
    path.write_text(drive_toml(drive), encoding="utf-8")
    assert load_drive(path) == drive
    assert load_drive(path).amplifier.flyback == rule


@pytest.mark.parametrize("text, fragment", [
    ('[amplifier]\nflyback = "slow"\n', "amplifier.flyback = 'slow': must be \"slew\", \"fixed\" or a time"),
    ("[amplifier]\nflyback = -1\n", "amplifier.flyback = -1 is out of range: must be >= 1e-09 s"),
    ('[amplifier]\nflyback = "3 mm"\n', "amplifier.flyback = '3 mm'"),
    ("[amplifier]\nflyback = true\n", "amplifier.flyback = True"),
])
def test_a_bad_rule_in_a_file_is_one_line_naming_file_and_key(text, fragment, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ValueError) as caught:
        load_drive(path)
    assert fragment in str(caught.value) and str(path) in str(caught.value) and "\n" not in str(caught.value)


def test_a_bad_rule_in_the_record_is_refused():
    for bad in ("slow", 0.0, -1e-6, math.nan, True):
        with pytest.raises(ValueError, match="flyback"):
            Amplifier(flyback=bad)


def test_the_drives_rule_sets_the_flyback_and_an_argument_overrides_it():
    fixed, stated = with_rule("fixed"), with_rule(1.5e-6)
    full = Drive().amplifier.full_stroke_time
    for amplitude in (20e-9, 100e-9, 202e-9):
        assert waveforms.flyback_time(amplitude, fixed) == full
        assert waveforms.flyback_time(amplitude, stated) == 1.5e-6
        slew = waveforms.flyback_time(amplitude, Drive())
        assert slew == pytest.approx(amplitude / 202e-9 * full, rel=1e-15)
        assert waveforms.flyback_time(amplitude, fixed, "slew") == waveforms.flyback_time(amplitude, Drive())
    a = waveforms.sawtooth(100e-9, 100.0, fixed, periods=2)
    b = waveforms.sawtooth(100e-9, 100.0, Drive(), periods=2, flyback="fixed")
    np.testing.assert_array_equal(a.times, b.times)
    with pytest.raises(ValueError, match="flyback"):
        waveforms.sawtooth(100e-9, 100.0, Drive(), flyback="slow")


def test_the_default_keyword_gives_the_results_of_the_explicit_slew_rule():
    """Every library function's flyback= defaults to the drive's rule, which is "slew" unless the drive
    says otherwise: the results are bit for bit those of the explicit rule."""
    drive = Drive(contacts=1)
    default = critical_amplitude.steady_step(drive, 120e-9, periods=3)
    explicit = critical_amplitude.steady_step(drive, 120e-9, periods=3, flyback="slew")
    assert default["steps_m"] == explicit["steps_m"]
    fixed = critical_amplitude.steady_step(with_rule("fixed", drive), 120e-9, periods=3)
    explicit = critical_amplitude.steady_step(drive, 120e-9, periods=3, flyback="fixed")
    assert fixed["steps_m"] == explicit["steps_m"]
    assert fixed["steps_m"] != default["steps_m"]  # the rule matters
    settled = velocity.settled_step(with_rule("fixed", drive), 120e-9, 100.0)
    assert settled["step_m"] == velocity.settled_step(drive, 120e-9, 100.0, flyback="fixed")["step_m"]


@pytest.mark.parametrize("command", [
    ["run", "--periods", "2"],
    ["force", "--amplitude", "150nm", "--contacts", "1", "--periods", "17", "--max-periods", "17"],
    ["critical-amplitude", "--contacts", "1", "--actuator", "rigid", "--tolerance", "20nm"],
    ["sweep", "step", "--contacts", "1", "--vary", "amplitude=100nm,150nm", "--executor", "serial"],
])
def test_every_simulating_command_takes_flyback_and_reports_it(command, capsys, tmp_path, monkeypatch):
    monkeypatch.setenv("PASSMD_CACHE_DIR", str(tmp_path / "cache"))
    status, out, err = run([*command, "--flyback", "fixed", "--json"], capsys)
    assert status == 0, err
    text = json.dumps(json.loads(out))
    assert '"flyback": "fixed"' in text, text[:400]


def test_fit_takes_flyback(capsys):
    with pytest.raises(SystemExit):
        cli.main(["fit", "--help"])
    assert "--flyback RULE" in capsys.readouterr().out


def test_drive_show_lists_the_rule_with_its_source(tmp_path, capsys):
    path = tmp_path / "d.toml"
    path.write_text('[amplifier]\nflyback = "1.5 us"\n', encoding="utf-8")
    status, out, _ = run(["drive", "show", "--drive", str(path), "--json"], capsys)
    rows = {row["key"]: row for row in json.loads(out)["parameters"]}
    row = rows["amplifier.flyback"]
    assert row["value"] == 1.5e-6 and row["source"] == f"given in {path}"
    status, out, _ = run(["drive", "show", "--drive", str(path), "--flyback", "fixed", "--json"], capsys)
    rows = {row["key"]: row for row in json.loads(out)["parameters"]}
    row = rows["amplifier.flyback"]
    assert (row["value"], row["source"]) == ("fixed", "option --flyback")
    status, out, _ = run(["drive", "show"], capsys)
    assert "amplifier.flyback" in out and "slew" in out


@pytest.mark.parametrize("value, fragment", [
    ("slow", "--flyback = 'slow' is not allowed: must be slew, fixed or a time with its unit"),
    ("1.5", "--flyback = 1.5 has no unit"),
    ("-2us", "--flyback = '-2us' is out of range: must be >= 0.001 us"),
])
def test_a_bad_flyback_option_is_one_line(value, fragment, capsys):
    status, out, err = run(["run", "--periods", "2", f"--flyback={value}"], capsys)
    assert status == 2 and out == "" and fragment in err and err.strip().count("\n") == 0


def test_a_stated_flyback_cannot_have_its_slew_rate_fitted():
    data = fit.measurements_from_rows(["amplitude_nm", "frequency_Hz", "step_nm"], [["100", "100", "1"]] * 3)
    with pytest.raises(ValueError, match="has no effect: the drive's fly-back is a stated time"):
        fit.fit(with_rule(1.5e-6), data, ["flyback_time"], executor="serial", cache=False)
