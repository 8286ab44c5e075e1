"""Sweep engine (passmd.runtime.sweep): executors agree, grid order, caching, interruption and resume.

The point functions live at module level so worker processes can unpickle them.
Results of the same deterministic function must be *identical* across executors
(same code, same inputs, same floating-point operations), so frames are compared
exactly (check_exact), not within a tolerance.
"""

import concurrent.futures as cf
import json
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from sweep_points import drive_theory_point, sawtooth_point

from passmd.model.parameters import Drive
from passmd.model.theory import contact_moduli, drive_theory
from passmd.runtime import sweep
from passmd.runtime.cache import Cache
from passmd.runtime.config import RunConfig


def logged_square(x, log):
    """x² + 1, appending x to a log file so that tests can count evaluations."""
    with open(log, "a") as fh:
        fh.write(f"{x!r}\n")
    return {"y": x * x + 1.0}


def slow_first(x, n):
    """Earlier points take longer, so that they finish last in a pool."""
    time.sleep(0.05 * (n - x))
    return {"y": 10 * x}


def interrupt_once(x, log, stop_at, flag):
    """Like logged_square, but raises KeyboardInterrupt (Ctrl-C) at x == stop_at the first time."""
    if x == stop_at and not Path(flag).exists():
        Path(flag).touch()
        raise KeyboardInterrupt
    return logged_square(x, log)


def fail_at(x, bad):
    if x == bad:
        raise ValueError(f"x = {x} is out of range")
    return {"y": x}


def not_a_dict(x):
    return x


def clashing(x):
    return {"x": 2 * x}


def evaluations(log: Path) -> list[float]:
    return [float(line) for line in log.read_text().split()] if log.exists() else []


@pytest.fixture
def store(tmp_path):
    return Cache(tmp_path / "cache")


THEORY_GRID = sweep.grid(
    preload=[0.1, 0.4, 0.7], contacts=[1, 6], actuator_model=["rigid", "flexible"]
)


@pytest.fixture(scope="module")
def serial_theory():
    return sweep.run(drive_theory_point, THEORY_GRID, executor="serial", cache=False)


def test_grid_is_row_major():
    points = sweep.grid(a=[1, 2], b=["x", "y", "z"])
    assert points[:4] == [{"a": 1, "b": "x"}, {"a": 1, "b": "y"}, {"a": 1, "b": "z"}, {"a": 2, "b": "x"}]
    assert len(points) == 6
    with pytest.raises(ValueError, match="a = 0.5 is not a sequence"):
        sweep.grid(a=0.5)


def test_serial_matches_python_api(serial_theory):
    assert list(serial_theory.columns[:3]) == ["preload", "contacts", "actuator_model"]
    assert len(serial_theory) == len(THEORY_GRID)
    for point, (_, row) in zip(THEORY_GRID, serial_theory.iterrows(), strict=True):
        expected = drive_theory(Drive(**point))
        assert row["analytic_critical_amplitude_m"] == expected["analytic_critical_amplitude_m"]
        assert row["presliding_m"] == expected["presliding_m"]


def test_process_pool_identical_to_serial(serial_theory, store):
    frame = sweep.run(drive_theory_point, THEORY_GRID, executor="process", workers=2, cache=store)
    pd.testing.assert_frame_equal(frame, serial_theory, check_exact=True)
    assert frame.attrs["sweep"]["computed"] == len(THEORY_GRID)
    again = sweep.run(drive_theory_point, THEORY_GRID, executor="process", workers=2, cache=store)
    pd.testing.assert_frame_equal(again, serial_theory, check_exact=True)
    assert again.attrs["sweep"] == {**frame.attrs["sweep"], "cached": len(THEORY_GRID), "computed": 0}


def test_sweep_log_records_cached_and_computed_points(store, tmp_path):
    # The book's execution-statistics page sums these lines per chapter.
    log = tmp_path / "sweeps.jsonl"
    config = RunConfig(sweep_log=log)
    sweep.run(drive_theory_point, THEORY_GRID[:3], executor="serial", cache=store, config=config)
    sweep.run(drive_theory_point, THEORY_GRID[:4], executor="serial", cache=store, config=config)
    lines = [json.loads(line) for line in log.read_text().splitlines()]
    assert [(r["cached"], r["computed"], r["points"]) for r in lines] == [(0, 3, 3), (3, 1, 4)]
    assert lines[0]["function"] == "drive_theory_point"
    sweep.run(drive_theory_point, THEORY_GRID[:1], executor="serial", cache=store)
    sweep.run(drive_theory_point, THEORY_GRID[:1], executor="serial", cache=store, config=RunConfig())
    assert len(log.read_text().splitlines()) == 2  # no sweep_log: nothing written


