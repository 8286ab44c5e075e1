"""No silent nonsense: what contradicts itself is refused, what is given is used.

Contract (README, "Reliability"): an input given twice (a drive-file key at the top level and in a
table, a range's N or spacing, a parameter's --bounds) or contradicting another (rigid actuators with
actuator dynamics) is refused with one line naming it, never settled by whichever comes last; an
option or file value the command reads is honoured (a drive file's load cell, a fit's scheduler);
a measurement cell is read as written or refused (``1_20`` is not 120); TOML the package writes
reads back for any string; a stall row never shows a force that reads as a violation of μΣF_N.
Each check runs before any simulation (the work is replaced by a marker where it would start).
"""

from __future__ import annotations

import argparse
import os
import sys

import pytest
from cli_runs import run_main
from hypothesis import given, settings
from hypothesis import strategies as st

from passmd.model.drive_file import drive_toml, load_drive
from passmd.model.parameters import Drive
from passmd.model.tables import Material


class _Reached(BaseException):
    """The work began: every check before it passed (not an Exception: the command's own handlers
    let it through)."""


def _reached(*args, **kwargs):
    raise _Reached()


def _refused(argv, *fragments, status=2):
    code, out, err = run_main(argv)
    assert code == status and out == "", (code, err)
    assert err.count("\n") == 1 and err.startswith("passmd") and "Traceback" not in err, err
    for fragment in fragments:
        assert fragment in err, (fragment, err)
    return err


@pytest.fixture(autouse=True)
def _quiet(monkeypatch):
    monkeypatch.setenv("CI", "true")


# --------------------------------------------------------------------------------------
# drive files
# --------------------------------------------------------------------------------------

@pytest.mark.parametrize(("text", "fragments"), [
    ("preload = 0.4\n[drive]\npreload = 0.6\n", ("preload is given twice", "the top level", "[drive]")),
    ("[actuator]\nmass = 2e-8\n[drive.actuator]\nmass = 3e-8\n", ("actuator.mass is given twice",)),
    ('actuator_model = "rigid"\n[actuator]\nstiffness = "5e6 N/m"\n',
     ('actuator.stiffness contradicts actuator_model = "rigid"',)),
    ('actuator_model = "rigid"\n[actuator]\ndamping_ratio = 0.1\n', ("actuator.damping_ratio contradicts",)),
], ids=["top level and [drive]", "two tables", "rigid with a stiffness", "rigid with a damping ratio"])
def test_a_drive_file_contradicting_itself_is_refused(tmp_path, text, fragments):
    path = tmp_path / "mine.toml"
    path.write_text(text, encoding="utf-8")
    _refused(["drive", "show", "--drive", str(path)], str(path), *fragments)


def test_a_rigid_drive_written_by_the_package_reads_back(tmp_path):
    drive = Drive(contacts=1, actuator_model="rigid")
    path = tmp_path / "rigid.toml"
    path.write_text(drive_toml(drive), encoding="utf-8")
    assert load_drive(path) == drive


@settings(max_examples=int(os.environ.get("PASSMD_FUZZ_EXAMPLES", "250")), deadline=None)
@given(name=st.text(max_size=12))
def test_any_material_name_the_package_writes_reads_back(tmp_path_factory, name):
    """Newlines, quotes, backslashes, DEL and every control character: TOML escapes, not raw."""
    drive = Drive(hemisphere_material=Material(400e9, 0.29, name), runner_material=Material(210e9, 0.3, name))
    path = tmp_path_factory.mktemp("names") / "d.toml"
    path.write_text(drive_toml(drive), encoding="utf-8")
    assert load_drive(path) == drive


@pytest.mark.parametrize(("text", "fragment"), [
    (f"preload = 1{'0' * 400}\n", "preload = 10000000… (401 digits) is out of range"),
    ("preload = " + "[" * 3000 + "]" * 3000 + "\n", "nested too deeply"),
], ids=["10^400", "deeply nested"])
def test_a_drive_file_beyond_numbers_is_bad_input(tmp_path, text, fragment):
    path = tmp_path / "odd.toml"
    path.write_text(text, encoding="utf-8")
    _refused(["drive", "show", "--drive", str(path)], str(path), fragment)


# --------------------------------------------------------------------------------------
# options given twice, or ignored
# --------------------------------------------------------------------------------------

