"""Calibration (passmd.protocols.fit, ``passmd fit``): round trips on data made by other means than the
fit's own forward model (the integrator refined twofold and the last step of a 16-period run,
:func:`passmd.experiments.design_your_drive.facts.independent_steps`), the goodness-of-fit test, regions of
several pieces, the identifiability verdict, rows checked before anything is simulated, and
malformed measurement files.

One contact with rigid actuators (a run costs milliseconds) runs in this process
(``executor="serial"``); the six-contact fits run on a process pool. Noise seeds are fixed: the tests
are deterministic.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace

import numpy as np
import pytest
from cli_runs import run_main

import passmd
from passmd.model.parameters import Drive
from passmd.model.tables import Amplifier
from passmd.protocols import fit
from passmd.protocols.fit.prediction import drive_at
from passmd.protocols.synthetic import independent_steps

RIGID = Drive(contacts=1, actuator_model="rigid")
HEADER = ["amplitude_nm", "preload_N", "frequency_Hz", "step_nm", "step_nm_sd"]
#: Measurement noise of the synthetic data (nm): a stand's step resolution.
NOISE_NM = 0.5


def _data(truth: Drive, preloads, amplitudes, seed: int, sd: float = NOISE_NM, flyback=None,
          values=None) -> fit.Measurements:
    """Steps of ``truth`` made independently of the fit's model (``flyback`` overrides its rule), plus
    Gaussian noise of ``sd`` nm, stated in the file."""
    conditions = [(p, a * 1e-9, 100.0) for p in preloads for a in amplitudes]
    exact = independent_steps(truth, conditions, flyback=flyback) if values is None else np.asarray(values)
    noisy = exact + np.random.default_rng(seed).normal(0.0, sd * 1e-9, exact.size)
    rows = [[repr(a * 1e9), repr(p), repr(f), repr(float(v * 1e9)), repr(sd)]
            for (p, a, f), v in zip(conditions, noisy, strict=True)]
    return fit.measurements_from_rows(HEADER, rows)


def _holds(result, name: str, value: float) -> bool:
    return any(low <= value <= high for low, high in result.estimates[name]["intervals"])


def test_round_trip_region_holds_the_true_friction_coefficient():
    """Steps at two preloads, made at μ = 0.25 with 0.5 nm noise: one closed region holding 0.25, the
    estimate within 3 local standard errors, and the χ² test passes (the model describes the data)."""
    truth = RIGID.replace(friction_coefficient=0.25)
    data = _data(truth, (0.2, 0.4), (60, 100, 140), seed=3)
    result = fit.fit(RIGID, data, ["friction_coefficient"], executor="serial", cache=False)
    est = result.estimates["friction_coefficient"]
    assert len(est["intervals"]) == 1 and _holds(result, "friction_coefficient", 0.25)
    assert abs(est["value"] - 0.25) < 3 * est["stderr"]
    assert est["interval"] == est["intervals"][0]
    assert result.identifiable and result.converged and not result.model_rejected
    assert result.goodness_of_fit["p_value"] > fit.REJECT_P and result.goodness_of_fit["dof"] == 5
    assert result.drive.friction_coefficient == pytest.approx(est["value"], rel=1e-12)
    # the estimate is the lowest point the fit saw: no point of any profile lies below it
    assert result.cost <= min(est["profile"]["cost"]) + 1e-9


def test_a_biased_model_leaves_the_truth_outside_and_the_test_rejects_it():
    """Counter-example: the same data with the model biased (the preload doubled on every row) leaves
    0.25 outside the region, and the χ² test says the model does not describe the data."""
    truth = RIGID.replace(friction_coefficient=0.25)
    data = _data(truth, (0.2, 0.4), (60, 100, 140), seed=3)
    biased = replace(data, preload=data.preload * 2.0)
    result = fit.fit(RIGID, biased, ["friction_coefficient"], executor="serial", cache=False)
    assert not _holds(result, "friction_coefficient", 0.25)
    assert result.model_rejected and not result.identifiable
    assert "does not describe the data" in result.verdict and "fly-back rule" in result.verdict
    assert result.report()["goodness_of_fit"]["rejected"] is True


def test_steps_falling_with_amplitude_are_never_called_identifiable():
    """Nonsense data (steps that fall as the amplitude rises) fit no drive: rejected, not identifiable."""
    data = _data(RIGID, (0.4,), (60, 100, 140, 180), seed=0, values=[90e-9, 70e-9, 50e-9, 30e-9])
    result = fit.fit(RIGID, data, ["friction_coefficient"], executor="serial", cache=False)
    assert result.model_rejected and not result.identifiable
    assert result.report()["identifiable"] is False and result.report()["model_rejected"] is True


def test_without_sd_the_goodness_of_fit_cannot_be_tested():
    truth = RIGID.replace(friction_coefficient=0.25)
    data = _data(truth, (0.2, 0.4), (60, 100, 140), seed=3)
    unknown = replace(data, sd=np.full(len(data), np.nan))
    result = fit.fit(RIGID, unknown, ["friction_coefficient"], executor="serial", cache=False)
    gof = result.goodness_of_fit
    assert gof["testable"] is False and gof["p_value"] is None and not result.model_rejected
    assert "cannot be tested" in result.verdict
    assert _holds(result, "friction_coefficient", 0.25)


def test_a_parameter_the_data_cannot_see_is_reported_not_identifiable():
    """With rigid actuators at 100 Hz the full-stroke fly-back time moves the step by < 0.05 nm over
    its whole range, a tenth of the noise: its region reaches a bound and the verdict says so."""
    truth = RIGID.replace(friction_coefficient=0.25)
    data = _data(truth, (0.4,), (60, 100, 140, 180), seed=5)
    result = fit.fit(RIGID, data, ["friction_coefficient", "flyback_time"], executor="serial", cache=False)
    assert not result.identifiable
    assert result.estimates["flyback_time"]["flat_profile"]
    assert "flyback_time is not identifiable" in result.verdict
    assert "add" in result.verdict  # says what data to add
    report = result.report()
    assert set(report) >= {"estimates", "residuals", "correlation", "identifiable", "goodness_of_fit"}
    assert set(report["estimates"]["flyback_time"]) >= {"value", "stderr", "interval", "intervals", "basins",
                                                        "unit"}


@pytest.mark.slow
def test_a_comb_in_k_p_gives_separate_pieces_and_the_row_that_separates_them():
    """One flexible contact, three steps at one preload: the step oscillates in k_p (±3–5 nm, a period
    of about 12 %), so teeth of the comb several periods apart fit the data within the 95 % level.
    The region is a set of separate pieces (one holds the truth), the verdict says "not uniquely
    identified" with the basins, and it names a computed added row whose predictions at the basins
    differ. A region from the best tooth alone (a local profile, the counter-example) would miss
    the other teeth: the pieces span more than a period of the comb."""
    flexible = Drive(contacts=1)
    truth = drive_at(flexible, ["actuator.stiffness"], [5e6], flexible.actuator.damping_ratio)
    data = _data(truth, (0.4,), (120, 160, 200), seed=1, sd=1.0)
    result = fit.fit(flexible, data, ["actuator.stiffness"], executor="serial", cache=False)
    est = result.estimates["actuator.stiffness"]
    assert len(est["intervals"]) >= 2 and _holds(result, "actuator.stiffness", 5e6)
    assert est["interval"] == [est["intervals"][0][0], est["intervals"][-1][1]]
    assert est["intervals"][-1][0] / est["intervals"][0][1] > 1.12  # more than a period apart
    assert not result.identifiable and "not uniquely identified" in result.verdict
    assert len(est["basins"]) >= 2
    row = result.next_measurement
    assert row is not None and row["excluded"] > 0 and f"{row['column']} at" in result.verdict
    spread = (max(row["predictions"]) - min(row["predictions"])) / 1e-9
    assert spread > 2.0  # the row tells the basins apart by more than its σ (1 nm) twice over
    assert json.loads(json.dumps(result.report()["next_measurement"])) == row


@pytest.mark.slow
def test_a_wrong_flyback_rule_is_rejected_by_the_goodness_of_fit_test():
    """Six flexible contacts: steps made with the fixed full-stroke fly-back, fitted with the slew-rate
    rule, fail the χ² test (the verdict names the fly-back rule); the same fit with the drive's rule
    set to "fixed" (the counter-example) passes it and its region holds the true μ."""
    six = Drive()
    truth = six.replace(friction_coefficient=0.25)
    data = _data(truth, (0.2, 0.4, 0.6), (110, 140, 170, 200), seed=2, flyback="fixed")
    wrong = fit.fit(six, data, ["friction_coefficient"])
    assert wrong.model_rejected and not wrong.identifiable
    assert "fly-back rule ('slew'" in wrong.verdict
    right = fit.fit(six.replace(amplifier=Amplifier(flyback="fixed")), data, ["friction_coefficient"])
    assert not right.model_rejected and _holds(right, "friction_coefficient", 0.25)
    assert right.report()["flyback"] == "fixed"


@pytest.mark.slow
@pytest.mark.parametrize("stiffness, seed", [(3.5e6, 11), (8.5e6, 12)])
def test_six_contacts_friction_and_stiffness_never_identifiable_with_a_region_that_misses_the_truth(
        stiffness, seed):
    """μ and k_p of six flexible contacts from twelve steady steps at three preloads (0.5 nm noise):
    whatever the verdict, it is never "identifiable" with a region that excludes the truth (the
    benchmark benchmarks/bench_fit_coverage.py counts the coverage over 40 draws)."""
    six = Drive()
    names = ["friction_coefficient", "actuator.stiffness"]
    truth = drive_at(six, names, [0.25, stiffness], six.actuator.damping_ratio)
    data = _data(truth, (0.2, 0.4, 0.6), (110, 140, 170, 200), seed=seed)
    result = fit.fit(six, data, names)
    holds = _holds(result, names[0], 0.25) and _holds(result, names[1], stiffness)
    assert holds or not result.identifiable, result.verdict


def test_rows_the_drive_cannot_run_are_refused_before_any_simulation(monkeypatch):
    """Each refusal is one line naming the file, the row, its line, the column, the value as the file
    gives it and the drive's limit; nothing is simulated (the sweep engine is never called)."""
    from passmd.runtime import sweep

    def never(*args, **kwargs):
        raise AssertionError("simulated before the rows were checked")

    monkeypatch.setattr(sweep, "run", never)
    header = ["amplitude_nm", "preload_N", "frequency_Hz", "radius_mm", "step_nm"]
    good = ["100", "0.4", "100", "", "50"]
    cases = [
        (["220", "0.4", "100", "", "50"], "column amplitude_nm = 220 is out of range: must be <= 202 nm"),
        (["150", "0.4", "4e5", "", "50"],
         "column frequency_Hz = 400000 is out of range: must be < 3.367e+05 Hz"),
        (["100", "400", "100", "", "50"], "column preload_N = 400 is out of range: must be <= 100 N"),
        (["100", "0.4", "100", "200", "50"], "column radius_mm = 200 is out of range: must be <= 100 mm"),
    ]
    for bad, fragment in cases:
        data = fit.measurements_from_rows(header, [good, good, bad], name="mine.csv")
        with pytest.raises(fit.MeasurementError) as caught:
            fit.fit(Drive(), data, ["friction_coefficient"], executor="serial", cache=False)
        message = str(caught.value)
        assert message.startswith("mine.csv row 3 (line 4), ") and fragment in message, message
        assert "\n" not in message


