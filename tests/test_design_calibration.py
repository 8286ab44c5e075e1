"""The design chapter's calibration (passmd.experiments.design_your_drive): measurements made by other
means than the fit's model, the fits' facts, and the fitted drive file read back."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from passmd.experiments.design_your_drive import facts, figures
from passmd.model.parameters import Drive
from passmd.model.tables import actuator_for_radius
from passmd.protocols import fit
from passmd.protocols.synthetic import independent_steps
from passmd.runtime.config import RunConfig


def test_fit_facts_say_whether_the_region_holds_the_truth():
    truth, _ = figures.example_drive()
    start = figures.start_drive(truth, ("friction_coefficient", "actuator.stiffness"))
    # the first guess is the paper's: μ of Table 1, k_p of Table 2 for the drive's radius
    assert start.friction_coefficient == Drive().friction_coefficient
    assert start.actuator.stiffness == pytest.approx(actuator_for_radius(truth.hemisphere_radius).stiffness)
    result = SimpleNamespace(names=["friction_coefficient", "actuator.stiffness"], estimates={
        "friction_coefficient": {"value": 0.249, "stderr": 0.003, "interval": [0.243, 0.256],
                                 "intervals": [[0.243, 0.256]]},
        "actuator.stiffness": {"value": 4.0e6, "stderr": 1e5, "interval": [3.8e6, 5.4e6],
                               "intervals": [[3.8e6, 4.2e6], [5.2e6, 5.4e6]]}})
    table = facts.fit_facts(result, truth, start).set_index("parameter")
    assert table.loc["friction_coefficient", "holds_truth"]
    # 5e6 lies in the hull 3.8–5.4e6 but in none of its two pieces
    assert not table.loc["actuator.stiffness", "holds_truth"]
    assert table.loc["actuator.stiffness", "pieces"] == 2
    assert table.loc["actuator.stiffness", "start"] == pytest.approx(start.actuator.stiffness)


def test_heldback_facts_rms():
    table = pd.DataFrame({"measured_nm": [10.0, 20.0], "start_nm": [13.0, 16.0], "fitted_nm": [10.0, 21.0]})
    found = facts.heldback_facts(table)
    assert found["rms_start_nm"] == pytest.approx(np.sqrt((9 + 16) / 2))
    assert found["rms_fitted_nm"] == pytest.approx(np.sqrt(0.5)) and found["heldback_points"] == 2


def test_fitted_drive_file_reads_back_to_the_fitted_drive():
    truth, sources = figures.example_drive()
    fitted = replace(truth, friction_coefficient=0.2493217)
    result = SimpleNamespace(drive=fitted, base=truth, names=["friction_coefficient"], keep="damping_ratio")
    text = fit.fitted_drive_file(result, "m.csv", sources)
    assert figures.load_fitted(text) == fitted
    line = {raw.split(" = ")[0]: raw for raw in text.splitlines() if " = " in raw}
    assert "fitted to m.csv by passmd fit" in line["friction_coefficient"]
    assert "given in" in line["runner_mass"] and "example_drive.toml" in line["runner_mass"]


def test_synthetic_measurements_are_independent_steps_plus_the_stated_noise(tmp_path):
    truth, _ = figures.example_drive()
    config = RunConfig(cache_dir=tmp_path)
    data, held = figures.synthetic_measurements(truth, "quick", config)
    s = figures.PROFILE_SETTINGS["quick"]
    assert len(data) == len(s.fit_preloads) * len(s.fit_amplitudes_nm) and len(held) == len(s.heldback)
    noise = np.random.default_rng(figures.SEED).normal(0.0, figures.NOISE_NM * 1e-9, len(data) + len(held))
    conditions = [(p, a, f) for p, a, f in zip(data.preload, data.amplitude, data.frequency, strict=True)]
    exact = independent_steps(truth, conditions)
    # the same simulation and the same draws: equal to round-off of the sum (values ~1e-7 m)
    np.testing.assert_allclose(data.value, exact + noise[:len(data)], rtol=0, atol=1e-18)
    # not the fit's own forward model: the refined integrator moves these steps by up to 0.12 nm (the
    # default scheme's error for this drive), well below the noise's σ (1 nm)
    own = fit.predict(truth, data, cache=False, executor="serial")
    assert np.max(np.abs(exact - own)) < 0.2 * figures.NOISE_NM * 1e-9 and np.any(exact != own)
    assert np.all(data.sd == figures.NOISE_NM * 1e-9) and data.known_sd
    text = facts.measurements_csv(data)
    path = tmp_path / "m.csv"
    path.write_text(text, encoding="utf-8")
    back = fit.read_measurements(path)
    np.testing.assert_allclose(back.value, data.value, rtol=1e-15)  # repr() round trip
    np.testing.assert_allclose(back.amplitude, data.amplitude, rtol=1e-15)
