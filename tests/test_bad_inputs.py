"""Bad and odd inputs: a table of named cases and a suite that generates its own.

Contract (README, "Reliability"): whatever the input, ``passmd`` ends in one of

* exit 0 with a finite result (``--json``: one JSON object whose numbers are all finite),
* exit 2 (usage error) or exit 1 (failed run) with exactly one line on stderr,
* exit 130 on Ctrl-C, 141 (nothing printed) when its standard output is closed,

never a traceback and never a RuntimeWarning; the library raises ``ValueError`` for bad
parameters (never ``TypeError``/``AttributeError`` later).
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import json
import math
import os
import re
import subprocess
import sys
import warnings
from pathlib import Path
from unittest import mock

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from passmd import cli
from passmd.cli import kernels, options
from passmd.cli.commands import run
from passmd.model.mdr_contact import MDRContact
from passmd.model.parameters import Drive
from passmd.model.tables import Actuator, Amplifier, Material

PATH_20000 = ",".join(f"{i % 40}nm" for i in range(20000))


def run_main(argv, env=None):
    """(status, stdout, stderr, warnings) of ``passmd argv`` in this process."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.ExitStack() as stack:
        stack.enter_context(contextlib.redirect_stdout(out))
        stack.enter_context(contextlib.redirect_stderr(err))
        caught = stack.enter_context(warnings.catch_warnings(record=True))
        warnings.simplefilter("always")
        if env:
            stack.enter_context(mock.patch.dict(os.environ, env))
        try:
            status = cli.main(list(argv))
        except SystemExit as exc:  # argparse
            status = exc.code
    return status, out.getvalue(), err.getvalue(), list(caught)


def run_process(argv, *, env=None, stdout=subprocess.PIPE, text=True, shell_pipe=None):
    """``python -m passmd argv`` in a subprocess (encodings, full disks, closed pipes)."""
    full_env = {**os.environ, "MPLBACKEND": "Agg", **(env or {})}
    if shell_pipe:
        status = 'echo "status=${PIPESTATUS[0]}" >&2'
        cmd = f"{sys.executable} -m passmd {' '.join(argv)} | {shell_pipe}; {status}"
        return subprocess.run(["bash", "-c", cmd], capture_output=True, text=True, env=full_env, timeout=120)
    return subprocess.run([sys.executable, "-m", "passmd", *argv], stdout=stdout, stderr=subprocess.PIPE,
                          text=text, env=full_env, timeout=120)


def assert_one_line(err: str):
    assert err.count("\n") == 1 and err.startswith("passmd"), err
    assert "Traceback" not in err


# --------------------------------------------------------------------------------------
# Named cases: inputs once found to misbehave, each with the outcome it must have now
# (status, a piece of the one stderr line).
# --------------------------------------------------------------------------------------