def test_a_free_flyback_is_checked_at_its_longest():
    """A row whose period holds the drive's fly-back but not the longest the bounds allow is refused."""
    data = fit.measurements_from_rows(["amplitude_nm", "frequency_Hz", "step_nm"],
                                    [["100", "1e5", "1"], ["100", "100", "1"], ["150", "100", "2"]])
    with pytest.raises(fit.MeasurementError, match="for the slew-limited fly-back"):
        fit.fit(RIGID, data, ["flyback_time"], bounds={"flyback_time": (1e-7, 2e-5)}, executor="serial",
              cache=False)


def test_free_takes_the_names_drive_show_uses():
    from passmd.cli.commands.fit import _free

    args = argparse.Namespace(free="friction_coefficient,actuator.stiffness")
    assert _free(args) == ["mu", "actuator-stiffness"]
    assert _free(argparse.Namespace(free="mu, damping-ratio")) == ["mu", "damping-ratio"]
    with pytest.raises(Exception, match="'preload' is not allowed"):
        _free(argparse.Namespace(free="preload"))
    with pytest.raises(Exception, match="names a parameter twice"):
        _free(argparse.Namespace(free="mu,friction_coefficient"))


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
    with pytest.raises(fit.MeasurementError) as info:
        fit.read_measurements(path)
    message = str(info.value)
    assert fragment in message and "\n" not in message