@pytest.mark.parametrize(("spec", "fragment"), [
    ("preload=0.2N..0.8N:2:3", "N is given twice ('2' and '3')"),
    ("preload=0.2N..0.8N:3:log:lin", "spacing is given twice ('log' and 'lin')"),
])
def test_a_range_option_given_twice_is_refused(spec, fragment):
    _refused(["sweep", "velocity", "--vary", spec], f"--vary = {spec!r}", fragment)


def test_bounds_given_twice_are_refused(tmp_path):
    data = tmp_path / "d.csv"
    data.write_text("amplitude_nm,frequency_Hz,step_nm\n100,2000,30\n150,2000,60\n")
    _refused(["fit", str(data), "--free", "mu", "--bounds", "mu=0.1..0.5", "--bounds", "mu=0.2..0.3"],
             "--bounds = 'mu=0.2..0.3' bounds mu again")


def test_run_keeps_the_drive_files_load_cell(tmp_path, monkeypatch):
    from passmd.cli.commands import run

    seen = []
    monkeypatch.setattr(run, "simulate", lambda args, drive, options: seen.append(drive) or _reached())
    path = tmp_path / "lc.toml"
    path.write_text("load_cell = true\nload_cell_stiffness = \"5000 N/m\"\n", encoding="utf-8")
    with pytest.raises(_Reached):
        run_main(["run", "--drive", str(path), "--periods", "1"])
    assert seen[0].load_cell and seen[0].load_cell_stiffness == 5000.0


@pytest.mark.parametrize("argv", [["--load-cell-stiffness", "5000N/m", "--vary", "preload=0.2N,0.4N"],
                                  ["--vary", "load-cell-stiffness=2500N/m,5000N/m"]],
                         ids=["option", "axis"])
def test_a_stall_sweep_takes_the_load_cells_stiffness(monkeypatch, argv):
    """The stall force pushes against the load cell: its stiffness is an input of the sweep."""
    from passmd.protocols import maps

    seen = []
    monkeypatch.setattr(maps, "compute_map", lambda quantity, points, **kw: seen.append(points) or _reached())
    with pytest.raises(_Reached):
        run_main(["sweep", "stall-force", *argv, "--contacts", "1", "--actuator", "rigid"])
    drives = [point["drive"] for point in seen[0]]
    assert all(d.load_cell for d in drives)
    assert {d.load_cell_stiffness for d in drives} <= {2500.0, 5000.0}


def test_a_fit_runs_on_the_scheduler_it_is_given(tmp_path, monkeypatch):
    from passmd.runtime import sweep

    monkeypatch.setattr(sweep, "_run_dask", lambda *args: _reached())
    data = tmp_path / "d.csv"
    data.write_text("amplitude_nm,frequency_Hz,step_nm\n100,2000,30\n150,2000,60\n")
    with pytest.raises(_Reached):
        run_main(["fit", str(data), "--free", "mu", "--contacts", "1", "--actuator", "rigid",
                  "--scheduler", "tcp://127.0.0.1:1", "--cache-dir", str(tmp_path / "cache")])


def test_a_fitted_flyback_time_is_reported_beside_its_rule():
    from passmd.cli.commands.fit import _flyback
    from passmd.model.tables import Amplifier

    drive = Drive(amplifier=Amplifier(slew_rate=100e6, flyback="fixed"))
    result = argparse.Namespace(drive=drive)
    assert _flyback(result, {"mu": "mu"}) == "fixed"
    text = _flyback(result, {"flyback_time": "flyback-time"})
    time = drive.amplifier.peak_to_peak_voltage / 100e6
    assert text == f"fixed with the fitted full-stroke time V_pp/SR = {time * 1e6:g} us", text


def test_a_sweep_prefix_ending_in_a_separator_is_refused(tmp_path):
    (tmp_path / "dir").mkdir()
    _refused(["sweep", "velocity", "--vary", "frequency=1kHz,2kHz", "--out", f"{tmp_path / 'dir'}/"],
             "names a directory, not a PREFIX")


# --------------------------------------------------------------------------------------
# measurement files
# --------------------------------------------------------------------------------------

