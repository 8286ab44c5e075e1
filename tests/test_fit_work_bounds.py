"""A fit's work is bounded and visible, and impossible data are refused before it starts.

Contract (README, "Reliability"): a fit says where it is at least every ten seconds (also within
one long sweep); identical conditions are simulated once; a measurement file holds at most
``MAX_ROWS`` rows; bounds beyond a parameter's plausible range need ``--allow-extrapolation``;
a step or velocity no drive can make is refused naming its row and column, before anything is
simulated (the simulator is replaced by a marker that fails the test if reached).
"""

from __future__ import annotations

import threading

import numpy as np
import pytest
from cli_runs import run_main

from passmd.model.parameters import Drive
from passmd.protocols import fit
from passmd.protocols.fit import estimator, prediction

RIGID = Drive(contacts=1, actuator_model="rigid")
HEADER = ["amplitude_nm", "frequency_Hz", "step_nm"]


class _Simulated(BaseException):
    """A simulation started: the refusal came too late."""


def _no_simulation(*args, **kwargs):
    raise _Simulated()


@pytest.fixture(autouse=True)
def _quiet(monkeypatch):
    monkeypatch.setenv("CI", "true")


def test_identical_conditions_are_simulated_once(monkeypatch):
    """Forty repeats of two conditions: two simulations per parameter set, each row its condition's."""
    calls = []

    def counted(drive, kind, amplitude, frequency, reading):
        calls.append((amplitude, frequency))
        return {"prediction": amplitude * 0.5, "settled": True}

    monkeypatch.setattr(prediction, "predict_point", counted)
    data = fit.measurements_from_rows(HEADER, [["100", "2000", "30"], ["150", "2000", "60"]] * 20)
    model = prediction._Model(RIGID, data, ["friction_coefficient"], "steady", executor="serial", cache=False,
                              config=None)
    (values,) = model.evaluate([np.log([0.2])])
    assert len(calls) == 2 and len(values) == 40
    expected = (data.amplitude * 0.5).tolist()  # each row its own condition's value
    assert values.tolist() == expected
    calls.clear()
    assert fit.predict(RIGID, data, executor="serial", cache=False).tolist() == expected
    assert len(calls) == 2


@pytest.mark.parametrize(("sets", "workers", "parts"), [
    (1, 2, 2), (2, 2, 1), (3, 2, 2), (5, 2, 2), (7, 2, 2), (8, 2, 1), (129, 2, 1),  # two cores
    (3, 8, 8), (4, 8, 2), (32, 8, 1),  # eight
    (1, 1, 1), (5, 1, 1),  # one worker: nothing to balance
])
def test_small_batches_are_split_to_fill_the_workers(sets, workers, parts):
    """A batch of a few parameter sets is split into row parts so that every worker has as many
    points (one set's part each) to run; a large batch, or one worker, keeps whole sets."""
    assert prediction.row_parts(sets, 15, workers) == parts
    if parts > 1:
        assert sets * parts % workers == 0 and parts <= 15
    assert prediction.row_parts(sets, 1, workers) == 1  # one row cannot be split


def test_split_rows_predict_what_whole_sets_do(monkeypatch):
    """The same parameter sets evaluated in row parts on a pool of two (threads here) and whole in
    this process: identical predictions, settled flags and simulation counts, each row its own."""
    import concurrent.futures as cf

    def stepped(drive, kind, amplitude, frequency, reading):
        return {"prediction": amplitude * drive.friction_coefficient, "settled": amplitude < 180e-9}

    monkeypatch.setattr(prediction, "predict_point", stepped)
    rows = [[str(a), "2000", "30"] for a in (100, 120, 140, 160, 180, 200, 220)]
    data = fit.measurements_from_rows(HEADER, rows)
    xs = [np.log([0.2]), np.log([0.3]), np.log([0.4])]  # three sets on two workers: split in two
    whole = prediction._Model(RIGID, data, ["friction_coefficient"], "steady", executor="serial", cache=False,
                              config=None)
    expected = whole.evaluate(xs)
    with cf.ThreadPoolExecutor(max_workers=2) as pool:
        split = prediction._Model(RIGID, data, ["friction_coefficient"], "steady", executor=pool, cache=False,
                                  config=None)
        assert prediction.row_parts(len(xs), len(split.rows), 2) == 2
        got = split.evaluate(xs)
    for a, b, mu in zip(got, expected, (0.2, 0.3, 0.4), strict=True):
        assert a.tolist() == b.tolist() == (data.amplitude * mu).tolist()
    for x in xs:
        key = x.tobytes()
        settled = (data.amplitude < 180e-9).tolist()
        assert split.settled[key].tolist() == whole.settled[key].tolist() == settled
    assert split.simulations == whole.simulations == 3 * len(rows) and split.evaluations == 3


def test_row_parts_from_the_cache_are_not_counted_as_simulations(tmp_path, monkeypatch):
    """A second model on the same cache reads every part: no simulation counted, same predictions."""
    import concurrent.futures as cf

    monkeypatch.setattr(prediction, "predict_point",
                        lambda drive, kind, amplitude, frequency, reading: {"prediction": amplitude,
                                                                            "settled": True})
    data = fit.measurements_from_rows(HEADER, [[str(a), "2000", "30"] for a in (100, 150, 200)])
    with cf.ThreadPoolExecutor(max_workers=2) as pool:
        first, again = (prediction._Model(RIGID, data, ["friction_coefficient"], "steady", executor=pool,
                                          cache=tmp_path, config=None) for _ in range(2))
        (a,) = first.evaluate([np.log([0.2])])
        (b,) = again.evaluate([np.log([0.2])])
    assert first.simulations == 3 and again.simulations == 0 and a.tolist() == b.tolist()