def test_a_well_formed_file_reads_in_si(tmp_path):
    path = tmp_path / "data.csv"
    path.write_text("amplitude_nm,preload_N,frequency_Hz,velocity_mm_per_s,critical_amplitude_nm\n"
                    "100,0.4,1000,0.05,\n,0.3,,,48\n")
    data = fit.read_measurements(path)
    assert data.kind == ("velocity", "critical_amplitude")
    assert data.value == pytest.approx([0.05e-3, 48e-9], rel=1e-12)
    assert data.frequency[1] == 100.0  # a critical amplitude's default frequency (Section 4.1)
    assert not data.known_sd


def _run(argv) -> tuple[int, str]:
    status, out, err = run_main(argv)
    return status, out + err


def test_the_papers_numbers_read_as_measurements():
    """The package's table of the paper's stated numbers is a valid measurement file, each row
    with the drive model it was stated for (a row without it would be fitted with the wrong drive)."""
    from passmd.ledger.reference import REFERENCE_DIR

    data = fit.read_measurements(REFERENCE_DIR / "paper_as_data.csv")
    assert data.kind == ("critical_amplitude", "position")
    assert data.model == ({"contacts": 1, "actuator_model": "flexible"},
                          {"contacts": 6, "actuator_model": "rigid"})
    assert data.value == pytest.approx([50e-9, 552e-9], rel=1e-12)
    assert data.known_sd


