"""Calibration (passmd.protocols.fit, ``passmd fit``): round trips through the package's own
simulator, the identifiability verdict, and malformed measurement files.

The round trips use one contact with rigid actuators (a run costs milliseconds) in this process
(``executor="serial"``), with a fixed noise seed: they are deterministic.
"""

from __future__ import annotations

import io
import json
from dataclasses import replace

import numpy as np
import pytest

import passmd
from passmd import cli
from passmd.model.parameters import Drive
from passmd.protocols import fit as F

RIGID = Drive(contacts=1, actuator_model="rigid")
HEADER = ["amplitude_nm", "preload_N", "frequency_Hz", "step_nm", "step_nm_sd"]
#: Measurement noise of the synthetic data (nm): a stand's step resolution.
NOISE_NM = 0.5


def _synthetic(truth: Drive, preloads, amplitudes, seed: int, cache) -> F.Measurements:
    rows = [[str(a), str(p), "100", "0", str(NOISE_NM)] for p in preloads for a in amplitudes]
    data = F.measurements_from_rows(HEADER, rows)
    exact = F.predict(truth, data, executor="serial", cache=cache)
    noise = np.random.default_rng(seed).normal(0.0, NOISE_NM * 1e-9, exact.size)
    return replace(data, value=exact + noise)


def test_round_trip_interval_contains_the_true_friction_coefficient(tmp_path):
    """Steps at two preloads, simulated at μ = 0.25 with 0.5 nm noise: the fit's profile interval
    holds 0.25, and the estimate is within 3 standard errors of it (a wrong model or a broken
    Jacobian moves it by far more: μ changes the step by ~40 nm per 0.1 at 0.4 N)."""
    truth = RIGID.replace(friction_coefficient=0.25)
    data = _synthetic(truth, (0.2, 0.4), (60, 100, 140), seed=3, cache=tmp_path)
    result = F.fit(RIGID, data, ["friction_coefficient"], executor="serial", cache=tmp_path, starts=4)
    est = result.estimates["friction_coefficient"]
    low, high = est["interval"]
    assert low < 0.25 < high
    assert abs(est["value"] - 0.25) < 3 * est["stderr"]
    assert low < est["value"] < high
    assert result.identifiable and result.converged
    assert result.drive.friction_coefficient == pytest.approx(est["value"], rel=1e-12)
    # noise of the stated size: the normalised residuals scatter like N(0, 1) (6 rows: a loose bound)
    assert np.sqrt(np.mean(result.residuals ** 2)) < 3.0


def test_a_biased_model_leaves_the_truth_outside(tmp_path):
    """Counter-example: the same data with the model biased (the drive's preload doubled on every
    row) leaves 0.25 outside the interval, so the interval check above can fail."""
    truth = RIGID.replace(friction_coefficient=0.25)
    data = _synthetic(truth, (0.2, 0.4), (60, 100, 140), seed=3, cache=tmp_path)
    biased = replace(data, preload=data.preload * 2.0)
    result = F.fit(RIGID, biased, ["friction_coefficient"], executor="serial", cache=tmp_path, starts=4)
    low, high = result.estimates["friction_coefficient"]["interval"]
    assert not low < 0.25 < high


def test_a_rough_parameter_is_scanned_out_of_a_local_minimum(tmp_path, monkeypatch):
    """The step of a flexible drive oscillates in k_p (one contact: ±3–5 nm over a period of about
    12 % of k_p at 0.4–0.6 N), so the cost of steps against k_p is a comb of minima. A local search
    from k_p = 5.64e6 N/m (truth 5e6, no global pass) stops in the neighbouring minimum near 5.9e6;
    the scan of the rough parameter finds the truth's basin and the interval holds 5e6. Without the
    scan (the counter-example) the same fit ends in that minimum with an interval that misses it."""
    flexible = Drive(contacts=1)
    stiffness = F.FREE_PARAMETERS["actuator.stiffness"]
    truth = stiffness.set(flexible, 5e6, flexible)
    rows = [[str(a), str(p), "100", "0", str(NOISE_NM)] for p in (0.4, 0.6) for a in (120, 160, 200)]
    data = F.measurements_from_rows(HEADER, rows)
    exact = F.predict(truth, data, executor="serial", cache=tmp_path)
    data = replace(data, value=exact + np.random.default_rng(1).normal(0.0, NOISE_NM * 1e-9, exact.size))
    start = stiffness.set(flexible, 5.64e6, flexible)
    result = F.fit(start, data, ["actuator.stiffness"], starts=0, executor="serial", cache=tmp_path)
    low, high = result.estimates["actuator.stiffness"]["interval"]
    assert low < 5e6 < high and result.converged
    monkeypatch.setattr(F.estimator, "SCAN_ROUNDS", 0)
    stuck = F.fit(start, data, ["actuator.stiffness"], starts=0, executor="serial", cache=tmp_path)
    low, high = stuck.estimates["actuator.stiffness"]["interval"]
    assert not low < 5e6 < high
    assert stuck.cost > result.cost + 3.84  # a worse minimum by more than the 95 % profile rise


