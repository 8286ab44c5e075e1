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
    if case == "dangling link":
        out.mkdir()
        (out / "fit.png").symlink_to(tmp_path / "nowhere" / "fit.png")
        expected = f"{out / 'fit.png'} is already there"
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