NAMED_CASES = {
    "huge mu": (["theory", "--mu", "1e200"], 2, "--mu = 1e+200 is out of range: must be <= 1"),
    "huge mu, json": (["theory", "--mu", "1e200", "--json"], 2, "--mu = 1e+200"),
    # finite: Eqs. 11-12 of u_x,max ~ 1e193 m do not overflow (passmd.model.theory.harmonic_combination)
    "huge mu, extrapolating": (["theory", "--mu", "1e200", "--allow-extrapolation"], 0, ""),
    "huge mu, extrapolating, json": (["theory", "--mu", "1e200", "--allow-extrapolation", "--json"], 0, ""),
    "huge stroke": (["run", "--actuator", "rigid", "--periods", "2", "--full-stroke-amplitude", "1e30nm",
                     "--json"], 2, "--full-stroke-amplitude = 1e+30 nm is out of range"),
    "huge stroke, extrapolating": (["run", "--full-stroke-amplitude", "1e30nm", "--allow-extrapolation"], 2,
                                   "hard limit"),
    "huge runner mass": (["run", "--runner-mass", "1e30g", "--json"], 2, "--runner-mass = 1e+30 g"),
    "tiny preload": (["run", "--preload", "1e-30"], 2, "--preload = 1e-30 N is out of range"),
    "tiny radius": (["run", "--radius", "1e-30mm"], 2, "--radius = 1e-30 mm is out of range"),
    "tiny radius, extrapolating": (["theory", "--radius", "1e-30mm", "--allow-extrapolation"], 2,
                                   "contact radius"),
    "tiny hemisphere modulus": (["run", "--hemisphere-modulus", "1e-30GPa"], 2, "--hemisphere-modulus"),
    "tiny modulus, extrapolating": (["theory", "--hemisphere-modulus", "1e-30GPa", "--allow-extrapolation",
                                     "--json"], 2, "hard limit"),
    "huge contact force": (["contact", "--normal-force", "1e30", "--path", "0nm,1nm"], 2, "--normal-force"),
    "huge contact force, extrapolating": (["contact", "--normal-force", "1e30", "--path", "0nm,1nm",
                                           "--allow-extrapolation", "--json"], 2, "contact radius"),
    "a billion samples": (["run", "--max-points", "1000000000"], 2, "GiB"),
    "a hundred million periods": (["run", "--periods", "100000000", "--json"], 2, "GiB"),
    "analytic-only checks its options": (["critical-amplitude", "--analytic-only", "--periods", "-5",
                                          "--tolerance=-1nm", "--frequency", "nan"], 2, "--periods = -5"),
    "analytic-only tolerance": (["critical-amplitude", "--analytic-only", "--tolerance=-1nm"], 2,
                                "--tolerance = -1.0 is out of range"),
    "analytic-only frequency": (["critical-amplitude", "--analytic-only", "--frequency", "nan"], 2,
                                "--frequency = 'nan'"),
    "threshold without steady": (["critical-amplitude", "--protocol", "first", "--threshold", "1nm"], 2,
                                 "--threshold contradicts --protocol first"),
    "rigid with actuator stiffness": (["theory", "--actuator", "rigid", "--actuator-stiffness", "5e6"], 2,
                                      "--actuator-stiffness contradicts --actuator rigid"),
    "rigid with absurd actuator stiffness": (["theory", "--actuator", "rigid", "--actuator-stiffness", "1"],
                                             2, "--actuator-stiffness"),
    "load cell stiffness without load cell": (["run", "--load-cell-stiffness", "3e4"], 2,
                                              "--load-cell-stiffness has no effect"),
    "plot into a device": (["run", "--plot", "/dev/full"], 2, "no image extension"),
    "plot, unknown format": (["run", "--plot", "out.xyz"], 2, "unknown image extension"),
    "csv into a missing directory": (["run", "--csv", "/nonexistent-dir/x.csv"], 2, "does not exist"),
    "empty figure directory": (["figure", "fig5a", "--out", ""], 2, "--out = '' is not a directory name"),
    "figure name is a path": (["figure", "../../etc/passwd"], 2, "is not a figure name"),
    "unknown figure": (["figure", "fig0x"], 2, "figure 'fig0x' is not available"),
    "frequency 1e-30": (["run", "--frequency", "1e-30kHz"], 2, "--frequency = 1e-30 kHz is out of range"),
    "frequency 1e-30, extrapolating": (["run", "--frequency", "1e-30kHz", "--allow-extrapolation"], 2,
                                       "hard limit"),
    "amplitude a hair above the stroke": (["run", "--amplitude", "202.0000001nm"], 2,
                                          "--amplitude = 202.0000001 nm is out of range: must be <= 202 nm"),
    "force periods name the option": (["force", "--periods", "1", "--max-periods", "2"], 2, "--periods"),
    "unit text that trips the unit parser": (["theory", "--preload", "0:"], 2, "unknown unit ':'"),
    "periods written 1e8": (["run", "--periods", "1e8"], 2, "invalid int value: '1e8'"),
    "slew rate 3e13": (["run", "--slew-rate", "3e13V/us"], 2, "--slew-rate"),
    "load cell stiffness 1e30": (["force", "--load-cell-stiffness", "1e30"], 2, "--load-cell-stiffness"),
    "runner mass 1e-30": (["run", "--runner-mass", "1e-30g"], 2, "--runner-mass"),
    "tiny tolerance, analytic only": (["critical-amplitude", "--analytic-only", "--tolerance", "1e-30nm"], 0,
                                      ""),
    # unbounded inputs: a device is never read (it would be read until killed)
    "drive file /dev/zero": (["drive", "show", "--drive", "/dev/zero"], 2,
                             "/dev/zero: a character device, not a regular file: a drive file is read from a "
                             "regular file of at most 1 MiB"),
    "measurements /dev/zero": (["fit", "/dev/zero", "--free", "mu"], 2,
                               "/dev/zero: a character device, not a regular file: a measurement file is "
                               "read from a regular file of at most 100 MiB"),
    "drive file is a directory": (["theory", "--drive", "/"], 2,
                                  "cannot read the drive file /: Is a directory"),
    # runaway worker counts: refused above the hard bound, before anything starts
    "a hundred thousand workers": (["sweep", "velocity", "--vary", "frequency=100Hz..5kHz:log:3",
                                    "--workers", "100000"], 2,
                                   "--workers = 100000 is out of range: must be an integer from 1 to 1024"),
    "a hundred thousand workers, figure": (["figure", "fig5a", "--workers", "100000"], 2,
                                           "--workers = 100000 is out of range"),
}


