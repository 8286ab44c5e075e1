"""Outputs that never destroy, and long work that is visible and stoppable.

Contract (README, "Reliability"):

* an output file is put in place atomically only when it is a regular file (replaced only with
  ``--overwrite``) or missing; a link stays a link (its target is written), a device, a pipe or
  ``/dev/stdout`` is written to, never replaced; a writer's temporary files never outlive it;
* outputs that would destroy each other, an input or the command's own standard output, and
  empty path options, are refused before anything runs, with one line naming the options;
* a command started with standard output closed ends quietly with the closed-pipe status 141;
* a long run or sweep shows its progress on stderr, also when stderr is not a terminal (a
  line every few seconds; nothing for work shorter than two seconds; never on stdout), and
  the run's work counts a discrete contact's springs;
* SIGTERM is handled as Ctrl-C: one line "interrupted", exit status 143, no output or
  temporary file left, a sweep's worker processes stopped.

Command lines run in real subprocesses (``python -m passmd``). The signal tests wait for a
marker (a progress line on stderr, files the sweep's workers create, a gate of
``tests/gates.py`` the command waits at) before signalling, with generous time limits that
only detect a hang.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import select
import signal
import stat
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from passmd.cli import main
from passmd.ledger.claims import CLAIMS_PATH
from passmd.model import waveforms
from passmd.model.parameters import Drive
from passmd.runtime import pools, progress, sweep
from passmd.runtime.outputs import write_file
from passmd.solver import simulation

#: Generous limits: a refusal or a one-period run takes seconds (start-up included).
QUICK_S = 120
#: How long a signalled command may take to end, and a marker to appear (hang detectors).
HANG_S = 120

QUICK_RUN = ["run", "--periods", "1", "--contacts", "1", "--max-points", "50"]


def _env(tmp_path, **extra) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith("PASSMD_") and k != "CI"}
    return {**env, "MPLBACKEND": "Agg", "PASSMD_CACHE_DIR": str(tmp_path / "cache"), **extra}


def passmd(argv, tmp_path, *, env=None, **kwargs) -> subprocess.CompletedProcess:
    """``python -m passmd argv`` in ``tmp_path`` (stdout and stderr captured unless given)."""
    kwargs.setdefault("stdout", subprocess.PIPE)
    kwargs.setdefault("stderr", subprocess.PIPE)
    return subprocess.run([sys.executable, "-m", "passmd", *argv], cwd=tmp_path, text=True,
                          env=env or _env(tmp_path), timeout=QUICK_S, **kwargs)


def assert_refused(done, *names, status=2):
    """Exit ``status``, nothing on stdout, one line on stderr naming every one of ``names``."""
    assert done.returncode == status, done.stderr
    assert done.stdout == ""
    assert done.stderr.count("\n") == 1 and done.stderr.startswith("passmd"), done.stderr
    assert "Traceback" not in done.stderr
    for name in names:
        assert name in done.stderr, (name, done.stderr)


def _json_flag(json_output: bool) -> list[str]:
    return ["--json"] if json_output else []


# --------------------------------------------------------------------------------------
# links, devices and pipes stay what they are
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("json_output", [False, True])
def test_stdout_link_stays_a_link_and_receives_the_csv(tmp_path, json_output):
    """``--csv`` through a link to /proc/self/fd/1 (what /dev/stdout is) into a pipe: the CSV and
    then the result arrive on the pipe in order, and the link is still a link."""
    link = tmp_path / "stdout"
    link.symlink_to("/proc/self/fd/1")
    done = passmd([*QUICK_RUN, "--csv", str(link), *_json_flag(json_output)], tmp_path)
    assert done.returncode == 0, done.stderr
    assert link.is_symlink() and os.readlink(link) == "/proc/self/fd/1"
    lines = done.stdout.splitlines()
    assert lines[0].startswith("time_s,piezo_position_m,runner_position_m")
    summary = done.stdout[done.stdout.index("{" if json_output else "passmd run"):]
    if json_output:
        assert json.loads(summary)["command"] == "run"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["stdout"]  # no temporary left


@pytest.mark.parametrize("json_output", [False, True])
def test_dev_stdout_into_a_pipe_is_written_not_replaced(tmp_path, json_output):
    """The example of the reliability contract: ``--csv /dev/stdout`` (run as root, the old writer
    replaced the /dev/stdout link with a regular file)."""
    before = os.lstat("/dev/stdout")
    done = passmd([*QUICK_RUN, "--csv", "/dev/stdout", *_json_flag(json_output)], tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("time_s,")
    after = os.lstat("/dev/stdout")
    assert stat.S_ISLNK(after.st_mode) and (after.st_ino, after.st_dev) == (before.st_ino, before.st_dev)


@pytest.mark.parametrize("json_output", [False, True])
def test_dev_stdout_redirected_to_a_file_is_refused(tmp_path, json_output):
    """``--csv /dev/stdout > out.txt``: the CSV and the results would overwrite each other in
    out.txt; refused before the run, and the link stays a link."""
    out = tmp_path / "out.txt"
    link = tmp_path / "stdout"
    link.symlink_to("/proc/self/fd/1")
    for target in (str(link), "/dev/stdout", str(out)):
        with open(out, "w") as sink:
            done = passmd([*QUICK_RUN, "--csv", target, *_json_flag(json_output)], tmp_path, stdout=sink)
        done.stdout = out.read_text()
        assert_refused(done, f"--csv {target}", "standard output")
    assert link.is_symlink() and Path("/dev/stdout").is_symlink()


@pytest.mark.parametrize("json_output", [False, True])
def test_link_to_a_regular_file_stays_a_link(tmp_path, json_output):
    """The link's target gets the new CSV, atomically; the link itself is kept."""
    data = tmp_path / "data"
    data.mkdir()
    real = data / "series.csv"
    real.write_text("old\n")
    link = tmp_path / "series.csv"
    link.symlink_to(real)
    done = passmd([*QUICK_RUN, "--csv", "series.csv", *_json_flag(json_output)], tmp_path)
    # a regular file, through the link: refused, then replaced with --overwrite
    assert_refused(done, "--csv series.csv is already there", "--overwrite")
    assert real.read_text() == "old\n"
    done = passmd([*QUICK_RUN, "--csv", "series.csv", "--overwrite", *_json_flag(json_output)], tmp_path)
    assert done.returncode == 0, done.stderr
    assert link.is_symlink() and link.resolve() == real
    assert real.read_text().startswith("time_s,")
    assert sorted(p.name for p in data.iterdir()) == ["series.csv"]


