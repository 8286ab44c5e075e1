"""A fitted drive carries its uncertainty: ``passmd fit --out`` records the fit's region in the fitted
drive file, and ``sweep``/``run`` with that file report the band its points span (CSV columns, the
human output, a shaded band in the PNG). Also the plots that read right: ``fit.png`` one series per
measured condition, a map's log colour scale, ``force --plot`` in newtons."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from cli_runs import run_main
from matplotlib import colors

from passmd.model.drive_file import REGION_KEY, read_drive_file
from passmd.model.parameters import Drive
from passmd.protocols import fit
from passmd.protocols.synthetic import independent_steps

RIGID = Drive(contacts=1, actuator_model="rigid")
HEADER = ["amplitude_nm", "preload_N", "frequency_Hz", "step_nm", "step_nm_sd"]


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """μ fitted to steps of one rigid contact made at μ = 0.25 (by other means, 0.5 nm noise)."""
    where = tmp_path_factory.mktemp("fitted")
    conditions = [(p, a * 1e-9, 100.0) for p in (0.2, 0.4) for a in (60, 100, 140)]
    exact = independent_steps(RIGID.replace(friction_coefficient=0.25), conditions)
    noisy = exact + np.random.default_rng(3).normal(0.0, 0.5e-9, exact.size)
    rows = [[repr(a * 1e9), repr(p), repr(f), repr(float(v * 1e9)), "0.5"]
            for (p, a, f), v in zip(conditions, noisy, strict=True)]
    fit.write_measurements(where / "data.csv", fit.measurements_from_rows(HEADER, rows))
    status, _, err = run_main(["fit", str(where / "data.csv"), "--contacts", "1", "--actuator", "rigid",
                               "--free", "mu", "--executor", "serial", "--out", str(where / "out")])
    assert status == 0, err
    return where


def test_the_fitted_drive_records_its_region_and_what_was_held(fitted):
    path = fitted / "out" / "fitted-drive.toml"
    text = path.read_text()
    report = json.loads((fitted / "out" / "fit.json").read_text())
    low, high = report["estimates"]["friction_coefficient"]["interval"]
    points = read_drive_file(path)[REGION_KEY]
    mus = sorted(p["friction_coefficient"] for p in points)
    assert len(points) == 2 and mus == pytest.approx([low, high], rel=0.02)  # the region's two ends
    assert "# Fitted to data.csv: friction_coefficient" in text
    assert "ζ = 0.05 where the file gives neither" in text


def test_a_sweep_with_the_fitted_drive_has_a_band(fitted, tmp_path):
    prefix = tmp_path / "band"
    argv = ["sweep", "step", "--drive", str(fitted / "out" / "fitted-drive.toml"), "--vary",
            "amplitude=100nm,140nm", "--executor", "serial", "--out", str(prefix)]
    status, text, err = run_main(argv)
    assert status == 0, err
    table = pd.read_csv(f"{prefix}.csv", comment="#")
    assert (table["step_m_band_low"] <= table["step_m"]).all()
    assert (table["step_m"] <= table["step_m_band_high"]).all()
    assert (table["step_m_band_high"] - table["step_m_band_low"] > 0.05e-9).all()  # μ's region moves the step
    assert "fit's 95 % region" in text
    # counter-example: the same sweep on the drive without its region has no band
    plain = tmp_path / "plain.toml"
    plain.write_text((fitted / "out" / "fitted-drive.toml").read_text().split("[fit_region]")[0])
    status, out, _ = run_main([*argv[:2], "--drive", str(plain), *argv[4:-2], "--json"])
    assert status == 0 and "step_m_band_low" not in json.loads(out)["columns"]


def test_a_run_with_the_fitted_drive_has_a_band(fitted, tmp_path):
    csv = tmp_path / "run.csv"
    status, text, err = run_main(["run", "--drive", str(fitted / "out" / "fitted-drive.toml"), "--amplitude",
                                  "120nm", "--periods", "4", "--csv", str(csv), "--plot",
                                  str(tmp_path / "r.png")])
    assert status == 0, err
    frame = pd.read_csv(csv)
    assert (frame["runner_position_band_low_m"] <= frame["runner_position_band_high_m"]).all()
    assert (frame["runner_position_band_high_m"] - frame["runner_position_band_low_m"]).iloc[-1] > 0.1e-9
    assert "fit's 95 % region" in text


def test_fit_png_draws_one_series_per_preload_and_frequency():
    """Two preloads × two frequencies: four measured series, each model line through its own points only
    (a line per preload alone would zig-zag between the frequencies)."""
    from passmd.plots.fit import fit_figure

    conditions = [(p, f, a) for p in (0.3, 0.4) for f in (100.0, 1e3) for a in (80, 120)]
    rows = [{"line": i, "quantity": "step_nm", "kind": "step", "unit": "nm", "preload_N": p,
             "frequency_Hz": f, "amplitude_nm": a, "measured": a / 2 + f / 100, "sd": 0.5,
             "predicted": a / 2 + f / 100, "normalized_residual": 0.0}
            for i, (p, f, a) in enumerate(conditions)]
    table = pd.DataFrame(rows)
    table.attrs.update(estimates={"friction_coefficient": 0.2}, goodness_of_fit={})
    top = fit_figure(table).axes[0]
    lines = [ln for ln in top.get_lines() if ln.get_linestyle() == "-" and len(ln.get_xdata()) == 2]
    assert len(lines) == 4
    for line in lines:  # every model line holds one frequency: a constant offset a/2 + f/100
        x, y = (np.asarray(v, float) for v in line.get_data())
        assert len(set(np.round(y - x / 2, 9))) == 1


def test_maps_spanning_decades_get_a_log_colour_scale():
    from passmd.plots.sweep_map import MapAxis, map_figure

    table = pd.DataFrame({"f": [1.0, 1.0, 10.0, 10.0], "a": [1.0, 2.0, 1.0, 2.0],
                          "v": [1e-3, 2e-3, 0.5, 1.0]})
    axes = [MapAxis("f", "f", "", log=True), MapAxis("a", "a", "")]
    value = MapAxis("v", "v", "mm/s", scale=1.0)
    mesh = map_figure(table, axes, value, "t").axes[0].collections[0]
    assert isinstance(mesh.norm, colors.LogNorm)
    linear = map_figure(table, axes, value, "t", color_scale="linear").axes[0].collections[0]
    assert not isinstance(linear.norm, colors.LogNorm)
    with pytest.raises(ValueError, match="needs values > 0"):
        map_figure(table.assign(v=[-1e-3, 2e-3, 0.5, 1.0]), axes, value, "t", color_scale="log")


def test_the_force_plot_has_a_force_axis_in_newtons(tmp_path):
    status, _, err = run_main(["force", "--contacts", "1", "--actuator", "rigid", "--amplitude", "150nm",
                               "--frequency", "1kHz", "--plot", str(tmp_path / "f.png")])
    assert status == 0, err
    from passmd.model import waveforms
    from passmd.plots.force_generation import stall_trace_figure
    from passmd.solver import simulation

    drive = RIGID.replace(load_cell=True)
    result = simulation.simulate(drive, waveforms.sawtooth(150e-9, 1e3, drive, periods=3), max_points=200)
    top = stall_trace_figure(result, "t", 0.01, 0.08).axes[0]
    assert top.get_ylabel() == "force [N]"
    force = drive.load_cell_stiffness * result.runner_position
    np.testing.assert_allclose(top.get_lines()[0].get_ydata(), force)


def test_progress_and_verdict_count_the_region_the_same_way():
    """The progress names each parameter's region pieces, as the verdict and the report count them, and
    every basin the report lists per parameter is one of the fit's basins."""
    conditions = [(p, a * 1e-9, 100.0) for p in (0.2, 0.4) for a in (60, 100, 140)]
    exact = independent_steps(RIGID.replace(friction_coefficient=0.25), conditions)
    rows = [[repr(a * 1e9), repr(p), repr(f), repr(float(v * 1e9)), "0.5"]
            for (p, a, f), v in zip(conditions, exact, strict=True)]
    lines = []
    data = fit.measurements_from_rows(HEADER, rows)
    result = fit.fit(RIGID, data, ["friction_coefficient"], executor="serial", cache=False,
                     progress=lines.append)
    pieces = len(result.estimates["friction_coefficient"]["intervals"])
    estimate_lines = [line for line in lines if line.startswith("estimate ")]
    assert estimate_lines and f"friction_coefficient in {pieces} piece(s) (" in estimate_lines[-1]
    assert not any("basin(s) within" in line for line in lines)
    listed = {round(b["parameters"]["friction_coefficient"], 12) for b in result.basins}
    assert {round(b["value"], 12) for b in result.estimates["friction_coefficient"]["basins"]} <= listed