def test_the_book_holds_the_papers_numbers_to_the_ledgers_tolerances():
    """The calibration chapter's standard deviations are the tolerances of the ledger's claims on the
    same numbers (5 nm on the 50 nm, 5 % of the 552 nm), read from claims.csv, not typed."""
    from passmd.experiments.calibration.figures import PAPER_DATA_CLAIMS, paper_measurements
    from passmd.ledger.claims import load_claims

    data = paper_measurements()
    claims = load_claims().set_index("id")
    fig5a, fig9a = (claims.loc[PAPER_DATA_CLAIMS[row]] for row in PAPER_DATA_CLAIMS)
    assert data.sd[0] == pytest.approx(float(fig5a["tolerance_num"]) * 1e-9, rel=1e-12)
    assert data.sd[1] == pytest.approx(float(fig9a["tolerance_num"]) * 552e-9, rel=1e-12)
    assert fig9a["tolerance_kind"] == "rel" and data.sd[1] == pytest.approx(27.6e-9, rel=1e-9)


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
    import passmd.plots.fit

    assert set(fit.MEASURED) <= set(passmd.plots.fit._LABELS)


MINE = """\
hemisphere_radius = "1 mm"
contacts = "one"
runner_mass = "8 g"
friction_coefficient = 0.2

[actuator]
stiffness = "6e6 N/m"
damping_ratio = 0.08

[amplifier]
flyback = "fixed"
"""


