"""Every refusal names what the user typed: the option, variable or parameter, its value, the limit.

Contract (README, "Reliability": one line naming the option or environment variable as
typed, its value and the allowed range): a value refused deep in the
package (a record, a waveform, the Eq. 15 design) reaches the user as the command-line
option that set it, with the value as typed and the limit in the option's unit; a
quantity computed from an option (the damping ratio from --actuator-viscosity, the
fly-back from --amplitude, Δ_a of Eq. 15) says what it is and how to change the option;
an environment variable is named as set. No message shows ``np.float64(…)`` or a field
path such as ``actuator.damping_ratio``. The library raises ``ValueError`` naming its own
parameter, with plain numbers.
"""

from __future__ import annotations

import math
import os
import pickle
import re
import subprocess
import sys
from unittest import mock

import numpy as np
import pytest
from cli_runs import run_main

from passmd.cli import options
from passmd.cli.commands import run
from passmd.cli.parser import make_parser
from passmd.model import optimized_waveform, waveforms
from passmd.model.mdr_contact import MDRContact
from passmd.model.parameters import PLAUSIBLE_RANGES, Drive, check_plausible
from passmd.model.tables import Actuator, actuator_viscosity, parameter_table
from passmd.protocols import eq15
from passmd.runtime.config import RunConfig
from passmd.runtime.validation import InputError, safe_bound

#: What a message must never show: numpy reprs, and the package's field paths and
#: snake_case names (``actuator.damping_ratio``, ``acceleration_amplitude``).
INTERNALS = (re.compile(r"np\.\w+\("), re.compile(r"\b[a-z_]{2,}\.[a-z_]{2,}\b"),
             re.compile(r"\b[a-z]{2,}_[a-z]{2,}\b"))


def assert_one_clean_line(err: str) -> str:
    assert err.count("\n") == 1 and err.startswith("passmd"), err
    assert "Traceback" not in err
    for pattern in INTERNALS:
        assert not pattern.search(err), (pattern.pattern, err)
    return err


def run_process(argv, env, cwd):
    """``python -m passmd argv`` in a subprocess: (status, stdout, stderr)."""
    full_env = {**os.environ, "MPLBACKEND": "Agg", "PASSMD_CACHE_DIR": str(cwd / "cache"), **env}
    done = subprocess.run([sys.executable, "-m", "passmd", *argv], capture_output=True, text=True,
                          env=full_env, cwd=cwd, timeout=300)
    return done.returncode, done.stdout, done.stderr


# --------------------------------------------------------------------------------------
# The inputs once answered in the package's own terms, each with what its line must say
# (the option or variable as typed, the value, the limit), run as a user would.
# --------------------------------------------------------------------------------------

FIGURE = ["figure", "fig5a", "--profile", "quick", "--out", "out"]
REPROS = {
    "actuator viscosity 1e300": (
        ["run", "--actuator-viscosity", "1e300"], {},
        ("the damping ratio", "derived from --actuator-viscosity 1e300 kg/s", "is 1.322e+300",
         "must be <= 10", "lower --actuator-viscosity to at most", "--allow-extrapolation")),
    "hemisphere poisson -0.99": (
        ["run", "--hemisphere-poisson", "-0.99"], {},
        ("--hemisphere-poisson = -0.99 is out of range: must be >= 0",
         "--allow-extrapolation goes beyond it")),
    "amplitude 1e-300": (
        ["run", "--amplitude", "1e-300nm"], {},
        ("fly-back time", "derived from --amplitude 1e-300nm", "must be >=",
         "raise --amplitude to at least")),
    "optimized waveform at 10 nm": (
        ["run", "--waveform", "optimized", "--amplitude", "10nm"], {},
        ("the Eq. 15 acceleration amplitude", "derived from --amplitude 10nm", "must be < 10 nm",
         "raise --amplitude above")),
    "PASSMD_WORKERS superscript two": (
        FIGURE, {"PASSMD_WORKERS": "²"},
        ("PASSMD_WORKERS = '²' is not allowed", "must be an integer from 1 to 1024")),
    "PASSMD_WORKERS a hundred thousand": (
        FIGURE, {"PASSMD_WORKERS": "100000"},
        ("PASSMD_WORKERS = '100000' is not allowed", "must be an integer from 1 to 1024")),
    "fit with a hundred thousand workers": (
        ["fit", "data.csv", "--free", "mu", "--workers", "100000"], {},
        ("--workers = 100000 is out of range: must be an integer from 1 to 1024",)),
    "drive file /dev/zero": (
        ["theory", "--drive", "/dev/zero"], {},
        ("/dev/zero: a character device, not a regular file: a drive file is read from a regular file of "
         "at most 1 MiB",)),
    "measurement file /dev/zero": (
        ["fit", "/dev/zero", "--free", "mu"], {},
        ("/dev/zero: a character device, not a regular file: a measurement file is read from a regular "
         "file of at most 100 MiB",)),
    "PASSMD_EXECUTOR threads": (
        FIGURE, {"PASSMD_EXECUTOR": "threads"},
        ("PASSMD_EXECUTOR = 'threads' is not allowed", "must be one of process, serial, dask")),
    "PASSMD_SWEEP_LOG on a full device": (
        FIGURE, {"PASSMD_SWEEP_LOG": "/dev/full"},
        ("PASSMD_SWEEP_LOG = '/dev/full' cannot be written", "No space left on device")),
}