@pytest.mark.parametrize("json_flag", [False, True], ids=["as written", "json toggled"])
@pytest.mark.parametrize("name", sorted(NAMED_CASES))
def test_named_case(name, json_flag, monkeypatch):
    """The same outcome with and without --json; a refusal stays one line even on a fresh install,
    where the kernels are still to compile (the compile notice comes only after every check)."""
    # as on a fresh install: numba starts compiling as soon as the notice is armed
    monkeypatch.setattr(kernels, "notice_on_compile", lambda: sys.stderr.write(f"passmd: {kernels.NOTICE}\n"))
    argv, status, message = NAMED_CASES[name]
    if json_flag:
        argv = [a for a in argv if a != "--json"] if "--json" in argv else [*argv, "--json"]
    got, out, err, caught = run_main(argv)
    assert got == status, (name, err)
    assert not [w for w in caught if issubclass(w.category, RuntimeWarning)]
    if status == 0:
        assert err in ("", f"passmd: {kernels.NOTICE}\n"), err
        if "--json" in argv:
            _finite_json(out)
        return
    assert out == ""
    assert_one_line(err)
    assert message in err, err
    assert "initial_periods" not in err and "finite number finite" not in err


def test_force_does_not_name_internal_parameters():
    _, _, err, _ = run_main(["force", "--periods", "1", "--max-periods", "2"])
    assert "initial_periods" not in err and "max_periods" not in err


def test_runner_that_cannot_move_is_not_reported_as_moved(monkeypatch):
    """m_r = 1e30 kg (only with --allow-extrapolation): friction cannot move it by 20 nm."""
    # a refusal of the result comes after the run: on a fresh install the compile notice precedes it
    monkeypatch.setattr(kernels, "notice_on_compile", lambda: None)
    status, out, err, _ = run_main(["run", "--runner-mass", "1e30g", "--allow-extrapolation",
                                    "--periods", "1",
                                    "--json"])
    if status == 0:  # a correct result: the runner stays within the work bound
        data = json.loads(out)
        assert abs(data["final_position_m"]) < 1e-20
    else:
        assert status == 1 and "farther than friction can push the runner" in err
        assert_one_line(err)


def test_interrupted_run_does_not_claim_a_cache():
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    with mock.patch.object(run, "simulate", interrupted):
        status, _, err, _ = run_main(["run"])
    assert status == 130 and err == "passmd run: interrupted\n"