def test_dask_local_cluster_identical_to_serial(serial_theory):
    """Dask LocalCluster with 2 worker *processes* (processes=True; starts in ~2 s here)."""
    frame = sweep.run(drive_theory_point, THEORY_GRID, executor="dask", workers=2, cache=False)
    pd.testing.assert_frame_equal(frame, serial_theory, check_exact=True)


def test_dask_scheduler_address(serial_theory):
    """An existing cluster reached by its address (threads-only cluster: light on 2 cores)."""
    from distributed import LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None) as cluster:
        frame = sweep.run(drive_theory_point, THEORY_GRID, scheduler=cluster.scheduler_address,
                          cache=False)
    pd.testing.assert_frame_equal(frame, serial_theory, check_exact=True)


def contact_path_point(normal_force, springs):
    """Forces of one MDR contact along a fixed path (a small-array result)."""
    from passmd.model.mdr_contact import MDRContact

    path = np.array([0.0, 30e-9, -10e-9, 45e-9, 5e-9])
    E_star, G_star = contact_moduli(Drive())
    return {"force_N": MDRContact(normal_force, 1e-3, E_star, G_star, 0.2, springs=springs).path(path)}


def test_simulations_and_arrays_identical_across_executors():
    """numba kernels in worker processes give bit-identical results to this process."""
    drive = Drive(contacts=1, actuator_model="rigid")
    runs = [{"drive": drive, "amplitude": a, "frequency": 100.0, "periods": 2} for a in (50e-9, 120e-9)]
    serial = sweep.run(sawtooth_point, runs, executor="serial", cache=False)
    pooled = sweep.run(sawtooth_point, runs, executor="process", workers=2, cache=False)
    pd.testing.assert_frame_equal(pooled, serial, check_exact=True)
    assert serial["mean_step_m"].iloc[1] > serial["mean_step_m"].iloc[0]

    paths = sweep.grid(normal_force=[0.2, 0.4], springs=[None, 100])
    serial = sweep.run(contact_path_point, paths, executor="serial", cache=False)
    for executor in ("process", "dask"):
        other = sweep.run(contact_path_point, paths, executor=executor, workers=2, cache=False)
        for a, b in zip(serial["force_N"], other["force_N"], strict=True):
            np.testing.assert_array_equal(a, b)


def test_caller_owned_executor(serial_theory):
    with cf.ThreadPoolExecutor(max_workers=2) as pool:
        frame = sweep.run(drive_theory_point, THEORY_GRID, executor=pool, cache=False)
        assert pool.submit(int, "3").result() == 3  # not shut down by run()
    pd.testing.assert_frame_equal(frame, serial_theory, check_exact=True)


def test_grid_order_regardless_of_completion_order():
    n = 6
    points = [{"x": x, "n": n} for x in range(n)]
    frame = sweep.run(slow_first, points, executor="process", workers=2, cache=False)
    assert frame["x"].tolist() == list(range(n))
    assert frame["y"].tolist() == [10 * x for x in range(n)]


def test_cache_skips_finished_points(tmp_path, store):
    log = tmp_path / "log.txt"
    points = [{"x": float(x), "log": str(log)} for x in range(5)]
    first = sweep.run(logged_square, points[:3], executor="serial", cache=store)
    assert evaluations(log) == [0.0, 1.0, 2.0]
    full = sweep.run(logged_square, points, executor="process", workers=2, cache=store)
    assert sorted(evaluations(log)) == [0.0, 1.0, 2.0, 3.0, 4.0]  # only the two new points ran
    assert full["y"].tolist() == [1.0, 2.0, 5.0, 10.0, 17.0]
    pd.testing.assert_frame_equal(full.iloc[:3], first)
    sweep.run(logged_square, points, executor="serial", cache=False)  # no cache: all recomputed
    assert len(evaluations(log)) == 10