def test_a_file_beyond_the_row_limit_is_refused(tmp_path, monkeypatch):
    monkeypatch.setattr(prediction, "predict_point", _no_simulation)
    path = tmp_path / "many.csv"
    rows = "".join(f"{100 + i % 50},2000,{30 + i % 7}\n" for i in range(fit.MAX_ROWS + 1))
    path.write_text("amplitude_nm,frequency_Hz,step_nm\n" + rows)
    status, out, err = run_main(["fit", str(path), "--free", "mu"])
    assert status == 2 and out == "", err
    assert f"{fit.MAX_ROWS + 1} measurement rows is out of range: must be at most {fit.MAX_ROWS}" in err


@pytest.mark.parametrize(("bounds", "fragment"), [
    ("mu=1e-9..1e9", "must be within 0.01..1, the plausible range of mu"),
    ("actuator-stiffness=1N/m..1e6N/m", "the plausible range of actuator-stiffness"),
])
def test_bounds_far_outside_the_plausible_range_need_extrapolation(tmp_path, monkeypatch, bounds, fragment):
    monkeypatch.setattr(prediction, "predict_point", _no_simulation)
    data = tmp_path / "d.csv"
    data.write_text("amplitude_nm,frequency_Hz,step_nm\n100,2000,30\n150,2000,60\n")
    name = bounds.split("=")[0]
    status, out, err = run_main(["fit", str(data), "--free", name, "--bounds", bounds])
    assert status == 2 and out == "", err
    assert f"--bounds = {bounds!r} is out of range" in err and fragment in err
    assert "--allow-extrapolation" in err
    with pytest.raises(fit.InputError, match="plausible range"):  # the library says it too
        fit.fit(Drive(), fit.measurements_from_rows(HEADER, [["100", "2000", "30"], ["150", "2000", "60"]]),
                ["friction_coefficient"], bounds={"friction_coefficient": (1e-9, 1e9)}, executor="serial",
                cache=False)


@pytest.mark.parametrize(("column", "value", "fragment"), [
    ("velocity_mm_per_s", "800", "row 2 (line 3), column velocity_mm_per_s = 800 is out of range"),
    ("step_nm", "5000", "row 2 (line 3), column step_nm = 5000 is out of range"),
    ("step_nm", "-5000", "row 2 (line 3), column step_nm = -5000 is out of range"),
])
def test_an_impossible_measurement_is_refused_before_simulating(tmp_path, monkeypatch, column, value,
                                                                fragment):
    """A velocity 4000 × A·f or a step fifty times the amplitude: no stick–slip drive moves so far."""
    monkeypatch.setattr(prediction, "predict_point", _no_simulation)
    path = tmp_path / "d.csv"
    first = "0.1" if column.startswith("velocity") else "30"
    path.write_text(f"amplitude_nm,frequency_Hz,{column}\n100,2000,{first}\n100,2000,{value}\n")
    status, out, err = run_main(["fit", str(path), "--free", "mu", "--contacts", "1", "--actuator", "rigid"])
    assert status == 2 and out == "", err
    assert fragment in err and "no stick–slip drive moves that far" in err, err


def test_a_real_step_is_not_refused():
    """The bound is generous: the model's own steady step of the paper's drive passes it."""
    from passmd.protocols.fit.checks import check_rows

    data = fit.measurements_from_rows(["amplitude_nm", "frequency_Hz", "velocity_mm_per_s"],
                                      [["202", "100000", "30"], ["202", "100", "0.02"]])
    check_rows(Drive(), data, {"friction_coefficient": (0.01, 1.0)})


def test_a_fit_reports_progress_while_one_sweep_runs_long(monkeypatch):
    """The first sweep waits until a heartbeat line arrived (the interval shortened to 0.05 s): a
    stage that outlasts the interval is reported while it runs, not after."""
    monkeypatch.setattr(estimator, "PROGRESS_INTERVAL", 0.05)
    lines, heard = [], threading.Event()

    def progress(line):
        lines.append(line)
        if line.startswith("still: "):
            heard.set()

    evaluate = prediction._Model.evaluate

    def slow_first(self, xs):
        if not self.evaluations:
            assert heard.wait(60), f"no progress line while the first sweep ran: {lines}"
        return evaluate(self, xs)

    monkeypatch.setattr(prediction._Model, "evaluate", slow_first)
    monkeypatch.setattr(prediction, "predict_point",
                        lambda drive, kind, a, f, r: {"prediction": drive.friction_coefficient * a,
                                                      "settled": True})
    rows = [["100", "2000", "20"], ["150", "2000", "30"], ["120", "2000", "24"]]
    data = fit.measurements_from_rows(HEADER, rows)
    fit.fit(RIGID, data, ["friction_coefficient"], executor="serial", cache=False, progress=progress)
    assert any(line.startswith("still: the start values") for line in lines), lines