def test_a_fit_stopped_in_a_local_minimum_says_so_and_claims_no_intervals(tmp_path, monkeypatch):
    """A local search cut to one evaluation stops at the start (μ = 0.2, the truth 0.25) and no
    new search may follow: the profile of μ meets a lower cost than the estimate, so the result
    says it has not converged and the verdict claims no identifiability (the round trip above,
    with the full search, is the counter-example: converged and identifiable)."""
    monkeypatch.setattr(F.estimator, "LOCAL_EVALUATIONS", 1)
    monkeypatch.setattr(F.estimator, "REFITS", 0)
    monkeypatch.setattr(F.estimator, "SCAN_ROUNDS", 0)
    truth = RIGID.replace(friction_coefficient=0.25)
    data = _synthetic(truth, (0.2, 0.4), (60, 100, 140), seed=3, cache=tmp_path)
    result = F.fit(RIGID.replace(friction_coefficient=0.2), data, ["friction_coefficient"], executor="serial",
                   cache=tmp_path, starts=0)
    assert result.estimates["friction_coefficient"]["value"] == pytest.approx(0.2, rel=1e-9)
    assert not result.converged and not result.identifiable
    assert result.verdict.startswith("Not converged to the global minimum")
    assert result.report()["converged"] is False


def test_a_parameter_the_data_cannot_see_is_reported_not_identifiable(tmp_path):
    """With rigid actuators at 100 Hz the full-stroke fly-back time moves the step by < 0.05 nm over
    its whole range, a tenth of the noise: its profile is flat and the verdict says so."""
    truth = RIGID.replace(friction_coefficient=0.25)
    data = _synthetic(truth, (0.4,), (60, 100, 140, 180), seed=5, cache=tmp_path)
    result = F.fit(RIGID, data, ["friction_coefficient", "flyback_time"], executor="serial", cache=tmp_path,
                   starts=4)
    assert not result.identifiable
    assert result.estimates["flyback_time"]["flat_profile"]
    assert "flyback_time is not identifiable" in result.verdict
    assert "add" in result.verdict  # says what data to add
    report = result.report()
    assert set(report) >= {"estimates", "residuals", "correlation", "identifiable"}
    assert set(report["estimates"]["flyback_time"]) >= {"value", "stderr", "interval", "unit"}


@pytest.mark.parametrize("text, fragment", [
    ("amplitude_nm,frequency_Hz,step_nm\n60,100,abc\n",
     "row 1 (line 2), column step_nm: 'abc' is not a number"),
    ("amplitude_nm,frequency_Hz,step_nm\n60,100,1\n\n70,100,2,3\n", "row 2 (line 4): 4 fields"),
    ("amplitude_nm,frequency_Hz,step_um\n60,100,1\n", "column 3 'step_um': not a known column"),
    ("amplitude_nm,frequency_Hz\n60,100\n", "no measured column"),
    ("amplitude_nm,step_nm\n60,1\n", "row 1 (line 2), column frequency_Hz: missing"),
    ("amplitude_nm,frequency_Hz,step_nm,force_N\n60,100,1,0.1\n",
     "row 1 (line 2), column force_N: more than one"),
    ("amplitude_nm,frequency_Hz,step_nm,step_nm_sd\n60,100,1,0.5\n70,100,2,\n",
     "row 2 (line 3), column step_nm_sd: missing"),
    ("amplitude_nm,frequency_Hz,step_nm\n-60,100,1\n",
     "row 1 (line 2), column amplitude_nm: -60 is out of range"),
    ("amplitude_nm,frequency_Hz,step_nm\n", "no measurement rows"),
    ("", "empty file"),
    ("amplitude_nm,frequency_Hz,step_nm,contacts\n60,100,1,3\n",
     "row 1 (line 2), column contacts: '3' is not allowed"),
])
def test_malformed_files_get_one_line_naming_row_and_column(tmp_path, text, fragment):
    path = tmp_path / "data.csv"
    path.write_text(text)
    with pytest.raises(F.MeasurementError) as info:
        F.read_measurements(path)
    message = str(info.value)
    assert fragment in message and "\n" not in message


def test_a_well_formed_file_reads_in_si(tmp_path):
    path = tmp_path / "data.csv"
    path.write_text("amplitude_nm,preload_N,frequency_Hz,velocity_mm_per_s,critical_amplitude_nm\n"
                    "100,0.4,1000,0.05,\n,0.3,,,48\n")
    data = F.read_measurements(path)
    assert data.kind == ("velocity", "critical_amplitude")
    assert data.value == pytest.approx([0.05e-3, 48e-9], rel=1e-12)
    assert data.frequency[1] == 100.0  # a critical amplitude's default frequency (Section 4.1)
    assert not data.known_sd