def test_descriptor_link_to_a_regular_file_is_appended_to_not_replaced(tmp_path):
    """The mechanism behind ``--csv /dev/stdout > out.txt``: a link to /proc/self/fd/N whose
    descriptor is a regular file. The old writer renamed a temporary over the link; the file the
    descriptor is open on must instead receive the output after what it already holds."""
    log = tmp_path / "out.txt"
    with open(log, "w") as held:
        held.write("printed before\n")
        held.flush()
        link = tmp_path / "fd-link"
        link.symlink_to(f"/proc/self/fd/{held.fileno()}")
        write_file(link, lambda tmp: Path(tmp).write_text("time_s\n0.0\n"))
        assert link.is_symlink() and os.readlink(link) == f"/proc/self/fd/{held.fileno()}"
    assert log.read_text() == "printed before\ntime_s\n0.0\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fd-link", "out.txt"]


def test_dangling_link_gets_its_target_created(tmp_path):
    link = tmp_path / "series.csv"
    link.symlink_to("target.csv")
    write_file(link, lambda tmp: Path(tmp).write_text("a\n"))
    assert link.is_symlink() and (tmp_path / "target.csv").read_text() == "a\n"


def test_fifo_is_written_to_not_replaced(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    reader = subprocess.Popen(["cat", str(fifo)], stdout=subprocess.PIPE)
    try:
        write_file(fifo, lambda tmp: Path(tmp).write_text("time_s\n0.0\n"))
        assert reader.communicate(timeout=HANG_S)[0] == b"time_s\n0.0\n"
    finally:
        reader.kill()
        reader.wait()
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pipe"]


def test_device_stays_a_device(tmp_path):
    write_file("/dev/null", lambda tmp: Path(tmp).write_text("x\n"))
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)
    link = tmp_path / "null"
    link.symlink_to("/dev/null")
    write_file(link, lambda tmp: Path(tmp).write_text("x\n"))
    assert link.is_symlink() and stat.S_ISCHR(os.stat(link).st_mode)