def test_missing_dask_names_the_extra(tmp_path):
    real = importlib.util.find_spec

    def find_spec(name, *args):
        return None if name == "distributed" else real(name, *args)

    with mock.patch.object(importlib.util, "find_spec", find_spec):
        status, _, err, _ = run_main(["figure", "fig5a", "--executor", "dask", "--out", str(tmp_path)])
    assert status == 1
    assert_one_line(err)
    # the extra's own requirement, which installs into any environment (a wheel's, a checkout's)
    assert "pip install 'dask[distributed]>=2024.1' (the passmd[dask] extra)" in err


@pytest.mark.parametrize("build, match", [
    (lambda: Drive(amplifier="x"), "amplifier = 'x' is not an Amplifier"),
    (lambda: Drive(contacts=6.0), "contacts = 6.0 is not allowed"),
    (lambda: Drive(friction_coefficient=1e200), "friction_coefficient"),
    (lambda: Material(210e9, 0.33, name=5), "name = 5"),
    (lambda: MDRContact(1e30, 1e-3, 1.5e11, 1.2e11, 0.2), "contact radius"),
])
def test_named_library_cases(build, match):
    with pytest.raises(ValueError, match=match):
        build()


def test_sawtooth_periods_is_a_count():
    from passmd.model import waveforms

    with pytest.raises(ValueError, match="periods = True"):
        waveforms.sawtooth(100e-9, 100.0, Drive(), periods=True)


def test_validation_messages_read_well():
    from passmd.runtime.validation import check_range

    with pytest.raises(ValueError) as info:
        check_range("x", float("nan"))
    assert str(info.value) == "x = nan is out of range: must be a finite number"


# --------------------------------------------------------------------------------------
# Input files as people (and accidents) make them: named cases that need a file
# --------------------------------------------------------------------------------------


def _refused(argv, *fragments, env=None):
    status, out, err, caught = run_main(argv, env=env)
    assert status == 2 and out == "", (argv, err)
    assert_one_line(err)
    for fragment in fragments:
        assert fragment in err, (fragment, err)
    return err


@pytest.mark.parametrize("command", [["drive", "show", "--drive", "{}"], ["fit", "{}", "--free", "mu"]],
                         ids=["drive file", "measurements"])
def test_a_named_pipe_without_a_writer_is_refused_at_once(tmp_path, command):
    """``mkfifo x; passmd fit x``: one line (it waited forever for a writer)."""
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    _refused([arg.format(fifo) for arg in command], f"{fifo}: a named pipe, not a regular file")


def test_oversized_inputs_are_refused_by_their_size(tmp_path):
    """A 2 MiB drive file and a 101 MiB measurement file (sparse: nothing is written or read)."""
    drive, data = tmp_path / "big.toml", tmp_path / "big.csv"
    with open(drive, "wb") as fh:
        fh.truncate(2 * 2**20)
    with open(data, "wb") as fh:
        fh.truncate(101 * 2**20)
    _refused(["theory", "--drive", str(drive)], f"{drive}: 2 MiB, above the 1 MiB limit of a drive file")
    _refused(["fit", str(data), "--free", "mu"],
             f"{data}: 101 MiB, above the 100 MiB limit of a measurement file")


def test_a_drive_file_with_a_byte_order_mark_reads_as_without(tmp_path):
    """Windows editors save UTF-8 with a byte-order mark: read as UTF-8; UTF-16 is named."""
    plain, marked, utf16 = (tmp_path / name for name in ("plain.toml", "bom.toml", "utf16.toml"))
    text = 'preload = "0.5 N"\n[actuator]\ndamping_ratio = 0.1\n'
    plain.write_bytes(text.encode())
    marked.write_bytes(b"\xef\xbb\xbf" + text.replace("\n", "\r\n").encode())
    utf16.write_bytes(text.encode("utf-16"))
    shown = [run_main(["drive", "show", "--drive", str(p), "--json"]) for p in (plain, marked)]
    assert [s[0] for s in shown] == [0, 0], shown
    assert json.loads(shown[0][1])["drive"] == json.loads(shown[1][1])["drive"]
    _refused(["drive", "show", "--drive", str(utf16)], f"{utf16}: saved as UTF-16", "must be UTF-8")