def test_free_names_and_bounds_are_checked():
    data = F.measurements_from_rows(HEADER, [["60", "0.4", "100", "1", "0.5"],
                                             ["90", "0.4", "100", "2", "0.5"]])
    with pytest.raises(ValueError, match="not a parameter the fit can free"):
        F.fit(RIGID, data, ["preload"], executor="serial", cache=False)
    with pytest.raises(ValueError, match="no effect on ideally rigid"):
        F.fit(RIGID, data, ["actuator.stiffness"], executor="serial", cache=False)
    with pytest.raises(ValueError, match="cannot determine 2 free parameters"):
        F.fit(RIGID, data, ["friction_coefficient", "runner_mass"], executor="serial", cache=False)
    with pytest.raises(ValueError, match="0 < low < high"):
        F.fit(RIGID, data, ["friction_coefficient"], bounds={"friction_coefficient": (0.5, 0.1)},
              executor="serial", cache=False)
    low, high = F.default_bounds(Drive(), "actuator.damping_ratio")
    assert (low, high) == (1e-3, 10.0)


def _run(argv) -> tuple[int, str]:
    out = io.StringIO()
    import contextlib

    err = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            status = cli.main(list(argv))
        except SystemExit as exc:  # --help
            status = exc.code
    return status, out.getvalue() + err.getvalue()


def test_cli_fit_writes_report_figure_and_drive(tmp_path, monkeypatch):
    monkeypatch.setenv("PASSMD_CACHE_DIR", str(tmp_path / "cache"))
    truth = RIGID.replace(friction_coefficient=0.25)
    data = _synthetic(truth, (0.2, 0.4), (60, 120), seed=7, cache=tmp_path / "cache")
    F.write_measurements(tmp_path / "data.csv", data)
    status, text = _run(["fit", str(tmp_path / "data.csv"), "--free", "mu", "--contacts", "1", "--actuator",
                         "rigid", "--starts", "2", "--executor", "serial", "--json", "--out",
                         str(tmp_path / "out")])
    assert status == 0, text
    report = json.loads(text[text.index("{"):text.rindex("}") + 1])
    low, high = report["estimates"]["friction_coefficient"]["interval"]
    assert low < 0.25 < high
    assert (tmp_path / "out" / "fit.png").stat().st_size > 0
    # the fitted drive file reads back (as --drive does) to the fitted μ and the drive it started from
    fitted = passmd.load_drive(tmp_path / "out" / "fitted-drive.toml")
    assert fitted.friction_coefficient == report["estimates"]["friction_coefficient"]["value"]
    assert (fitted.contacts, fitted.actuator_model) == (1, "rigid")
    assert "fitted to data.csv" in (tmp_path / "out" / "fitted-drive.toml").read_text()
    # the outputs are never replaced
    status, text = _run(["fit", str(tmp_path / "data.csv"), "--free", "mu", "--contacts", "1", "--actuator",
                         "rigid", "--out", str(tmp_path / "out")])
    assert status == 2 and "already there" in text


def test_cli_fit_names_the_bad_row_and_option(tmp_path):
    path = tmp_path / "data.csv"
    path.write_text("amplitude_nm,frequency_Hz,step_nm\n60,100,x\n")
    status, text = _run(["fit", str(path), "--free", "mu"])
    assert status == 2 and "row 1 (line 2), column step_nm" in text and text.count("\n") == 1
    status, text = _run(["fit", str(path), "--free", "preload"])
    assert status == 2 and "--free = 'preload' is not allowed" in text


def test_the_papers_numbers_read_as_measurements():
    """The package's table of the paper's stated numbers is a valid measurement file, each row
    with the drive model it was stated for (a row without it would be fitted with the wrong drive)."""
    from passmd.ledger.reference import REFERENCE_DIR

    data = F.read_measurements(REFERENCE_DIR / "paper_as_data.csv")
    assert data.kind == ("critical_amplitude", "position")
    assert data.model == ({"contacts": 1, "actuator_model": "flexible"},
                          {"contacts": 6, "actuator_model": "rigid"})
    assert data.value == pytest.approx([50e-9, 552e-9], rel=1e-12)
    assert data.known_sd


def test_help_gives_every_option_a_default():
    status, text = _run(["fit", "--help"])
    assert status == 0
    blocks, current = {}, None
    for line in text.splitlines():
        stripped = line.strip()
        if line.startswith("  --"):  # an option's first line (continuations are indented further)
            current = stripped.split()[0].rstrip(",")
            blocks[current] = stripped
        elif current and line.startswith(" " * 10) and stripped:
            blocks[current] += " " + stripped
        else:
            current = None
    assert {"--free", "--bounds", "--mu", "--json", "--out"} <= set(blocks)
    for flag, help_text in blocks.items():
        assert "default:" in help_text, (flag, help_text)


def test_every_measured_quantity_has_a_plot_label():
    """The figure labels each measured column; a new quantity without a label fails the --out figure."""
    from passmd.plots import fit as plot

    assert set(F.MEASURED) <= set(plot._LABELS)