def test_run_with_hits_names_the_points_read_from_the_cache(tmp_path, store):
    """The indices of the cached points, exactly; the table is run's, its attrs without them."""
    log = tmp_path / "log.txt"
    points = [{"x": float(x), "log": str(log)} for x in range(5)]
    sweep.run(logged_square, [points[1], points[3]], executor="serial", cache=store)
    frame, hits = sweep.run_with_hits(logged_square, points, executor="process", workers=2, cache=store)
    assert hits == {1, 3} and sorted(evaluations(log)) == [0.0, 1.0, 2.0, 3.0, 4.0]
    pd.testing.assert_frame_equal(frame, sweep.run(logged_square, points, executor="serial", cache=store))
    assert set(frame.attrs) == {"sweep"}
    assert sweep.run_with_hits(logged_square, points, executor="serial", cache=False)[1] == frozenset()


def test_interrupted_serial_sweep_resumes(tmp_path, store):
    log, flag = tmp_path / "log.txt", tmp_path / "interrupted"
    points = [{"x": float(x), "log": str(log), "stop_at": 3.0, "flag": str(flag)} for x in range(6)]
    with pytest.raises(KeyboardInterrupt):
        sweep.run(interrupt_once, points, executor="serial", cache=store)
    assert evaluations(log) == [0.0, 1.0, 2.0]
    assert len(store.entries()) == 3  # every finished point was cached
    frame = sweep.run(interrupt_once, points, executor="serial", cache=store)
    assert evaluations(log) == [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]  # resumed: no point computed twice
    assert frame["y"].tolist() == [x * x + 1.0 for x in range(6)]
    assert frame.attrs["sweep"]["cached"] == 3


def test_interrupted_process_sweep_resumes(tmp_path, store):
    """With a pool, which points finished before the interrupt is timing-dependent; the
    invariant is that the rerun computes exactly the points not in the cache."""
    log, flag = tmp_path / "log.txt", tmp_path / "interrupted"
    points = [{"x": float(x), "log": str(log), "stop_at": 2.0, "flag": str(flag)} for x in range(8)]
    with pytest.raises(KeyboardInterrupt):
        sweep.run(interrupt_once, points, executor="process", workers=2, cache=store)
    cached = {i for i, p in enumerate(points) if store.key(interrupt_once, p) in store}
    assert 2 not in cached
    before = len(evaluations(log))
    frame = sweep.run(interrupt_once, points, executor="process", workers=2, cache=store)
    rerun = evaluations(log)[before:]
    assert sorted(rerun) == sorted(points[i]["x"] for i in range(8) if i not in cached)
    assert frame["y"].tolist() == [x * x + 1.0 for x in range(8)]
    assert frame.attrs["sweep"]["cached"] == len(cached)


@pytest.mark.parametrize("executor", ["serial", "process"])
def test_failing_point_raises_and_keeps_finished_points(executor, store):
    points = [{"x": x, "bad": 3} for x in range(6)]
    with pytest.raises(ValueError, match="x = 3 is out of range") as info:
        sweep.run(fail_at, points, executor=executor, workers=2, cache=store)
    assert any("points[3]" in note for note in getattr(info.value, "__notes__", []))
    cached = [i for i, p in enumerate(points) if store.key(fail_at, p) in store]
    assert 3 not in cached
    if executor == "serial":
        assert cached == [0, 1, 2]


def test_bad_arguments(store):
    points = [{"x": 1}]
    with pytest.raises(ValueError, match="executor = 'threads' is not allowed"):
        sweep.run(fail_at, points, executor="threads")
    with pytest.raises(ValueError, match="is not a list of dicts"):
        sweep.run(fail_at, {"x": 1})
    with pytest.raises(ValueError, match=r"points\[1\] = 3 is not a dict"):
        sweep.run(fail_at, [{"x": 1}, 3])
    with pytest.raises(ValueError, match="workers = 0 is out of range"):
        sweep.run(fail_at, points, workers=0)
    with pytest.raises(ValueError, match="cannot be sent to worker processes"):
        sweep.run(lambda x: {"y": x}, points, executor="process", cache=False)
    with pytest.raises(ValueError, match="needs executor='dask'"):
        sweep.run(fail_at, points, executor="serial", scheduler="tcp://localhost:1")
    with pytest.raises(TypeError, match="it must return a dict"):
        sweep.run(not_a_dict, points, executor="serial", cache=store)
    with pytest.raises(ValueError, match="clash with parameter names"):
        sweep.run(clashing, points, executor="serial", cache=False)