def test_replaced_file_keeps_its_permissions(tmp_path):
    target = tmp_path / "series.csv"
    target.write_text("old\n")
    target.chmod(0o600)
    write_file(target, lambda tmp: Path(tmp).write_text("new\n"), overwrite=True)
    assert target.read_text() == "new\n" and stat.S_IMODE(target.stat().st_mode) == 0o600


def test_a_writers_own_temporary_files_are_removed_when_it_is_interrupted(tmp_path):
    """A writer that makes its own temporary beside the file it was given and is interrupted leaves
    nothing behind."""
    (tmp_path / "kept.txt").write_text("mine\n")

    def interrupted(tmp):
        Path(tmp).with_name(f".{Path(tmp).name}.tmp").write_text("half")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        write_file(tmp_path / "baseline.csv", interrupted)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["kept.txt"]


# --------------------------------------------------------------------------------------
# refused before anything runs
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize(("csv", "plot", "json_output"), [
    ("out/x.png", "out/x.png", False), ("out/x.png", "out/x.png", True), ("out/x.png", "./out/x.png", False),
    ("out/../out/x.png", "out/x.png", False), ("out/x.png", "link.png", True)])
def test_two_outputs_naming_the_same_file_are_refused(tmp_path, csv, plot, json_output):
    """Through any spelling or link; the refusal is the same with --json (one line on stderr)."""
    (tmp_path / "out").mkdir()
    (tmp_path / "link.png").symlink_to("out/x.png")
    done = passmd(["run", "--periods", "1", "--csv", csv, "--plot", plot, *_json_flag(json_output)], tmp_path)
    assert_refused(done, f"--csv {csv}", f"--plot {plot}", "the same file")
    assert list((tmp_path / "out").iterdir()) == []  # nothing ran, nothing was written


def test_baseline_naming_the_claims_table_is_refused(tmp_path):
    """``ledger --write-baseline`` onto the claims table the ledger reads (by its path, or through
    a link): refused before the ledger is computed; the table is untouched."""
    before = CLAIMS_PATH.read_bytes()
    (tmp_path / "claims-link.csv").symlink_to(CLAIMS_PATH)
    for name in (str(CLAIMS_PATH), "claims-link.csv"):
        done = passmd(["ledger", "--write-baseline", name], tmp_path)
        assert_refused(done, f"--write-baseline {name}", "the claims table")
    assert CLAIMS_PATH.read_bytes() == before
    assert not (tmp_path / "cache").exists()  # nothing was computed


def test_figure_output_naming_the_sweep_log_is_refused(tmp_path):
    done = passmd(["figure", "fig5a", "--out", "."], tmp_path,
                  env=_env(tmp_path, PASSMD_SWEEP_LOG="fig5a.csv"))
    assert_refused(done, "--out .", "PASSMD_SWEEP_LOG fig5a.csv", "the same file")
    assert not (tmp_path / "cache").exists()


#: Every path option of every command, with an empty value (the refusal is the same line with
#: and without --json: half the cases carry it).
EMPTY_PATHS = {
    "run --csv": ["run", "--csv", "", "--json"],
    "run --plot": ["run", "--plot", ""],
    "force --csv": ["force", "--csv", ""],
    "figure --out": ["figure", "fig5a", "--out", "", "--json"],
    "figure --cache-dir": ["figure", "fig5a", "--cache-dir", ""],
    "ledger --cache-dir": ["ledger", "--cache-dir", "", "--json"],
    "ledger --write-baseline": ["ledger", "--write-baseline", ""],
    "cache clear --cache-dir": ["cache", "clear", "--cache-dir", "", "--json"],
}


@pytest.mark.parametrize("case", sorted(EMPTY_PATHS))
def test_empty_path_is_refused_before_anything_runs(tmp_path, case):
    """Refused while the command line is parsed: nothing computed (no cache, no sweep log), and
    ``cache clear --cache-dir ''`` does not fall back to clearing the default cache."""
    argv = EMPTY_PATHS[case]
    default_cache = tmp_path / "xdg" / "passmd" / "results"  # the user cache folder (platformdirs, Linux)
    default_cache.mkdir(parents=True)
    (default_cache / "keep.txt").write_text("mine\n")
    env = {k: v for k, v in _env(tmp_path, PASSMD_SWEEP_LOG=str(tmp_path / "log"),
                                 XDG_CACHE_HOME=str(tmp_path / "xdg")).items() if k != "PASSMD_CACHE_DIR"}
    done = passmd(argv, tmp_path, env=env)
    flag = argv[argv.index("") - 1]
    assert_refused(done, f"{flag} = '' is not a")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["xdg"]
    assert [p.name for p in default_cache.iterdir()] == ["keep.txt"]