MEASURED = ("amplitude_nm{d}frequency_Hz{d}step_nm\n"
            "100{d}1000{d}64.25\n150{d}1000{d}116.9\n200{d}1000{d}169.6\n")


@pytest.mark.parametrize("delimiter", [",", ";", "\t"], ids=["comma", "semicolon", "tab"])
def test_measurements_separated_by_semicolons_or_tabs_read_as_with_commas(tmp_path, delimiter):
    """Spreadsheets write semicolons (where the comma is the decimal separator) or tabs; the
    separator is recognised from the header, and the file reads to the same measurements; a byte-
    order mark (Excel's "CSV UTF-8") is dropped."""
    from passmd.protocols.fit import read_measurements

    path = tmp_path / "data.csv"
    path.write_bytes(b"\xef\xbb\xbf" + MEASURED.format(d=delimiter).encode())
    comma = tmp_path / "comma.csv"
    comma.write_text(MEASURED.format(d=","))
    got, expected = read_measurements(path), read_measurements(comma)
    assert got.kind == expected.kind and np.array_equal(got.value, expected.value)
    assert np.array_equal(got.amplitude, expected.amplitude)


def test_a_decimal_comma_is_refused_not_misread(tmp_path):
    path = tmp_path / "data.csv"
    path.write_text(MEASURED.format(d=";").replace("64.25", "64,25"))
    _refused(["fit", str(path), "--free", "mu"],
             f"{path} row 1 (line 2), column step_nm: '64,25' has a decimal comma: write 64.25",
             "separated by semicolons")


@pytest.mark.parametrize(("column", "known"), [
    ("amplitude_m", "amplitude_nm, in nm"), ("velocity_m_per_s", "velocity_mm_per_s, in mm/s"),
    ("critical_amplitude_um", "critical_amplitude_nm, in nm"), ("step_um_sd", "step_nm_sd, in nm"),
    ("frequency_kHz", "frequency_Hz, in Hz"), ("preload", "preload_N, in N"),
])
def test_an_unknown_column_in_another_unit_names_the_known_one(tmp_path, column, known):
    path = tmp_path / "data.csv"
    header = "amplitude_nm,frequency_Hz,step_nm,step_nm_sd".split(",")
    header[{"amplitude": 0, "velocity": 2, "critical": 2, "step": 3, "frequency": 1, "preload": 0}[
        column.split("_")[0]]] = column
    path.write_text(",".join(header) + "\n100,1000,64,1\n")
    err = _refused(["fit", str(path), "--free", "mu"], f"'{column}': not a known column; the column of this "
                                                       f"quantity is {known}")
    assert "allowed:" not in err


def test_too_many_workers_are_capped_with_one_line(monkeypatch):
    """Above two per usable core, one line names the option or the variable as typed and the count
    run; the command then goes on (here: up to its computation, which gets the capped count)."""
    from passmd.protocols import maps

    monkeypatch.setattr("passmd.cli.configuration.usable_cores", lambda: 2)
    seen = []

    def compute_map(*args, config, **kwargs):
        seen.append(config.workers)
        raise _Reached

    monkeypatch.setattr(maps, "compute_map", compute_map)
    argv = ["sweep", "velocity", "--vary", "frequency=100Hz..5kHz:log:3"]
    for extra, env, typed in ((["--workers", "64"], {}, "--workers 64"),
                              ([], {"PASSMD_WORKERS": "9"}, "PASSMD_WORKERS = 9")):
        err = io.StringIO()
        with mock.patch.dict(os.environ, env), contextlib.redirect_stderr(err), pytest.raises(_Reached):
            cli.main([*argv, *extra])
        assert err.getvalue() == (f"passmd sweep: warning: {typed} is more than the 2 usable cores can run: "
                                  "4 worker processes run (2 per core)\n")
    assert seen == [4, 4]