def test_run_configuration_fills_the_defaults(tmp_path):
    """The RunConfig's executor / workers / scheduler / cache fill arguments left at None."""
    double = lambda x: {"y": 2 * x}  # noqa: E731 - not picklable: only the serial executor can run it
    assert sweep.run(double, [{"x": 1}, {"x": 2}], cache=False,
                     config=RunConfig(executor="serial"))["y"].tolist() == [2, 4]
    with pytest.raises(ValueError, match="executor = 'threads' is not allowed"):
        sweep.run(double, [{"x": 1}], cache=False, config=RunConfig(executor="threads"))
    config = RunConfig(executor="serial", cache_dir=tmp_path / "configured")
    sweep.run(drive_theory_point, THEORY_GRID[:2], config=config)
    assert len(Cache(tmp_path / "configured").entries()) == 2
    # an explicit executor wins over the configuration's scheduler
    with_scheduler = RunConfig(scheduler="tcp://127.0.0.1:1")
    assert sweep.run(double, [{"x": 3}], executor="serial", cache=False,
                     config=with_scheduler)["y"].tolist() == [6]
    with pytest.raises(ValueError, match="needs executor='dask'"):
        sweep.run(fail_at, [{"x": 1, "bad": 0}], executor="process", scheduler="tcp://127.0.0.1:1")


def test_the_environment_does_not_steer_a_sweep(tmp_path, monkeypatch):
    """Only entry points read PASSMD_*: a sweep without a configuration runs with the defaults."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.setenv("PASSMD_EXECUTOR", "threads")
    monkeypatch.setenv("PASSMD_WORKERS", "two")
    monkeypatch.setenv("PASSMD_CACHE_DIR", str(tmp_path / "elsewhere"))
    monkeypatch.setenv("PASSMD_SWEEP_LOG", str(tmp_path / "log.jsonl"))
    frame = sweep.run(drive_theory_point, THEORY_GRID[:2], executor="serial")
    assert frame.attrs["sweep"]["computed"] == 2
    assert len(Cache(tmp_path / "xdg" / "passmd" / "results").entries()) == 2  # the user cache folder
    assert sorted(p.name for p in tmp_path.iterdir()) == ["xdg"]  # nothing in the working folder


def test_lambda_runs_serially_without_cache():
    frame = sweep.run(lambda x: {"y": 2 * x}, [{"x": 1}, {"x": 2}], executor="serial", cache=False)
    assert frame["y"].tolist() == [2, 4]


def test_progress_quiet_off_tty_and_in_ci():
    class Tty:
        def isatty(self):
            return True

    assert sweep.progress_enabled(None, Tty())
    assert not sweep.progress_enabled(None, object())
    assert sweep.progress_enabled(True, object())
    assert not sweep.progress_enabled(False, Tty())
    # $CI reaches the sweeps through the entry point's run configuration
    assert RunConfig.from_environment({"CI": "true"}).progress is False
    assert RunConfig.from_environment({}).progress is None


SIGINT_SCRIPT = """
import sys, time
from passmd.runtime import sweep
from passmd.runtime.cache import Cache


def slow(x, log):
    with open(log, "a") as fh:
        fh.write(f"{x}\\n")
    time.sleep(0.4)
    return {"y": x + 0.5}


if __name__ == "__main__":
    cache_dir, log = sys.argv[1], sys.argv[2]
    points = [{"x": x, "log": log} for x in range(int(sys.argv[3]))]
    try:
        frame = sweep.run(slow, points, executor="process", workers=2, cache=Cache(cache_dir))
    except KeyboardInterrupt:
        print("interrupted", flush=True)
        sys.exit(130)
    print(frame.attrs["sweep"]["computed"], flush=True)
"""


def test_ctrl_c_stops_a_process_pool_sweep_and_rerun_resumes(tmp_path):
    """A real SIGINT to the whole process group, as a terminal's Ctrl-C sends it."""
    import os
    import signal
    import subprocess
    import sys

    script, log, cache_dir = tmp_path / "sweep_script.py", tmp_path / "log.txt", tmp_path / "cache"
    script.write_text(SIGINT_SCRIPT)
    n = 20
    cmd = [sys.executable, str(script), str(cache_dir), str(log), str(n)]
    # the default SIGINT, as under a terminal (a background job inherits an ignored one)
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    store = Cache(cache_dir)
    deadline = time.monotonic() + 60
    while len(store.entries()) < 2 and time.monotonic() < deadline:
        time.sleep(0.05)
    assert len(store.entries()) >= 2, "the sweep did not get going"
    os.killpg(proc.pid, signal.SIGINT)
    out, err = proc.communicate(timeout=30)  # stops promptly: pending points are cancelled
    assert proc.returncode == 130, err
    assert out.strip() == "interrupted"
    assert "Traceback" not in err
    finished = len(store.entries())
    assert 2 <= finished < n
    assert not list(cache_dir.glob("??/*.tmp"))  # no half-written entry
    started = len(evaluations(log))

    done = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert int(done.stdout) == n - finished  # the rerun computed only the missing points
    assert len(evaluations(log)) == started + n - finished
    assert len(store.entries()) == n