@pytest.mark.parametrize("json_flag", [[], ["--json"]], ids=["human", "json"])
@pytest.mark.parametrize("name", list(REPROS))
def test_repro_names_what_was_typed(name, json_flag, tmp_path):
    argv, env, fragments = REPROS[name]
    if env.get("PASSMD_SWEEP_LOG") == "/dev/full" and not os.path.exists("/dev/full"):
        pytest.skip("needs /dev/full")
    (tmp_path / "data.csv").write_text("amplitude_nm,frequency_Hz,step_nm\n100,1000,64\n150,1000,117\n")
    status, out, err = run_process([*argv, *json_flag], env, tmp_path)
    assert status == 2, err
    assert out == ""
    assert_one_clean_line(err)
    for fragment in fragments:
        assert fragment in err, (fragment, err)
    assert not (tmp_path / "out").exists()  # refused before anything ran


def test_viscosity_advice_holds():
    """The viscosity bound the message gives is on its safe side; a hair above the exact one is refused."""
    _, _, err = run_main(["theory", "--actuator-viscosity", "1e300"])
    bound = float(re.search(r"to at most ([0-9.e+-]+) kg/s", err).group(1))
    actuator = Drive().actuator
    per_zeta = 2 * math.sqrt(actuator.stiffness * actuator.mass)  # c_p = 2ζ√(k_p m_a)
    exact = PLAUSIBLE_RANGES["actuator.damping_ratio"].soft_high * per_zeta
    assert exact * (1 - 1e-3) < bound <= exact
    assert run_main(["theory", "--actuator-viscosity", f"{bound!r}"])[0] == 0
    assert run_main(["theory", "--actuator-viscosity", f"{exact * (1 + 1e-9)!r}"])[0] == 2


def test_eq15_advice_holds():
    """Above the Δ_a the optimized-waveform message names, the design fits and the run succeeds."""
    status, _, err = run_main(["run", "--waveform", "optimized", "--amplitude", "10nm", "--periods", "2"])
    assert status == 2, err
    bound = float(re.search(r"raise --amplitude above ([0-9.e+-]+) nm", err).group(1))
    status, out, err = run_main(["run", "--waveform", "optimized", "--amplitude", f"{bound * 1.001:.6g}nm",
                                 "--periods", "2", "--json"])
    assert status == 0, err


@pytest.mark.parametrize(("op", "bound", "shown"), [
    (">", 19.7461, "19.75"), (">=", 1.40191e-9, "1.402e-09"), ("<", 250000.00000000003, "2.5e+05"),
    ("<=", 7.5630681604756145, "7.563"), ("<=", 10.0, "10"), (">", -1.0, "-1"), ("<", 0.5, "0.5"),
    (">", 0.0, "0"), ("<", 19.7469, "19.74"),
])
def test_limits_are_rounded_on_their_safe_side(op, bound, shown):
    """A rounded lower limit is not below the exact one, a rounded upper one not above it."""
    assert safe_bound(op, bound) == shown
    assert (float(shown) >= bound) if op.startswith(">") else (float(shown) <= bound)


# --------------------------------------------------------------------------------------
# Every numeric option of ``run``, read from its parser (a new option is covered at once)
# --------------------------------------------------------------------------------------