@pytest.mark.slow
def test_the_fitted_drive_file_is_the_fit(tmp_path, monkeypatch):
    """``passmd fit --out`` on a user's drive file: fitted-drive.toml keeps the user's values with their
    sources, names the fitted ones, keeps the fly-back rule and holds ζ while k_p moves (drive show
    derives c_p from it); read back, it is the fitted drive, and ``run --steady`` and ``sweep step``
    on it reproduce the fit's predictions at the data's conditions to the settled step's accuracy.
    The outputs are never replaced."""
    monkeypatch.setenv("PASSMD_CACHE_DIR", str(tmp_path / "cache"))
    mine = tmp_path / "mine.toml"
    mine.write_text(MINE, encoding="utf-8")
    base = passmd.load_drive(mine)
    names = ["friction_coefficient", "actuator.stiffness"]
    truth = drive_at(base, names, [0.25, 5e6], base.actuator.damping_ratio)
    data = _data(truth, (0.3, 0.5), (120, 160, 200), seed=4)
    fit.write_measurements(tmp_path / "data.csv", data)
    out = tmp_path / "out"
    status, text = _run(["fit", str(tmp_path / "data.csv"), "--drive", str(mine), "--free",
                         "friction_coefficient,actuator-stiffness", "--executor", "serial", "--json", "--out",
                         str(out)])
    assert status == 0, text
    report = json.loads((out / "fit.json").read_text())
    assert report["flyback"] == "fixed" and report["keep"] == "damping_ratio"
    toml = (out / "fitted-drive.toml").read_text()
    line = {raw.split(" = ")[0]: raw for raw in toml.splitlines() if " = " in raw}
    assert f"given in {mine}" in line["runner_mass"] and "Table 1" not in line["runner_mass"]
    assert "fitted to data.csv" in line["friction_coefficient"] and "fitted to data.csv" in line["stiffness"]
    assert line["damping_ratio"].startswith("damping_ratio = 0.08") and "held while" in line["damping_ratio"]
    assert line["flyback"].startswith('flyback = "fixed"')
    fitted = passmd.load_drive(out / "fitted-drive.toml")
    assert fitted.friction_coefficient == report["estimates"]["friction_coefficient"]["value"]
    assert fitted.actuator.stiffness == report["estimates"]["actuator.stiffness"]["value"]
    assert fitted.actuator.damping_ratio == pytest.approx(0.08, rel=1e-12)
    assert (fitted.runner_mass, fitted.amplifier.flyback) == (8e-3, "fixed")
    status, text = _run(["drive", "show", "--drive", str(out / "fitted-drive.toml"), "--json"])
    shown = {row["key"]: row for row in json.loads(text[text.index("{"):])["parameters"]}
    assert shown["actuator.damping_ratio"]["source"] == f"given in {out / 'fitted-drive.toml'}"
    assert shown["actuator.viscosity"]["source"].startswith("derived from ζ = 0.08")
    for row in report["residuals"][:2]:  # 0.3 N at 120 and 160 nm
        i = report["residuals"].index(row)
        amplitude, preload = float(data.amplitude[i]), float(data.preload[i])
        status, text = _run(["run", "--steady", "--drive", str(out / "fitted-drive.toml"), "--periods", "20",
                             "--amplitude", f"{amplitude * 1e9!r}nm", "--frequency", "100Hz", "--preload",
                             repr(preload), "--json"])
        assert status == 0, text
        steady = json.loads(text[text.index("{"):])["steady"]["step_m"]
        assert steady * 1e9 == pytest.approx(row["predicted"], abs=0.05)  # the integrator's accuracy
        status, text = _run(["sweep", "step", "--drive", str(out / "fitted-drive.toml"), "--preload",
                             repr(preload), "--vary", f"amplitude={amplitude * 1e9!r}nm", "--frequency",
                             "100Hz", "--executor", "serial", "--json"])
        assert status == 0, text
        swept = json.loads(text[text.index("{"):])
        assert swept["rows"][0]["step_m"] * 1e9 == pytest.approx(row["predicted"], abs=0.05)
    status, text = _run(["fit", str(tmp_path / "data.csv"), "--drive", str(mine), "--free", "mu", "--out",
                         str(out)])
    assert status == 2 and "already there" in text


def test_cli_fit_refuses_a_bad_row_in_one_line(tmp_path):
    path = tmp_path / "data.csv"
    path.write_text("amplitude_nm,frequency_Hz,step_nm\n60,100,x\n")
    status, text = _run(["fit", str(path), "--free", "mu"])
    assert status == 2 and "row 1 (line 2), column step_nm" in text and text.count("\n") == 1
    path.write_text("amplitude_nm,frequency_Hz,step_nm\n60,100,1\n250,100,1\n")
    status, text = _run(["fit", str(path), "--free", "mu"])
    assert status == 2 and text.count("\n") == 1
    assert f"{path} row 2 (line 3), column amplitude_nm = 250 is out of range: must be <= 202 nm" in text
    status, text = _run(["fit", str(path), "--free", "preload"])
    assert status == 2 and "--free = 'preload' is not allowed" in text