# --------------------------------------------------------------------------------------
# Design maps (passmd.protocols.maps): the protocols' quantities through the sweep engine
# --------------------------------------------------------------------------------------


def test_compute_map_keeps_grid_order_and_the_caller_s_columns(store):
    from passmd.protocols.maps import compute_map, critical_amplitude_point, steady_point

    drive = Drive(contacts=1, actuator_model="rigid")
    points = [{"drive": drive, "frequency": f, "amplitude": a, "f_kHz": f / 1e3, "a_nm": a * 1e9}
              for f in (1e3, 2e3) for a in (100e-9, 150e-9)]
    config = RunConfig(executor="serial", cache_dir=store.directory, progress=False)
    table = compute_map("velocity", points, config=config)
    assert list(table.columns[:2]) == ["f_kHz", "a_nm"] and "drive" not in table.columns
    assert table["f_kHz"].tolist() == [1.0, 1.0, 2.0, 2.0] and table["a_nm"].tolist() == pytest.approx(
        [100.0, 150.0, 100.0, 150.0])
    for row, point in zip(table.itertuples(), points, strict=True):
        expected = steady_point(drive, point["amplitude"], point["frequency"])
        assert row.velocity_m_per_s == expected["velocity_m_per_s"]
    # step and back-step are columns of the same runs: every point from the cache
    assert compute_map("step", points, config=config).attrs["sweep"]["cached"] == 4
    # the critical amplitude searches over the amplitude: a point without one is its input
    ac = compute_map("critical-amplitude", [{"drive": drive, "frequency": 100.0}], reading="first",
                     config=config)
    expected = critical_amplitude_point(drive, 100.0, "first")
    assert ac["critical_amplitude_m"].iloc[0] == expected["critical_amplitude_m"]
    with pytest.raises(ValueError, match=r"points\[0\] has no 'amplitude': a velocity map needs"):
        compute_map("velocity", [{"drive": drive, "frequency": 1e3}], config=config)
    with pytest.raises(ValueError, match="quantity = 'speed' is not allowed"):
        compute_map("speed", points, config=config)


def test_map_figure_draws_a_heat_map_with_contours_and_a_curve():
    from passmd.plots.sweep_map import MapAxis, map_figure

    f, a = np.meshgrid([1e3, 1e4, 1e5], [50e-9, 100e-9, 150e-9, 200e-9], indexing="ij")
    v = (a * 1e9 - 60) * np.log10(f) * 1e-5  # changes sign: a diverging scale centred on zero
    table = pd.DataFrame({"frequency_Hz": f.ravel(), "amplitude_m": a.ravel(), "velocity_m_per_s": v.ravel()})
    axes = [MapAxis("frequency_Hz", "frequency", "kHz", log=True), MapAxis("amplitude_m", "amplitude", "nm")]
    fig = map_figure(table, axes, MapAxis("velocity_m_per_s", "velocity", "mm/s"), "title")
    ax = fig.axes[0]
    mesh = ax.collections[0]
    # a sign change: a diverging scale symmetric about zero (a small value of either sign stays pale)
    assert ax.get_xscale() == "log" and mesh.norm.vmin == -mesh.norm.vmax == -np.abs(v).max() * 1e3
    assert mesh.get_array().reshape(4, 3)[2, 1] == pytest.approx(v[1, 2] * 1e3)  # (amplitude, frequency) cell
    assert len(ax.collections) > 1  # contour lines
    curve = map_figure(table.iloc[:3].assign(frequency_Hz=[1e3, 1e4, 1e5]), axes[:1],
                       MapAxis("velocity_m_per_s", "velocity", "mm/s"), "curve")
    assert len(curve.axes[0].lines) == 2  # the points, and a faint line joining them
    with pytest.raises(ValueError, match="a map draws one or two"):
        map_figure(table, axes * 2, MapAxis("velocity_m_per_s", "velocity", "mm/s"), "t")