def _numeric_run_options() -> list[str]:
    run_parser = make_parser()._subparsers._group_actions[0].choices["run"]
    return [action.option_strings[-1] for action in run_parser._actions
            if action.option_strings and (action.type in (int, float)
                                          or action.option_strings[-1] in options.QUANTITIES)]


RUN_OPTIONS = _numeric_run_options()


class _Reached(BaseException):
    """The simulation was reached: every check passed."""


def _reached(*args, **kwargs):
    raise _Reached


def test_the_option_list_is_read_from_the_parser():
    assert {"--actuator-viscosity", "--hemisphere-poisson", "--amplitude", "--frequency", "--periods",
            "--springs", "--max-points", "--contacts"} <= set(RUN_OPTIONS)
    assert {q.flag for q in options.DRIVE_QUANTITIES} <= set(RUN_OPTIONS)


@pytest.mark.parametrize("json_flag", [[], ["--json"]], ids=["human", "json"])
@pytest.mark.parametrize("value", ["-1e300", "1e300"])
@pytest.mark.parametrize("flag", RUN_OPTIONS)
def test_every_numeric_run_option_is_named_when_refused(flag, value, json_flag):
    argv = ["run", f"{flag}={value}", "--load-cell", *json_flag]  # --load-cell: its stiffness applies
    with mock.patch.object(run, "simulate", _reached):
        try:
            status, out, err = run_main(argv)
        except _Reached:
            pytest.fail(f"{argv} was accepted")
    assert status == 2, err
    assert out == ""
    assert_one_clean_line(err)
    assert flag in err, err


# --------------------------------------------------------------------------------------
# Environment variables and the sweep log
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize(("variable", "value", "allowed"), [
    ("PASSMD_WORKERS", "²", "an integer from 1 to 1024"),
    ("PASSMD_WORKERS", "0", "an integer from 1 to 1024"),
    ("PASSMD_WORKERS", "٣", "an integer from 1 to 1024"),
    ("PASSMD_WORKERS", "100000", "an integer from 1 to 1024"),
    ("PASSMD_WORKERS", "9" * 5000, "an integer from 1 to 1024"),  # (beyond int()'s digit limit)
    ("PASSMD_EXECUTOR", "threads", "one of process, serial, dask"),
    ("PASSMD_PROFILE", "fast", "one of quick, paper"),
])
def test_environment_errors_name_the_variable(variable, value, allowed):
    with pytest.raises(ValueError) as info:
        RunConfig.from_environment({variable: value})
    assert str(info.value).startswith(f"{variable} = {value!r} is not allowed: must be {allowed}"), \
        str(info.value)[:200]


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
def test_sweep_log_write_failure_names_where_the_path_came_from():
    with pytest.raises(OSError, match=r"sweep log PASSMD_SWEEP_LOG = '/dev/full': No space left"):
        RunConfig.from_environment({"PASSMD_SWEEP_LOG": "/dev/full"}).log_sweep({"points": 1})
    with pytest.raises(OSError, match=r"sweep log sweep_log = '/dev/full': No space left"):
        RunConfig(sweep_log="/dev/full").log_sweep({"points": 1})


