"""Outputs the command names itself are created new, all together or not at all, after checks made
before any work.

Contract (README, "Reliability"): ``fit --out DIR`` (fit.json, fit.png, fitted-drive.toml) and
``sweep --out PREFIX`` (PREFIX.csv, .json, .png) never replace a file: one that is there before
the run is refused before any work, one that appears while the run writes (another run) is kept
and the run refuses with exit 2 naming it; a failed write leaves none of the run's files and names
the failing one; an output location that cannot be written is refused before any work (exit 2).
"""

from __future__ import annotations

import contextlib
import errno
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from cli_runs import run_main

GATES_PY = Path(__file__).with_name("gates.py")
#: A fit of μ of one rigid contact to two steps at 2 kHz (the steady protocol, 20 periods a point):
#: seconds, and cached after the first run.
FIT_DATA = "amplitude_nm,frequency_Hz,step_nm\n100,2000,30\n150,2000,60\n"
FIT = ["--free", "mu", "--contacts", "1", "--actuator", "rigid", "--executor", "serial"]
#: A sweep of two cheap points (one rigid contact).
SWEEP = ["sweep", "velocity", "--vary", "frequency=1kHz,2kHz", "--contacts", "1", "--actuator", "rigid",
         "--executor", "serial"]
HANG_S = 120


class _Reached(Exception):
    """The work began: the checks that must come before it did not refuse."""


def _reached(*args, **kwargs):
    raise _Reached()


@pytest.fixture(autouse=True)
def _no_progress(monkeypatch):
    monkeypatch.setenv("CI", "true")  # the fits' progress lines off: stderr holds the one line


def _one_line(err: str) -> None:
    assert err.count("\n") == 1 and err.startswith("passmd") and "Traceback" not in err, err


@pytest.fixture
def data(tmp_path) -> Path:
    path = tmp_path / "data.csv"
    path.write_text(FIT_DATA)
    return path


def _leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir()) if folder.exists() else []


# --------------------------------------------------------------------------------------
# fit --out DIR
# --------------------------------------------------------------------------------------

def _env() -> dict:
    env = {k: v for k, v in os.environ.items() if k != "PASSMD_SWEEP_LOG"}
    return {**env, "MPLBACKEND": "Agg", "CI": "true"}


def _default_signals():  # a test runner started as a background job ignores SIGINT
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def test_two_fits_to_one_new_out_leave_one_result_and_one_refusal(tmp_path, data):
    """Both fits stop once their files are written to temporary names, then race to link them: one
    reports them written (exit 0, three complete files), the other refuses (exit 2, one line naming
    the file) and leaves nothing of its own."""
    gates = tmp_path / "gates"
    gates.mkdir()
    argv = [sys.executable, str(GATES_PY), str(gates), "publish", "fit", str(data), *FIT, "--out", "res"]
    procs = [subprocess.Popen(argv, cwd=tmp_path, env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True, preexec_fn=_default_signals, start_new_session=True)
             for _ in range(2)]
    try:
        deadline = time.monotonic() + HANG_S
        while len(list(gates.glob("publish-*"))) < 2:
            assert time.monotonic() < deadline and all(p.poll() is None for p in procs), \
                [p.communicate() for p in procs if p.poll() is not None]
            time.sleep(0.05)
        (gates / "open").write_text("")
        done = [(p.wait(timeout=HANG_S), *p.communicate()) for p in procs]
    finally:
        for p in procs:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(p.pid, signal.SIGKILL)
    assert sorted(status for status, _, _ in done) == [0, 2], done
    (_, out, _), (_, _, err) = sorted(done, key=lambda d: d[0])
    assert "written" in out
    _one_line(err)
    assert "appeared while this run was writing" in err and "res/fit.json" in err, err
    assert _leftovers(tmp_path / "res") == ["fit.json", "fit.png", "fitted-drive.toml"]
    assert (tmp_path / "res" / "fit.json").read_text().rstrip().endswith("}")