def test_a_pool_never_starts_more_workers_than_points(monkeypatch):
    """``sweep.run(workers=1000)`` over three points forks three processes (two per core at most)."""
    import concurrent.futures as cf

    from passmd.runtime import config, pools, sweep

    monkeypatch.setattr(config, "usable_cores", lambda: 2)
    sizes = []

    class Pool(cf.ThreadPoolExecutor):
        def __init__(self, max_workers, initializer=None, initargs=()):
            sizes.append(max_workers)
            super().__init__(max_workers)

    monkeypatch.setattr(cf, "ProcessPoolExecutor", Pool)
    monkeypatch.setattr(pools, "worker_signals", lambda *args: None)
    with pytest.warns(config.WorkersCapped, match="workers = 1000 is more than the 2 usable cores"):
        sweep.run(_double, sweep.grid(x=[1, 2, 3]), executor="process", workers=1000, cache=False)
    sweep.run(_double, sweep.grid(x=[1, 2, 3]), executor="process", workers=4, cache=False)
    assert sizes == [3, 3]
    with pytest.raises(ValueError, match="workers = 1025 is out of range: must be an integer from 1 to 1024"):
        sweep.run(_double, sweep.grid(x=[1, 2]), workers=1025, cache=False)


def _double(x):
    return {"y": 2 * x}


# --------------------------------------------------------------------------------------
# Output paths: full disk, closed pipe, ASCII console (real processes)
# --------------------------------------------------------------------------------------

full_disk = pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")


@full_disk
@pytest.mark.parametrize("argv", [["theory"], ["theory", "--json"],
                                  ["contact", "--path", "0nm,30nm", "--json"],
                                  ["--help"], ["run", "--help"], ["--version"]])
def test_full_disk_on_stdout_is_one_line_exit_1(argv):
    with open("/dev/full", "w") as full:
        done = run_process(argv, stdout=full)
    assert done.returncode == 1, done.stderr
    assert_one_line(done.stderr)
    assert "No space left on device" in done.stderr


@pytest.mark.parametrize("json_flag", [[], ["--json"]])
def test_closed_pipe_exits_quietly(json_flag):
    done = run_process(["contact", "--path", PATH_20000, *json_flag], shell_pipe="head -1")
    assert done.stdout.startswith("{" if json_flag else "passmd contact")
    # nothing on stderr but the shell's status line: 141 when the write met the closed pipe,
    # 0 when the whole output fit into the pipe before ``head`` went away (a race)
    assert done.stderr.strip() in ("status=141", "status=0"), done.stderr


@pytest.mark.parametrize("argv", [["theory"], ["contact", "--path", "0nm,30nm"], ["theory", "--help"],
                                  ["theory", "--json"]])
def test_ascii_console_gets_ascii_symbols(argv):
    done = run_process(argv, env={"PYTHONIOENCODING": "ascii"})
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    assert done.stdout.isascii()
    if argv == ["theory"]:
        assert "mu = 0.2" in done.stdout


def test_ascii_console_error_message():
    done = run_process(["theory", "--mu", "2"], env={"PYTHONIOENCODING": "ascii"})
    assert done.returncode == 2
    assert_one_line(done.stderr)
    assert "Cattaneo-Mindlin" in done.stderr


# --------------------------------------------------------------------------------------
# Generated inputs (hypothesis) over the CLI's option grammar and the constructors
# --------------------------------------------------------------------------------------


class _Reached(BaseException):
    """Raised by stand-ins of the long computations: the input passed every check."""


def _reached(*args, **kwargs):
    raise _Reached


UNITS = ["", "N", "mN", "nm", "um", "mm", "m", "g", "kg", "GPa", "Pa", "kHz", "Hz", "V", "V/us", "N/m",
         "kg/s", "s", "furlong"]
ODD = ["nan", "inf", "-inf", "", " ", "1e309", "-0", "0", "abc", "1e-320", "0x10", "1,2", "µ", "--", "1e",
       "3N", "1 furlong", "+", "1_000", "٣"]
numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(min_value=1e-3, max_value=1e3),
    st.integers(min_value=-10**12, max_value=10**12),
)
values = st.one_of(
    st.builds(lambda x, u: f"{x!r}{u}", numbers, st.sampled_from(UNITS)),
    st.sampled_from(ODD),
    st.text(max_size=8),
)
QUANTITY_FLAGS = [q.flag for q in options.DRIVE_QUANTITIES]
COMMANDS = {
    "theory": (QUANTITY_FLAGS, ["--json", "--allow-extrapolation"],
               {"--contacts": ["1", "6", "3", "x"], "--actuator": ["rigid", "flexible", "x"]}),
    "contact": (["--radius", "--mu", "--normal-force", *options.MATERIAL_FLAGS, "--springs"],
                ["--json", "--allow-extrapolation"],
                {"--path": ["0,30nm,-10nm", "0", "1e30", "nan", "", "0,,1", "0,1e-300,3N"]}),
    "critical-amplitude": (QUANTITY_FLAGS + ["--frequency", "--threshold", "--tolerance", "--periods"],
                           ["--json", "--analytic-only", "--allow-extrapolation"],
                           {"--protocol": ["steady", "first", "x"], "--flyback": ["slew", "fixed", "x"],
                            "--actuator": ["rigid", "flexible"]}),
    "run": (QUANTITY_FLAGS + ["--amplitude", "--frequency", "--periods", "--springs", "--max-points"],
            ["--json", "--load-cell", "--allow-extrapolation"],
            {"--waveform": ["sawtooth", "optimized", "x"], "--flyback": ["slew", "fixed"],
             "--plot": ["p.png", "p", "p.xyz", "", "/dev/full", "missing/p.png"],
             "--csv": ["r.csv", "", "missing/r.csv", "."], "--actuator": ["rigid", "flexible"]}),
    "force": (QUANTITY_FLAGS + ["--amplitude", "--frequency", "--periods", "--max-periods", "--max-points"],
              ["--json", "--allow-extrapolation"], {"--waveform": ["sawtooth", "optimized"]}),
    "figure": ([], ["--json"], {"--profile": ["quick", "paper", "x"], "--out": ["", "out", ".", "/dev/null"],
                                "--executor": ["serial", "process", "x"],
                                "--workers": ["0", "2", "-1", "x"]}),
}


@st.composite
def command_lines(draw):
    command = draw(st.sampled_from(sorted(COMMANDS)))
    quantities, flags, choices = COMMANDS[command]
    argv = [command]
    if command == "figure":
        argv.append(draw(st.one_of(st.sampled_from(["fig5a", "fig9b", "list", "fig0x", "../x", ""]),
                                   st.text(max_size=6))))
    for flag in draw(st.lists(st.sampled_from(quantities), max_size=4, unique=True)) if quantities else []:
        argv += [flag, draw(values)] if not flag.endswith(("periods", "springs", "max-points")) else \
            [flag, draw(st.one_of(st.integers(-5, 10**10).map(str), values))]
    for flag in draw(st.lists(st.sampled_from(sorted(choices)), max_size=3, unique=True)):
        argv += [flag, draw(st.sampled_from(choices[flag]))]
    argv += draw(st.lists(st.sampled_from(flags), max_size=len(flags), unique=True))
    return argv


def _finite_json(text: str):
    def refuse(constant):
        raise AssertionError(f"non-finite {constant} in the JSON output")

    data = json.loads(text, parse_constant=refuse)

    def walk(x):
        if isinstance(x, float):
            assert math.isfinite(x)
        elif isinstance(x, dict):
            for v in x.values():
                walk(v)
        elif isinstance(x, list):
            for v in x:
                walk(v)

    walk(data)
    return data


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    """A working directory (and cache) of its own: generated paths never touch the project."""
    path = tmp_path_factory.mktemp("fuzz")
    before = os.getcwd()
    os.chdir(path)
    try:
        yield path
    finally:
        os.chdir(before)