@pytest.mark.parametrize(("log", "message"), [
    ("missing-dir/sweeps", "PASSMD_SWEEP_LOG = 'missing-dir/sweeps': the directory 'missing-dir' does "
                              "not exist"),
    (".", "PASSMD_SWEEP_LOG = '.' is a directory"),
])
def test_unusable_sweep_log_is_refused_before_running(log, message, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("PASSMD_SWEEP_LOG", log)
    status, out, err = run_main(["ledger", "--profile", "quick"])
    assert status == 2 and out == ""
    assert_one_clean_line(err)
    assert message in err, err


# --------------------------------------------------------------------------------------
# The library: public functions check their arguments; messages show plain numbers
# --------------------------------------------------------------------------------------

DESIGN = optimized_waveform.OptimizedDesign(1e-6, 1e-6, 10e-9)
D = Drive()
#: (name, call, what the message must start with)
API_CASES = [
    ("flyback_time, not a drive", lambda: waveforms.flyback_time(1e-7, "x"), r"drive = 'x' is not a Drive"),
    ("flyback_time, amplitude text", lambda: waveforms.flyback_time("a", D),
     r"amplitude = 'a' is not a number"),
    ("flyback_time, negative amplitude", lambda: waveforms.flyback_time(-1.0, D),
     r"amplitude = -1.0 is out of range"),
    ("sawtooth, not a drive", lambda: waveforms.sawtooth(1e-7, 100.0, "x"), r"drive = 'x' is not a Drive"),
    ("piecewise_linear, settle window a number",
     lambda: waveforms.piecewise_linear([0, 0.01], [0, 0], 100.0, 1, 3, 0.0), r"settle_window = 3 "),
    ("piecewise_linear, kind a number",
     lambda: waveforms.piecewise_linear([0, 0.01], [0, 0], 100.0, 1, (0, 0.005), 0.0, kind=3), r"kind = 3 "),
    ("piecewise_linear, times text",
     lambda: waveforms.piecewise_linear("ab", [0, 0], 100.0, 1, (0, 0.005), 0.0), r"period_times = 'ab'"),
    ("Waveform, amplitude nan",
     lambda: waveforms.Waveform([0.0, 1.0], [0.0, 0.0], 1.0, 1, [[0.0, 1.0]], [0.0], amplitude=math.nan),
     r"amplitude = nan is out of range"),
    ("Waveform, times not increasing",
     lambda: waveforms.Waveform(np.array([0.0, 1.0, 1.0]), np.zeros(3), 1.0, 1, [[0.0, 1.0]], [0.0]),
     r"waveform times must increase strictly: times\[2\] = 1.0 <= times\[1\] = 1.0$"),
    ("actuator_viscosity, negative stiffness", lambda: actuator_viscosity(-1.0, 1.0),
     r"stiffness = -1.0 is out"),
    ("actuator_viscosity, text mass", lambda: actuator_viscosity(1.0, "a"), r"mass = 'a' is not a number"),
    ("actuator_viscosity, negative damping", lambda: actuator_viscosity(1.0, 1.0, -0.1),
     r"damping_ratio = -0.1 is out"),
    ("parameter_table, not a record", lambda: parameter_table("x"),
     r"record = 'x' is not a parameter record"),
    ("check_plausible, not a drive", lambda: check_plausible("x"), r"drive = 'x' is not a Drive"),
    ("max_piezo_velocity, not a drive", lambda: optimized_waveform.max_piezo_velocity("x"), r"drive = 'x'"),
    ("optimized_timing, not a drive", lambda: optimized_waveform.optimized_timing(DESIGN, 1e-7, 100.0, "x"),
     r"drive = 'x'"),
    ("optimized, periods text", lambda: optimized_waveform.optimized(1e-7, 100.0, D, "x", design=DESIGN),
     r"periods = 'x' is out of range"),
    ("MDRContact.for_drive, not a drive", lambda: MDRContact.for_drive("x"), r"drive = 'x' is not a Drive"),
    ("optimized_design, not a drive", lambda: eq15.optimized_design(1e-7, "x"),
     r"drive = 'x' is not a Drive"),
    ("Drive, numpy contacts", lambda: Drive(contacts=np.int64(3)), r"contacts = 3 is not allowed"),
    ("Drive, numpy viscosity", lambda: Drive(actuator=Actuator(6.5e6, 2.2e-8, np.float64(1e300), 202e-9)),
     r"actuator\.damping_ratio = 1\.32\d*e\+300 is out of range: must be <= 10"),
]


@pytest.mark.parametrize(("call", "start"),
                         [pytest.param(call, start, id=name) for name, call, start in API_CASES])
def test_public_functions_name_the_parameter(call, start):
    with pytest.raises(ValueError, match="^" + start) as info:
        call()
    assert "np." not in str(info.value)


def test_derived_quantity_carries_its_source():
    """The damping ratio's error says which input it came from and the limit on that input."""
    with pytest.raises(InputError) as info:
        Drive(actuator=Actuator(6.5e6, 2.2e-8, 1e300, 202e-9))
    exc = info.value
    assert (exc.name, exc.source, exc.source_value, exc.soft) == ("actuator.damping_ratio",
                                                                  "actuator.viscosity", 1e300, True)
    (op, bound), = exc.source_limits
    assert op == "<=" and bound == pytest.approx(10 * 2 * math.sqrt(6.5e6 * 2.2e-8), rel=1e-12)


def test_input_error_survives_a_process_pool():
    """Sweeps send a point's error back from a worker process: its parts must survive pickling."""
    with pytest.raises(InputError) as info:
        Drive(preload=1e30)
    again = pickle.loads(pickle.dumps(info.value))
    assert type(again) is InputError and str(again) == str(info.value)
    assert (again.name, again.limits, again.soft) == (info.value.name, info.value.limits, info.value.soft)


# --------------------------------------------------------------------------------------
# Input files: the file, what it is, the limit; the column the user meant
# --------------------------------------------------------------------------------------


def _files(tmp_path) -> dict:
    """Inputs that are not what a reader reads, by what they are."""
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    big = tmp_path / "big"
    with open(big, "wb") as fh:
        fh.truncate(200 * 2**20)
    utf16, latin1 = tmp_path / "utf16", tmp_path / "latin1"
    utf16.write_bytes("preload = 0.4\n".encode("utf-16"))
    latin1.write_bytes("preload = 0.4 # réglé\n".encode("latin-1"))
    kept = "not a regular file: a {kind} is read from a regular file of at most {limit}"
    return {"a device": ("/dev/zero", "a character device, " + kept),
            "a named pipe": (str(fifo), "a named pipe, " + kept),
            "too large": (str(big), "200 MiB, above the {limit} limit of a {kind}"),
            "UTF-16": (str(utf16), "saved as UTF-16: a {kind} must be UTF-8 text (save it as UTF-8)"),
            "Latin-1": (str(latin1), "not UTF-8 text: byte 0xe9 on line 1 (a {kind} must be UTF-8 text)")}


@pytest.mark.parametrize("what", ["a device", "a named pipe", "too large", "UTF-16", "Latin-1"])
@pytest.mark.parametrize(("kind", "limit"), [("drive file", "1 MiB"), ("measurement file", "100 MiB")])
def test_an_unread_input_file_is_named_with_what_it_is_and_the_limit(tmp_path, what, kind, limit):
    """``file: what it is, the limit`` — from the library (a ValueError) and the command line alike."""
    from passmd.model.drive_file import read_drive_file
    from passmd.protocols.fit import read_measurements

    path, text = _files(tmp_path)[what]
    expected = f"{path}: " + text.format(kind=kind, limit=limit)
    if what == "too large" and kind == "drive file":
        expected = f"{path}: 200 MiB, above the 1 MiB limit of a drive file"
    reader = read_drive_file if kind == "drive file" else read_measurements
    with pytest.raises(ValueError) as info:
        reader(path)
    assert str(info.value) == expected
    argv = ["theory", "--drive", path] if kind == "drive file" else ["fit", path, "--free", "mu"]
    status, out, err = run_main(argv)
    assert (status, out) == (2, "") and err == f"passmd {argv[0]}: error: {expected}\n"


@pytest.mark.parametrize(("column", "message"), [
    ("amplitude_m", "'amplitude_m': not a known column; the column of this quantity is amplitude_nm, in nm "
                    "(a column name carries its unit: convert the values)"),
    ("Amplitude (nm)", "'Amplitude (nm)': not a known column; did you mean amplitude_nm? (column names are "
                       "written exactly so)"),
    ("FORCE_N", "'FORCE_N': not a known column; did you mean force_N?"),
    ("force_mN_sd", "'force_mN_sd': not a known column; the column of this quantity is force_N_sd, in N"),
    ("temperature_K", "'temperature_K': not a known column; allowed: amplitude_nm, preload_N, frequency_Hz"),
])
def test_an_unknown_column_names_the_column_meant(tmp_path, column, message):
    from passmd.protocols.fit import MeasurementError, read_measurements

    path = tmp_path / "data.csv"
    path.write_text(f"frequency_Hz,step_nm,{column}\n100,1,1\n")
    with pytest.raises(MeasurementError) as info:
        read_measurements(path)
    assert str(info.value).startswith(f"{path} header, column 3 {message}"), str(info.value)


# --------------------------------------------------------------------------------------
# What the user typed, where the package's own terms or argparse's would hide it
# --------------------------------------------------------------------------------------

ANGLE_FILE = ('[[contact_groups]]\ncount = 2\nside = 1\ncontact_angle = "1e-6 deg"\n'
              '[[contact_groups]]\ncount = 2\nside = 2\ncontact_angle = "1e-6 deg"\n')
TYPED = {
    "a frequency in another unit": (["--frequency", "1mHz"], None, (
        "--frequency = 1mHz (= 1e-06 kHz) is out of range: must be > 1e-06 kHz",)),
    "a value below the smallest double": (["--preload", "1e-400N"], None, (
        "--preload = 1e-400N (below the smallest number a double holds: it reads as 0) is out of range",)),
    "a negative value after an option": (["--flyback", "-1us"], None, (
        "--flyback = '-1us' is out of range",)),
    "a fly-back below any amplifier": (["--flyback", "1e-30us"], None, (
        "--flyback = '1e-30us' is out of range: must be >= 0.001 us",)),
    "a fly-back option longer than half a period": (["--flyback", "6ms"], None, (
        "--frequency = 0.1 kHz (default) is out of range", "the fly-back is --flyback 6ms")),
    "a drive file's fly-back longer than half a period": ([], '[amplifier]\nflyback = "6 ms"\n', (
        "--frequency = 0.1 kHz (default) is out of range", "the fly-back is amplifier.flyback in {file}")),
    "a drive file's contact angle": ([], ANGLE_FILE, ("{file}: the Hertz contact radius",
                                                     "the contacts this drive file describes")),
    "Eq. 15 times that do not fit the default frequency": (
        ["--waveform", "optimized", "--settling-time", "5ms"], None,
        ("--frequency = 0.1 kHz (default) is out of range", "(from --settling-time 5ms)",
         "lower --settling-time, or give a lower --frequency")),
}


@pytest.mark.parametrize("name", list(TYPED))
def test_a_refusal_names_the_input_as_typed(name, tmp_path):
    argv, file_text, fragments = TYPED[name]
    path = tmp_path / "mine.toml"
    if file_text is not None:
        path.write_text(file_text, encoding="utf-8")
        argv = [*argv, "--drive", str(path)]
    status, out, err = run_main(["run", "--periods", "1", *argv])
    assert status == 2 and out == "", err
    assert err.count("\n") == 1 and err.startswith("passmd run: error: ") and "Traceback" not in err, err
    for fragment in fragments:
        assert fragment.format(file=path) in err, (fragment, err)
    if name == "a drive file's contact angle":
        assert "--preload" not in err and "--radius" not in err  # options the user did not type


def test_an_upper_frequency_limit_is_shown_rounded_down():
    """Typed back, the highest frequency a message names is within the limit (never rounded up)."""
    from passmd.cli.notes import hz

    for limit in (99.9849, 99.98, 4908.7, 1e5 * (1 - 1e-9), 123456.0, 0.0123456):
        shown = hz(limit, down=True)
        value, unit = shown.split()
        typed = float(value) * (1e3 if unit == "kHz" else 1.0)
        assert typed <= limit * (1 + 1e-12) and typed > limit * (1 - 1e-3), (limit, shown)


def test_an_unusable_user_cache_folder_names_its_variable(tmp_path, monkeypatch):
    from passmd.runtime.cache import store

    afile = tmp_path / "afile"
    afile.write_text("")
    monkeypatch.delenv("PASSMD_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(afile))
    monkeypatch.setattr(store, "_REPORTED_UNWRITABLE", set())
    status, out, err = run_main(["sweep", "velocity", "--vary", "frequency=1kHz,2kHz", "--contacts", "1",
                                 "--actuator", "rigid", "--executor", "serial", "--json"])
    assert status == 0, err
    warning = [line for line in err.splitlines() if "warning" in line]
    assert len(warning) == 1, err
    assert f"cannot use the cache {afile}/passmd/results: Not a directory" in warning[0]
    assert f"from XDG_CACHE_HOME = {afile}" in warning[0] and "PASSMD_CACHE_DIR or --cache-dir" in warning[0]


def test_a_kernel_cache_without_a_folder_names_the_variables(monkeypatch):
    def no_locator(args, out):
        raise RuntimeError("cannot cache function 'step': no locator available for file '/x/kernels.py'")

    monkeypatch.setattr("passmd.cli.commands.theory.run_theory", no_locator)
    monkeypatch.setenv("XDG_CACHE_HOME", "/nonexistent/file")
    status, out, err = run_main(["theory"])
    assert status == 1 and out == "", err
    assert err.count("\n") == 1 and "cannot cache the compiled simulation kernels" in err
    assert "XDG_CACHE_HOME = /nonexistent/file" in err and "NUMBA_CACHE_DIR" in err