def test_a_cell_with_an_underscore_is_not_a_number():
    from passmd.protocols import fit

    refused = r"row 1 \(line 2\), column step_nm: '1_20' is not a number"
    with pytest.raises(fit.MeasurementError, match=refused):
        fit.measurements_from_rows(["amplitude_nm", "frequency_Hz", "step_nm"], [["100", "2000", "1_20"]])


def test_a_row_number_counts_measurements_not_blank_lines(tmp_path):
    from passmd.protocols import fit

    path = tmp_path / "d.csv"
    path.write_text("amplitude_nm,frequency_Hz,step_nm,step_nm_sd\n\n\n100,2000,30,1\n150,2000,60,\n")
    with pytest.raises(fit.MeasurementError, match=r"row 2 \(line 5\), column step_nm_sd: missing"):
        fit.read_measurements(path)


def test_position_rows_get_advice_like_every_kind():
    """The documented ``position_nm`` column reaches the verdict (it ended in a KeyError)."""
    from passmd.protocols import fit
    from passmd.protocols.fit.result import _advice

    data = fit.measurements_from_rows(["amplitude_nm", "frequency_Hz", "position_nm", "position_nm_sd"],
                                      [["100", "2000", "50", "1"], ["150", "2000", "90", "1"]])
    assert "the critical amplitude or the stall force" in _advice(data)


# --------------------------------------------------------------------------------------
# the stall force beside its bound
# --------------------------------------------------------------------------------------

def test_no_stall_force_column_reads_as_a_violation_of_the_coulomb_bound():
    """At 1 mN of preload the no-slip reference k·x̄_p is far above μΣF_N: it is named as a
    reference; every force the stall run reports as acting stays within the bound."""
    from passmd.protocols import stall

    drive = Drive(contacts=1, actuator_model="rigid", preload=1e-3)
    out = stall.generated_force(drive, drive.actuator.full_stroke_amplitude, 100.0)
    bound = out["coulomb_bound_N"] + stall.bound_margin(drive)
    acting = {k: v for k, v in out.items() if k.endswith("_force_N") and v is not None
              and k not in ("coulomb_bound_N", "no_slip_reference_force_N")}
    assert "generated_force_N" in acting and "piezo_mean_force_N" not in out
    assert all(abs(v) <= bound for v in acting.values()), (acting, bound)
    assert out["no_slip_reference_force_N"] > out["coulomb_bound_N"]  # what the name must explain


# --------------------------------------------------------------------------------------
# API sweeps
# --------------------------------------------------------------------------------------

_READS_ENVIRONMENT = '''
import os

def point(x):
    return {"y": x * float(os.environ.get("PASSMD_TEST_SCALE", "1"))}
'''


def test_a_sweep_of_code_reading_the_environment_is_not_cached(tmp_path, monkeypatch):
    """The cache key cannot see the environment: such a function is recomputed, with one warning."""
    from passmd.runtime import sweep
    from passmd.runtime.cache import CacheWarning

    (tmp_path / "env_points.py").write_text(_READS_ENVIRONMENT)
    monkeypatch.syspath_prepend(str(tmp_path))
    import env_points

    try:
        monkeypatch.setenv("PASSMD_TEST_SCALE", "1")
        with pytest.warns(CacheWarning, match="reads the environment"):
            first = sweep.run(env_points.point, [{"x": 2.0}], executor="serial", cache=tmp_path / "cache")
        monkeypatch.setenv("PASSMD_TEST_SCALE", "10")
        with pytest.warns(CacheWarning, match="reads the environment"):
            second = sweep.run(env_points.point, [{"x": 2.0}], executor="serial", cache=tmp_path / "cache")
        assert (first["y"][0], second["y"][0]) == (2.0, 20.0)
    finally:
        sys.modules.pop("env_points", None)


def test_a_thread_pool_needs_no_pickling(tmp_path):
    """Threads share the process: a function that cannot be pickled runs on them."""
    from concurrent.futures import ThreadPoolExecutor

    from passmd.runtime import sweep

    offset = 3.0

    def local_point(x):  # a closure: not picklable
        return {"y": x + offset}

    with ThreadPoolExecutor(2) as pool:
        frame = sweep.run(local_point, sweep.grid(x=[1.0, 2.0]), executor=pool, cache=False)
    assert frame["y"].tolist() == [4.0, 5.0]