# --------------------------------------------------------------------------------------
# closed standard streams
# --------------------------------------------------------------------------------------


def _close_stdout():  # runs in the child before exec
    os.close(1)


@pytest.mark.parametrize("argv", [["theory"], ["theory", "--json"], ["--help"], ["theory", "--help"]])
def test_closed_stdout_exits_quietly_like_a_closed_pipe(tmp_path, argv):
    """``passmd theory >&-``: exit 141 (as when a pipe's reader went away) and nothing on stderr."""
    done = passmd(argv, tmp_path, stdout=None, preexec_fn=_close_stdout)
    assert (done.returncode, done.stderr) == (141, "")


def test_closed_stdout_still_writes_the_csv(tmp_path):
    """The output file is complete; only the printed result had nowhere to go."""
    done = passmd([*QUICK_RUN, "--csv", "series.csv"], tmp_path, stdout=None, preexec_fn=_close_stdout)
    assert (done.returncode, done.stderr) == (141, "")
    assert (tmp_path / "series.csv").read_text().startswith("time_s,")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["series.csv"]


def test_closed_stderr_still_gives_the_status(tmp_path):
    done = passmd(["run", "--periods", "0"], tmp_path, stderr=None, preexec_fn=lambda: os.close(2))
    assert (done.returncode, done.stdout) == (2, "")


# --------------------------------------------------------------------------------------
# progress of long work
# --------------------------------------------------------------------------------------


def _read_until(proc, marker: bytes, timeout: float) -> bytes:
    """What ``proc`` wrote on stderr (a binary pipe) up to a complete line holding ``marker``."""
    fd, seen = proc.stderr.fileno(), b""
    deadline = time.monotonic() + timeout
    while not any(marker in line for line in seen.split(b"\n")[:-1]):
        left = deadline - time.monotonic()
        assert left > 0, f"no {marker!r} on stderr within {timeout} s: {seen!r}"
        if select.select([fd], [], [], left)[0]:
            chunk = os.read(fd, 65536)
            assert chunk, f"stderr closed before {marker!r} appeared: {seen!r}"
            seen += chunk
    return seen