@settings(max_examples=int(os.environ.get("PASSMD_FUZZ_EXAMPLES", "250")), deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(argv=command_lines())
def test_generated_command_lines_end_cleanly(scratch, argv):
    from passmd.experiments import figure_table
    from passmd.protocols import critical_amplitude, stall

    # the long computations are replaced by a marker: reaching them means every check passed
    with mock.patch.object(run, "simulate", _reached), \
            mock.patch.object(critical_amplitude, "critical_amplitude", _reached), \
            mock.patch.object(stall, "generated_force", _reached), \
            mock.patch.object(figure_table, "figure_data", _reached):
        try:
            status, out, err, caught = run_main(argv, env={"PASSMD_CACHE_DIR": str(scratch / "cache")})
        except _Reached:
            event(f"{argv[0]}: every check passed")
            return
    event(f"{argv[0]}: exit {status}")
    assert not [w for w in caught if issubclass(w.category, RuntimeWarning)], argv
    assert "Traceback" not in err, (argv, err)
    assert status in (0, 1, 2), (argv, status, err)
    if status == 0:
        assert err == "", (argv, err)
        if "--json" in argv:
            _finite_json(out)
    else:
        assert err.count("\n") == 1 and err.startswith("passmd"), (argv, err)
        assert "internal error" not in err, (argv, err)


anything = st.one_of(
    st.none(), st.booleans(), st.integers(-10, 10), st.floats(allow_nan=True, allow_infinity=True),
    st.floats(min_value=1e-12, max_value=1e12), st.text(max_size=4),
    st.lists(st.floats(min_value=0, max_value=1), max_size=2),
    st.sampled_from([np.float64(0.4), np.int64(6), np.bool_(True), np.array([1.0]), "rigid", "flexible"]),
)
DRIVE_FIELDS = ["hemisphere_radius", "preload", "friction_coefficient", "contacts", "actuator_model",
                "runner_mass", "load_cell_stiffness", "load_cell", "hemisphere_material", "runner_material",
                "actuator", "amplifier", "allow_extrapolation"]


@settings(max_examples=int(os.environ.get("PASSMD_FUZZ_EXAMPLES", "250")), deadline=None)
@given(kwargs=st.dictionaries(st.sampled_from(DRIVE_FIELDS), anything, max_size=4))
def test_generated_drives_are_valid_or_a_value_error(kwargs):
    try:
        drive = Drive(**kwargs)
    except ValueError as exc:
        assert re.match(r"^[\w.,\s]+", str(exc)), exc
        return
    assert isinstance(drive.contacts, int) and drive.contacts in (1, 6)
    assert isinstance(drive.amplifier, Amplifier) and isinstance(drive.actuator, Actuator)


@settings(max_examples=int(os.environ.get("PASSMD_FUZZ_EXAMPLES", "250")), deadline=None)
@given(record=st.sampled_from([Material, Actuator, Amplifier]), args=st.lists(anything, max_size=4))
def test_generated_records_are_valid_or_a_value_error(record, args):
    try:
        record(*args)
    except ValueError:
        pass
    except TypeError as exc:  # only a wrong number of arguments
        assert "argument" in str(exc), exc


def test_named_cases_cover_every_command():
    """The named command lines reach at least five commands, and the generated ones all six (the
    generated drive files, measurement files and --vary specifications: test_generated_inputs.py)."""
    assert len({argv[0] for argv, _, _ in NAMED_CASES.values()}) >= 5
    assert len(COMMANDS) == 6


def test_output_files_are_complete_or_absent(tmp_path):
    """A write that fails half-way (full disk, Ctrl-C) leaves neither a partial file nor a temporary."""
    from passmd.runtime.outputs import write_file

    target = tmp_path / "series.csv"

    def half_then_fail(tmp):
        Path(tmp).write_text("time_s,x_m\n0.0,")
        raise OSError(28, "No space left on device")

    with pytest.raises(OSError, match="No space"):
        write_file(target, half_then_fail)
    assert list(tmp_path.iterdir()) == []
    write_file(target, lambda tmp: Path(tmp).write_text("time_s\n0.0\n"))
    assert target.read_text() == "time_s\n0.0\n"
    assert oct(target.stat().st_mode & 0o777) == oct(0o666 & ~_umask())
    assert [p.name for p in tmp_path.iterdir()] == ["series.csv"]


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