def test_a_file_that_appears_while_a_fit_runs_is_kept(tmp_path, data, monkeypatch):
    out = tmp_path / "res"
    monkeypatch.setattr("passmd.runtime.outputs._before_linking",
                        lambda: (out / "fit.json").write_text("mine\n"))
    status, stdout, err = run_main(["fit", str(data), *FIT, "--out", str(out)])
    assert status == 2 and stdout == "", err
    _one_line(err)
    assert f"{out / 'fit.json'} appeared while this run was writing" in err
    assert _leftovers(out) == ["fit.json"] and (out / "fit.json").read_text() == "mine\n"


def test_a_failed_write_leaves_none_of_the_fits_outputs(tmp_path, data, monkeypatch):
    """fit.png cannot be written (a full disk): exit 1 naming fit.png, no fit.json left (so the rerun
    is not refused), the folder the fit created removed again."""
    from matplotlib.figure import Figure

    def full(self, *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    out = tmp_path / "res"
    with monkeypatch.context() as patch:
        patch.setattr(Figure, "savefig", full)
        status, stdout, err = run_main(["fit", str(data), *FIT, "--out", str(out)])
    assert status == 1 and stdout == "", err
    _one_line(err)
    assert f"cannot write {out / 'fit.png'}" in err and "No space left on device" in err, err
    assert not out.exists() and _leftovers(tmp_path) == ["data.csv"]
    status, stdout, err = run_main(["fit", str(data), *FIT, "--out", str(out)])
    assert status == 0, err
    assert _leftovers(out) == ["fit.json", "fit.png", "fitted-drive.toml"]


@pytest.mark.parametrize("case", ["dangling link", "file there", "unwritable folder", "missing parent"])
def test_fit_out_is_checked_before_any_work(tmp_path, data, monkeypatch, case):
    out = tmp_path / "res"
    if case == "dangling link":  # its target would be created, in a folder that is not there
        out.mkdir()
        (out / "fit.png").symlink_to(tmp_path / "nowhere" / "fit.png")
        expected = f"{out / 'fit.png'}: cannot create files in {tmp_path / 'nowhere'}"
    elif case == "file there":
        out.mkdir()
        (out / "fitted-drive.toml").write_text("mine\n")
        expected = f"{out / 'fitted-drive.toml'} is already there"
    elif case == "unwritable folder":
        out = Path("/sys/passmd-fit-out")  # not writable, even by root
        expected = "cannot create files in /sys"
    else:
        out = tmp_path / "missing" / "res"
        expected = "does not exist"
    monkeypatch.setattr("passmd.protocols.fit.read_measurements", _reached)
    status, stdout, err = run_main(["fit", str(data), *FIT, "--out", str(out)])
    assert status == 2 and stdout == "", err
    _one_line(err)
    assert expected in err and f"--out {out}" in err, err


def test_an_unwritable_sweep_log_is_refused_before_a_fit(tmp_path, data, monkeypatch):
    monkeypatch.setenv("PASSMD_SWEEP_LOG", "/dev/full")
    monkeypatch.setattr("passmd.protocols.fit.read_measurements", _reached)
    status, _, err = run_main(["fit", str(data), *FIT])
    assert status == 2, err
    _one_line(err)
    assert "PASSMD_SWEEP_LOG" in err and "/dev/full" in err, err


def test_an_unreadable_data_file_is_bad_input(tmp_path, data, monkeypatch):
    """Exit 2, as an unreadable drive file: the input is what is wrong, found before any work."""
    from passmd.runtime import inputs

    def unreadable(*args, **kwargs):
        raise PermissionError(errno.EACCES, "Permission denied", str(data))

    monkeypatch.setattr(inputs, "read_bounded", unreadable)
    monkeypatch.setattr("passmd.protocols.fit.measurements.read_bounded", unreadable)
    status, _, err = run_main(["fit", str(data), *FIT])
    assert status == 2, err
    _one_line(err)
    assert str(data) in err and "Permission denied" in err


# --------------------------------------------------------------------------------------
# sweep --out PREFIX, and the single-file outputs
# --------------------------------------------------------------------------------------

def test_a_failed_sweep_write_leaves_none_of_its_files(tmp_path, monkeypatch):
    """PREFIX.png fails after PREFIX.csv and PREFIX.json were written: neither is left."""
    from matplotlib.figure import Figure

    def full(self, *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(Figure, "savefig", full)
    prefix = tmp_path / "map"
    status, out, err = run_main([*SWEEP, "--out", str(prefix)])
    assert status == 1 and out == "", err
    _one_line(err)
    assert f"cannot write {prefix}.png" in err, err
    assert _leftovers(tmp_path) == []


@pytest.mark.parametrize("case", ["folder with a slash", "json there", "unwritable folder"])
def test_sweep_out_is_checked_before_any_work(tmp_path, monkeypatch, case):
    from passmd.protocols import maps

    prefix = str(tmp_path / "map")
    if case == "folder with a slash":
        prefix = str(tmp_path / "dir") + "/"
        (tmp_path / "dir").mkdir()
        expected = "names a directory, not a PREFIX"
    elif case == "json there":
        Path(prefix + ".json").write_text("{}\n")
        expected = f"{prefix}.json is already there"
    else:
        prefix = "/sys/passmd-map"
        expected = "cannot create files in /sys"
    monkeypatch.setattr(maps, "compute_map", _reached)
    status, out, err = run_main([*SWEEP, "--out", prefix])
    assert status == 2 and out == "", err
    _one_line(err)
    assert expected in err, err


@pytest.mark.parametrize("argv", [
    ["run", "--csv", "/sys/passmd.csv"],
    ["run", "--plot", "/sys/passmd.png"],
    ["ledger", "--profile", "quick", "--write-drive", "/nonexistent-folder/joint.toml"],
], ids=["run --csv", "run --plot", "ledger --write-drive"])
def test_single_file_outputs_are_checked_before_any_work(argv, monkeypatch):
    from passmd.cli.commands import run
    from passmd.report import evaluation

    monkeypatch.setattr(run, "simulate", _reached)
    monkeypatch.setattr(evaluation, "collect_results", _reached)
    status, out, err = run_main(argv)
    assert status == 2 and out == "", err
    _one_line(err)
    assert argv[-2] in err and argv[-1] in err, err


# --------------------------------------------------------------------------------------
# a file already there: refused before any work, replaced with --overwrite
# --------------------------------------------------------------------------------------

#: Cheap command lines writing each output option (one rigid contact, one period; the stall run
#: of ``force`` as short as its criterion allows).
RUN = ["run", "--contacts", "1", "--actuator", "rigid", "--periods", "1", "--max-points", "50"]
FORCE = ["force", "--contacts", "1", "--actuator", "rigid", "--periods", "17", "--max-periods", "17",
         "--max-points", "50"]
MINE = "mine, not the package's\n"


def _fake_figure(monkeypatch):
    """``figure fig99z``: a stand-in panel of two rows (the figure machinery, not its physics)."""
    import pandas as pd
    from matplotlib.figure import Figure

    from passmd.experiments import figure_table

    def plot(name, data):
        fig = Figure()
        fig.add_subplot().plot(data["x"], data["y"])
        return fig

    monkeypatch.setattr(figure_table, "figure_names", lambda: ["fig99z"])
    monkeypatch.setattr(figure_table, "figure_data", lambda name, config: pd.DataFrame({"x": [1.0, 2.0],
                                                                                          "y": [3.0, 4.0]}))
    monkeypatch.setattr(figure_table, "figure_plot", plot)


def _fake_ledger(monkeypatch):
    """The ledger on the closed forms alone (its sweeps are the ledger tests' business): every claim is
    still evaluated, and both files still written."""
    from passmd.report import evaluation

    monkeypatch.setattr(evaluation, "collect_results",
                        lambda config: {"closed_forms": evaluation.closed_form_results(config)})


def _work(monkeypatch, reach):
    """The work of every command replaced by ``reach``: reaching it means no check refused."""
    from passmd.cli.commands import run
    from passmd.experiments import figure_table
    from passmd.protocols import maps, stall
    from passmd.report import evaluation

    for owner, name in ((run, "simulate"), (stall, "generated_force"), (figure_table, "figure_data"),
                        (evaluation, "collect_results"), (maps, "compute_map")):
        monkeypatch.setattr(owner, name, reach)
    monkeypatch.setattr("passmd.protocols.fit.read_measurements", reach)


#: Each output option: (its command line, given the folder and the data file; the file already
#: there; the option as the refusal must name it; a stand-in for the work, or None).
CASES = {
    "run --csv": (lambda d, data: [*RUN, "--csv", str(d / "x.csv")], "x.csv", "--csv {d}/x.csv", None),
    "run --plot": (lambda d, data: [*RUN, "--plot", str(d / "x.png")], "x.png", "--plot {d}/x.png", None),
    "force --csv": (lambda d, data: [*FORCE, "--csv", str(d / "x.csv")], "x.csv", "--csv {d}/x.csv", None),
    "force --plot": (lambda d, data: [*FORCE, "--plot", str(d / "x.png")], "x.png", "--plot {d}/x.png", None),
    "figure --out": (lambda d, data: ["figure", "fig99z", "--profile", "quick", "--out", str(d)],
                     "fig99z.png", "--out {d}: {d}/fig99z.png", _fake_figure),
    "ledger --write-baseline": (lambda d, data: ["ledger", "--write-baseline", str(d / "b.csv")], "b.csv",
                                "--write-baseline {d}/b.csv", _fake_ledger),
    "ledger --write-drive": (lambda d, data: ["ledger", "--write-drive", str(d / "j.toml")], "j.toml",
                             "--write-drive {d}/j.toml", _fake_ledger),
    "ledger --write-evaluation": (lambda d, data: ["ledger", "--write-evaluation", str(d / "l.pmc")], "l.pmc",
                                  "--write-evaluation {d}/l.pmc", _fake_ledger),
    "sweep --out": (lambda d, data: [*SWEEP, "--out", str(d / "map")], "map.json",
                    "--out {d}/map: {d}/map.json", None),
    "fit --out": (lambda d, data: ["fit", str(data), *FIT, "--out", str(d)], "fitted-drive.toml",
                  "--out {d}: {d}/fitted-drive.toml", None),
}


@pytest.mark.parametrize("case", CASES)
def test_a_file_already_there_is_refused_before_any_work(tmp_path, data, monkeypatch, case):
    """Exit 2 before any work, one line naming the option as typed, the file and how to replace it;
    the file unchanged, nothing else written."""
    argv, name, named, fake = CASES[case]
    out = tmp_path / "out"
    out.mkdir()
    (out / name).write_text(MINE)
    if fake is not None:
        fake(monkeypatch)
    _work(monkeypatch, _reached)
    status, stdout, err = run_main(argv(out, data))
    assert status == 2 and stdout == "", err
    _one_line(err)
    assert f"{named.format(d=out)} is already there: pass --overwrite to replace it" in err, err
    assert (out / name).read_text() == MINE and _leftovers(out) == [name]


@pytest.mark.parametrize("case", CASES)
def test_overwrite_replaces_a_file_already_there(tmp_path, data, monkeypatch, case):
    argv, name, _, fake = CASES[case]
    out = tmp_path / "out"
    out.mkdir()
    (out / name).write_text(MINE)
    (out / name).chmod(0o640)
    if fake is not None:
        fake(monkeypatch)
    status, _, err = run_main([*argv(out, data), "--overwrite"])
    assert status == 0, err
    assert (out / name).read_bytes() not in (MINE.encode(), b"")
    assert (out / name).stat().st_mode & 0o777 == 0o640  # the file replaced keeps its permissions
    assert not [p for p in out.iterdir() if p.name.startswith(".")]  # no temporary left


def test_a_file_that_appears_while_a_run_works_is_kept_and_refused(tmp_path, monkeypatch):
    """Without --overwrite, --csv and --plot are created new at the end: a CSV that appeared meanwhile
    is kept, the run refuses (exit 2, naming it) and leaves neither of its files."""
    csv, png = tmp_path / "x.csv", tmp_path / "x.png"
    monkeypatch.setattr("passmd.runtime.outputs._before_linking", lambda: csv.write_text(MINE))
    status, stdout, err = run_main([*RUN, "--csv", str(csv), "--plot", str(png)])
    assert status == 2 and stdout == "", err
    _one_line(err)
    assert f"--csv {csv}: {csv} appeared while this run was writing" in err and "--overwrite" in err, err
    assert csv.read_text() == MINE and _leftovers(tmp_path) == ["x.csv"]


def test_with_overwrite_whatever_is_there_at_the_end_is_replaced(tmp_path, monkeypatch):
    """--overwrite replaces the file at the path when the run ends, also one that appeared meanwhile:
    no check made before the rename could be atomic with it."""
    csv = tmp_path / "x.csv"
    monkeypatch.setattr("passmd.runtime.outputs._before_linking", lambda: csv.write_text(MINE))
    status, _, err = run_main([*RUN, "--csv", str(csv), "--overwrite"])
    assert status == 0, err
    assert csv.read_text().startswith("time_s,") and _leftovers(tmp_path) == ["x.csv"]


def test_a_failed_overwrite_puts_back_the_files_it_replaced(tmp_path):
    """The second output cannot be written after the first replaced its file: the first file is put
    back as it was, and no temporary is left."""
    from passmd.runtime import outputs

    kept = tmp_path / "a.csv"
    kept.write_text(MINE)
    (tmp_path / "b.csv").mkdir()  # not a file: written into, last, and that fails
    with pytest.raises(outputs.OutputWriteError) as caught:
        outputs.write_files({kept: lambda tmp: Path(tmp).write_text("new\n"),
                             tmp_path / "b.csv": lambda tmp: Path(tmp).write_text("new\n")}, overwrite=True)
    assert caught.value.filename == str(tmp_path / "b.csv")
    assert kept.read_text() == MINE and _leftovers(tmp_path) == ["a.csv", "b.csv"]


def _evaluated():
    """A ledger of one claim, as :func:`passmd.report.evaluation.evaluate` returns it (the columns a
    baseline reads)."""
    import pandas as pd

    return pd.DataFrame({"claim": ["c0"], "status": ["reproduced"], "depends_on": [""],
                         "held_out_reading": ["—"], "joint_reading": ["—"]})


@pytest.mark.parametrize("function", ["write_baseline", "write_measurements", "write_reference_curves"])
def test_the_api_replaces_a_file_only_with_overwrite(tmp_path, function):
    """The functions that write files refuse one already there (``FileExistsError``, the file kept)
    unless ``overwrite=True``."""
    from passmd.ledger import baseline, reference
    from passmd.protocols import fit

    if function == "write_baseline":
        target = tmp_path / "baseline.csv"
        write = lambda **kw: baseline.write_baseline(_evaluated(), target, **kw)  # noqa: E731
    elif function == "write_measurements":
        target = tmp_path / "data.csv"
        data = fit.measurements_from_rows(["amplitude_nm", "frequency_Hz", "step_nm"],
                                          [["100", "2000", "30"]])
        write = lambda **kw: fit.write_measurements(target, data, **kw)  # noqa: E731
    else:
        target = tmp_path / next(iter(reference.CURVES.values())).filename
        write = lambda **kw: reference.write_reference_curves(tmp_path, **kw)  # noqa: E731
    target.write_text(MINE)
    with pytest.raises(FileExistsError, match="already there"):
        write()
    assert target.read_text() == MINE and _leftovers(tmp_path) == [target.name]
    write(overwrite=True)
    assert target.read_text() != MINE