def _default_signals():
    """Runs in the child before exec: SIGINT and SIGTERM at their default action, whatever the test
    runner inherited (a background job of a non-interactive shell starts with SIGINT ignored,
    and an ignored signal stays ignored across exec)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


@contextlib.contextmanager
def _started(argv, tmp_path, env=None):
    """``python argv`` running in ``tmp_path`` (binary pipes) in a process group of its own, which
    is killed at the end: worker processes a failed check left behind would hold the pipes open."""
    proc = subprocess.Popen([sys.executable, *argv], cwd=tmp_path, env=env or _env(tmp_path),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, preexec_fn=_default_signals,
                            start_new_session=True)
    try:
        yield proc
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()


def _terminate(proc, before: bytes, to_group: bool = False) -> tuple[int, str, str]:
    """SIGTERM to ``proc`` (or its process group); (status, stdout, all of stderr)."""
    if to_group:
        os.killpg(proc.pid, signal.SIGTERM)
    else:
        proc.send_signal(signal.SIGTERM)
    out, rest = proc.communicate(timeout=HANG_S)
    return proc.returncode, out.decode(), (before + rest).decode()


#: A progress line off a terminal (passmd.runtime.progress), e.g. "simulation: 4.2% (4.20/100 periods) ...".
PROGRESS_LINE = re.compile(r"^\w+: \d+\.\d% \([\d.]+/\d+ (periods|points)\) after [\d:]+, "
                           r"(about [\d:]+ left|time left known after 3 (periods|points))$")


def _check_interrupted(status, out, err, prog="passmd run", kept=""):
    """Exit 143, nothing on stdout; on stderr progress lines and one line "interrupted"."""
    assert status == 143, err
    assert out == ""
    lines = err.splitlines()
    assert [line for line in lines if not PROGRESS_LINE.match(line)] == [f"{prog}: interrupted{kept}"], err


def test_long_run_shows_progress_lines_off_a_terminal_and_sigterm_stops_it(tmp_path):
    """``run --periods 100000`` with stderr a pipe: a progress line after a few seconds (on
    stderr only); SIGTERM then ends it with one line, exit 143 and no CSV or temporary file."""
    with _started(["-m", "passmd", "run", "--periods", "100000", "--csv", "series.csv"], tmp_path) as proc:
        seen = _read_until(proc, b"simulation: ", HANG_S)
        status, out, err = _terminate(proc, seen)
    _check_interrupted(status, out, err)
    first = err.splitlines()[0]
    assert first.startswith("simulation: ") and PROGRESS_LINE.match(first) and "\r" not in err, first
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_many_springs_count_in_the_work_estimate(tmp_path):
    """``run --contacts 1 --springs N``: a few thousand steps of N springs each is long work, so it
    shows progress; the kernel returns often enough for SIGTERM to stop it at once."""
    argv = ["-m", "passmd", "run", "--contacts", "1", "--springs", "3000000", "--periods", "1", "--json"]
    with _started(argv, tmp_path) as proc:
        seen = _read_until(proc, b"simulation: ", HANG_S)
        status, out, err = _terminate(proc, seen)
    _check_interrupted(status, out, err)


def test_work_estimate_counts_the_springs(monkeypatch):
    """The same drive and waveform: 10 000 discrete springs are 1 + 10 000/SPRINGS_PER_STEP times
    the work per step of the exact contact."""
    seen = {}
    original = simulation._integrate_in_chunks

    def record(arguments, periods, period, expected, step_work, progress):
        seen["work"] = step_work
        return original(arguments, periods, period, expected, step_work, progress)

    monkeypatch.setattr(simulation, "_integrate_in_chunks", record)
    drive = Drive(contacts=1)
    wave = waveforms.sawtooth(drive.actuator.full_stroke_amplitude, 10e3, drive, periods=1)
    simulation.simulate(drive, wave, max_points=10)
    assert seen["work"] == 1.0
    simulation.simulate(drive, wave, contact_model="discrete", springs=10_000, max_points=10)
    assert seen["work"] == 1.0 + 10_000 / simulation.SPRINGS_PER_STEP


@pytest.mark.parametrize("json_output", [False, True])
def test_short_run_shows_no_progress(tmp_path, json_output):
    done = passmd([*QUICK_RUN, *_json_flag(json_output)], tmp_path)
    assert done.returncode == 0 and done.stderr == ""
    assert "simulation:" not in done.stdout


def test_library_runs_stay_quiet_off_a_terminal(monkeypatch, capsys):
    """Without ``progress="long"`` (the command line's choice) a long run prints nothing off a
    terminal: the book's notebooks treat any stderr output as a warning."""
    monkeypatch.setattr(simulation, "PROGRESS_MIN_WORK", 0.0)
    monkeypatch.setattr(progress, "DELAY", 0.0)
    monkeypatch.setattr(progress, "LINE_INTERVAL", 0.0)
    monkeypatch.setattr(simulation, "CHUNK_STEPS", 200)
    drive = Drive(contacts=1)
    wave = waveforms.sawtooth(drive.actuator.full_stroke_amplitude, 10e3, drive, periods=2)
    simulation.simulate(drive, wave, max_points=10)
    assert capsys.readouterr().err == ""
    simulation.simulate(drive, wave, max_points=10, progress="long")
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert lines and all(line.startswith("simulation: ") and "periods)" in line for line in lines), lines
    assert "\r" not in captured.err and captured.out == ""


def test_a_terminal_gets_a_bar_redrawn_in_place():
    class Terminal:
        text = ""

        def isatty(self):
            return True

        def write(self, text):
            self.text += text

        def flush(self):
            pass

    terminal = Terminal()
    bar = progress.bar(4, unit="point", desc="sweep", delay=0.0, stream=terminal)
    bar.update(2)
    bar.refresh()
    bar.close()
    assert "\r" in terminal.text and "\n" not in terminal.text and "2/4 points" in terminal.text


def slow_point(x):
    time.sleep(0.05)
    return {"y": 2 * x}


def test_sweep_progress_lines_off_a_terminal(monkeypatch, capsys):
    monkeypatch.setattr(progress, "DELAY", 0.0)
    monkeypatch.setattr(progress, "LINE_INTERVAL", 0.0)
    points = sweep.grid(x=[1, 2, 3, 4])
    sweep.run(slow_point, points, executor="serial", cache=False)  # default: on a terminal only
    assert capsys.readouterr().err == ""
    sweep.run(slow_point, points, executor="serial", cache=False, progress=True)
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert "slow_point: 50.0% (2/4 points)" in captured.err and "\r" not in captured.err
    assert all(PROGRESS_LINE.match(line) and line.startswith("slow_point: ") for line in lines), lines
    # the time left once three points are done (the first ones carry the start-up)
    assert lines[0].endswith("time left known after 3 points") and lines[-1].endswith(" left")
    assert not any("about" in line for line in lines if "(2/4 points)" in line or "(1/4 points)" in line)
    assert "about" in lines[-1] and captured.out == ""


def test_figure_and_ledger_ask_for_sweep_progress_unless_in_ci(monkeypatch):
    from passmd.cli.configuration import run_config
    from passmd.cli.parser import make_parser

    monkeypatch.delenv("CI", raising=False)
    assert run_config(make_parser().parse_args(["figure", "fig5a"])).progress is True
    monkeypatch.setenv("CI", "true")
    assert run_config(make_parser().parse_args(["ledger"])).progress is False


# --------------------------------------------------------------------------------------
# SIGTERM
# --------------------------------------------------------------------------------------

# started in a subprocess: ``passmd figure`` over a stand-in panel whose sweep runs in a process
# pool; each point announces itself with a file and sleeps
_SWEEP_RUNNER = textwrap.dedent("""
    import sys, types
    sys.path.insert(0, sys.argv[1])
    import slow_points
    from passmd.experiments import figure_table
    from passmd.runtime import sweep
    from passmd.cli import main

    def figure_data(name, config):  # three workers: one is idle once the fast points are done
        return sweep.run(slow_points.point, sweep.grid(x=[1, 2, 3, 4]), executor="process", workers=3,
                         config=config)

    figure_table.figure_names = lambda: ["fig99z"]
    figure_table.figure_spec = lambda name: types.SimpleNamespace(name=name, title="stand-in")
    figure_table.figure_data = figure_data
    sys.exit(main(sys.argv[2:]))
""")

_SLOW_POINTS = textwrap.dedent("""
    import os, time
    from pathlib import Path

    def point(x):
        if x > 2:  # points 1 and 2 finish at once, 3 and 4 announce themselves and sleep
            Path(MARKERS, f"{x}-{os.getpid()}").write_text("")
            time.sleep(600)
        return {"y": x}
""")


@pytest.mark.parametrize("to_group", [False, True], ids=["to the command", "to its process group"])
def test_sigterm_stops_a_process_pool_sweep_and_its_workers(tmp_path, to_group):
    """SIGTERM while two workers are inside a point and one is idle, sent to the command (``kill
    PID``) or to its whole process group (as a service manager or a closed terminal does): one
    line, exit 143, the workers gone without a word, the two finished points in the cache and no
    temporary file in it, no figure written."""
    from passmd.runtime.cache import Cache

    code = tmp_path / "code"
    code.mkdir()
    markers, out, cache = tmp_path / "markers", tmp_path / "out", tmp_path / "cache"
    markers.mkdir()
    # the markers' folder written into the code: a point reading the environment is not cached
    (code / "slow_points.py").write_text(f"MARKERS = {str(markers)!r}\n" + _SLOW_POINTS)
    argv = ["-c", _SWEEP_RUNNER, str(code), "figure", "fig99z", "--out", str(out)]
    with _started(argv, tmp_path, env=_env(tmp_path)) as proc:
        deadline = time.monotonic() + HANG_S
        # both workers inside a slow point, the fast ones cached
        while len(list(markers.iterdir())) < 2 or len(Cache(cache).entries()) < 2:
            assert time.monotonic() < deadline and proc.poll() is None, "the sweep did not get going"
            time.sleep(0.1)
        status, stdout, err = _terminate(proc, b"", to_group=to_group)
        _check_interrupted(status, stdout, err, prog="passmd figure",
                           kept=" (finished points are kept in the cache)")
        deadline = time.monotonic() + HANG_S
        while any(_alive(pid) for pid in _workers(markers)):
            assert time.monotonic() < deadline, f"worker processes {_workers(markers)} still run"
            time.sleep(0.1)
    assert not out.exists()
    assert len(Cache(cache).entries()) == 2
    assert [p for p in cache.rglob("*") if p.is_file() and p.suffix in (".tmp", ".part")] == []


def test_pool_workers_end_on_sigterm_whatever_the_parent_handles(monkeypatch):
    """A worker forked while the command handles SIGTERM must not inherit the handler: it ends
    at once on SIGTERM (and leaves Ctrl-C to its parent)."""
    previous = {sig: signal.getsignal(sig) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        signal.signal(signal.SIGTERM, lambda signum, frame: None)
        pools.worker_signals()  # the pool's worker initializer
        assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def _workers(markers: Path) -> set[int]:
    """The worker processes that started a point (their marker files name them)."""
    return {int(p.name.split("-")[1]) for p in markers.iterdir()}


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    try:  # a zombie (ended, not yet reaped) is gone
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().split(")")[-1].split()[0] != "Z"
    except OSError:
        return False


def test_sigterm_handler_is_removed_after_the_command(monkeypatch):
    """``main`` called from Python handles SIGTERM only while the command runs."""
    previous = signal.signal(signal.SIGTERM, signal.SIG_DFL)
    seen = []
    monkeypatch.setattr("passmd.cli.commands.theory.run_theory",
                        lambda args, out: seen.append(signal.getsignal(signal.SIGTERM)) or 0)
    try:
        with open(os.devnull, "w") as sink:
            assert main(["theory"], out=sink) == 0
        assert seen and seen[0] is not signal.SIG_DFL
        assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL
    finally:
        signal.signal(signal.SIGTERM, previous)


def test_critical_amplitude_search_shows_progress_off_a_terminal(monkeypatch, capsys):
    """The A_c bisection counts its runs on stderr with ``progress="long"`` (the command line's
    choice), and stays quiet off a terminal without it (the book's notebooks)."""
    from passmd.protocols import critical_amplitude

    monkeypatch.setattr(progress, "DELAY", 0.0)
    monkeypatch.setattr(progress, "LINE_INTERVAL", 0.0)
    drive = Drive(contacts=1, actuator_model="rigid")
    critical_amplitude.critical_amplitude(drive, protocol="first", tolerance=20e-9)
    assert capsys.readouterr().err == ""
    found = critical_amplitude.critical_amplitude(drive, protocol="first", tolerance=20e-9, progress="long")
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert lines and all(line.startswith("critical amplitude: ") for line in lines), lines
    assert f"({found['runs']}/" in captured.err and "\r" not in captured.err and captured.out == ""


# --------------------------------------------------------------------------------------
# A signal at any moment of a process pool's life: starting, running, shutting down
# --------------------------------------------------------------------------------------

GATES_PY = Path(__file__).with_name("gates.py")
#: A cheap map in a pool of two workers (one rigid contact: a point takes a fraction of a second).
POOL_SWEEP = ["sweep", "velocity", "--vary", "frequency=100Hz..400Hz:4", "--contacts", "1", "--actuator",
              "rigid", "--workers", "2"]
#: A fit of one parameter to three steps, on the same drive, in a pool of two workers.
POOL_FIT = ["fit", "data.csv", "--free", "mu", "--contacts", "1", "--actuator", "rigid",
            "--executor", "process", "--workers", "2"]
FIT_DATA = "amplitude_nm,frequency_Hz,step_nm\n100,1000,64.25\n150,1000,116.9\n200,1000,169.6\n"
#: moment: (the gates the command stops at, the markers to see before the signal: tests/gates.py)
MOMENTS = {
    "pool starting": ("spawn,worker", ("spawn", "worker")),  # one worker forked, not yet initialized
    "points running": ("point", ("point", "point")),  # both workers inside a point
    "pool shutting down": ("shutdown", ("shutdown",)),  # every point done, the pool stopping
}
#: a fit's first sweep is its start values, one parameter set whose rows are split between the two
#: workers (passmd.protocols.fit.prediction.row_parts): both inside a point, as in a sweep
FIT_MOMENTS = {**MOMENTS, "between two sweeps": ("evaluate", ("evaluate",))}  # the pool idle


def _descendants(pid: int) -> set[int]:
    """The processes ``pid`` started, and theirs (from /proc)."""
    parents = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            with contextlib.suppress(OSError, IndexError, ValueError):
                parents[int(entry.name)] = int((entry / "stat").read_text().rsplit(")", 1)[1].split()[1])
    found, todo = set(), [pid]
    while todo:
        pid = todo.pop()
        children = {child for child, parent in parents.items() if parent == pid}
        todo += list(children - found)
        found |= children
    return found


def _signal_at(tmp_path, argv, prog, moment, sig, moments=MOMENTS):
    """Run ``argv`` stopped at ``moment``, send ``sig`` to its process group (as a terminal's Ctrl-C or
    a service manager does), open the gates; (status, stdout, stderr), every process of it gone."""
    gates, wanted = moments[moment]
    directory = tmp_path / "gates"
    directory.mkdir()
    env = _env(tmp_path, CI="true")  # (no progress lines)
    with _started([str(GATES_PY), str(directory), gates, *argv], tmp_path, env=env) as proc:
        deadline = time.monotonic() + HANG_S
        while sorted(p.name.rsplit("-", 1)[0] for p in directory.iterdir()) != sorted(wanted):
            assert time.monotonic() < deadline and proc.poll() is None, \
                f"{moment}: markers {sorted(p.name for p in directory.iterdir())}, not {wanted}"
            time.sleep(0.05)
        started = _descendants(proc.pid)
        os.killpg(proc.pid, sig)
        (directory / "open").write_text("")
        out, err = proc.communicate(timeout=HANG_S)
        deadline = time.monotonic() + HANG_S
        while any(_alive(pid) for pid in started):
            assert time.monotonic() < deadline, f"processes {started} of the command still run"
            time.sleep(0.1)
    return proc.returncode, out.decode(), err.decode()


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("moment", list(MOMENTS))
def test_a_signal_at_any_moment_of_a_pool_sweep_is_one_line(tmp_path, moment, sig):
    """Ctrl-C or SIGTERM to the command and its workers while the pool starts (a worker forked,
    its handlers not yet set: it inherited the command's), runs or shuts down: exit 130 or 143,
    the one line "interrupted", no traceback from a worker, no process left, no temporary file."""
    status, out, err = _signal_at(tmp_path, [*POOL_SWEEP, "--out", "map"], "passmd sweep", moment, sig)
    assert (status, out, err) == (128 + sig, "", "passmd sweep: interrupted\n")
    assert {p.name for p in tmp_path.iterdir()} <= {"cache", "gates"}  # no map written
    assert [p for p in tmp_path.rglob("*.tmp")] == []


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("moment", list(FIT_MOMENTS))
def test_a_signal_at_any_moment_of_a_fit_is_one_line(tmp_path, moment, sig):
    """The same for ``passmd fit``, whose one pool serves all its sweeps, and between two sweeps."""
    (tmp_path / "data.csv").write_text(FIT_DATA)
    status, out, err = _signal_at(tmp_path, [*POOL_FIT, "--out", "fit"], "passmd fit", moment, sig,
                                  moments=FIT_MOMENTS)
    assert (status, out, err) == (128 + sig, "", "passmd fit: interrupted\n")
    assert {p.name for p in tmp_path.iterdir()} <= {"cache", "data.csv", "gates"}  # no fit written


def test_time_left_waits_for_a_few_units():
    """No estimate from the first units (they carry the start-up); the average rate after them."""
    assert progress.time_left(12.0, 1, 12, "run") == f"time left known after {progress.MIN_DONE} runs"
    assert progress.time_left(9.0, 3, 6, "point", lambda s: f"{s:.0f} s") == "about 18 s left"
    assert progress.time_left(9.0, 3, None, "point") == "time left unknown"
    class Terminal:
        text = ""

        def isatty(self):
            return True

        def write(self, text):
            self.text += text

        def flush(self):
            pass

        def getvalue(self):
            return self.text

    terminal = Terminal()
    bar = progress.bar(13, unit="run", desc="critical amplitude", delay=0.0, stream=terminal)
    bar.update(1)
    bar.refresh()
    assert "time left known after 3 runs" in terminal.getvalue() and "about" not in terminal.getvalue()
    bar.close()
