"""A sweep's worker processes never outlive it, and Ctrl-C ends a Dask sweep at once.

Contract (README, "Reliability"): Ctrl-C ends a sweep with exit status 130 and the one line
"interrupted" — under the Dask executor too, within seconds, with no log or traceback of the
cluster's; and when the sweep's main process dies, even by ``kill -9`` (which it cannot
handle), its worker processes end by themselves (process pool: the kernel's parent-death signal;
Dask: ``distributed`` watches the parent).

The sweep is a stand-in ``figure`` whose points announce themselves with a marker file and then
sleep: the test signals once every worker is inside a point (never sleep-and-hope), and a point
never finishes by itself, so only the signal can end the command.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest
from test_outputs_safety import _alive, _descendants  # (a zombie counts as ended)

#: Hang detector: how long a marker may take to appear (a local Dask cluster starts in seconds).
HANG_S = 120
#: The contract's limits: Ctrl-C ends a Dask sweep within 5 s, a dead sweep's workers end within 10 s.
CTRL_C_S = 5.0
ORPHANS_S = 10.0

_RUNNER = textwrap.dedent("""
    import sys, types
    from passmd.experiments import figure_table
    from passmd.runtime import sweep
    from passmd.cli import main
    import slow_points

    def figure_data(name, config):
        return sweep.run(slow_points.point, sweep.grid(x=[1, 2, 3, 4]), config=config)

    figure_table.figure_names = lambda: ["fig99z"]
    figure_table.figure_spec = lambda name: types.SimpleNamespace(name=name, title="stand-in")
    figure_table.figure_data = figure_data
    sys.exit(main(sys.argv[1:]))
""")

_SLOW_POINTS = textwrap.dedent("""
    import os, time
    from pathlib import Path

    def point(x):
        Path(MARKERS, f"{x}-{os.getpid()}").write_text("")
        time.sleep(600)
        return {"y": x}
""")


def _default_signals():  # a test runner started as a background job ignores SIGINT
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


@contextlib.contextmanager
def _sweep_inside_points(tmp_path, executor: str, moment: str = "points running"):
    """The stand-in figure sweeping four slow points on two workers, returned once both are inside
    a point (``moment`` "points running") or once its two worker processes exist ("workers
    starting": a Dask worker is still starting its interpreter, or already waiting for work); its
    process group is killed at the end whatever happened."""
    code, markers = tmp_path / "code", tmp_path / "markers"
    code.mkdir()
    markers.mkdir()
    # the markers' folder written into the code: a point reading the environment is not cached
    (code / "slow_points.py").write_text(f"MARKERS = {str(markers)!r}\n" + _SLOW_POINTS)
    env = {k: v for k, v in os.environ.items() if not k.startswith("PASSMD_")}
    env.update(MPLBACKEND="Agg", CI="true", PASSMD_CACHE_DIR=str(tmp_path / "cache"),
               PYTHONPATH=os.pathsep.join([str(code), env.get("PYTHONPATH", "")]).rstrip(os.pathsep))
    argv = [sys.executable, "-c", _RUNNER, "figure", "fig99z", "--executor", executor, "--workers", "2",
            "--out", str(tmp_path / "out")]
    proc = subprocess.Popen(argv, cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, preexec_fn=_default_signals, start_new_session=True)
    try:
        deadline = time.monotonic() + HANG_S
        while (len(list(markers.iterdir())) < 2 if moment == "points running"
               else len(_descendants(proc.pid)) < 2):
            assert time.monotonic() < deadline and proc.poll() is None, proc.poll() is not None and \
                proc.communicate()
            time.sleep(0.05)
        yield proc, {int(p.name.split("-")[1]) for p in markers.iterdir()}
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()


@pytest.mark.parametrize("moment", ["workers starting", "points running"])
def test_ctrl_c_ends_a_dask_sweep_within_seconds_in_one_line(tmp_path, moment):
    """Ctrl-C (SIGINT to the process group, as a terminal sends it) while the local cluster's
    workers start, or while both run a point: exit 130 within 5 s, the one line "interrupted" (no
    traceback of a starting worker, no log of the cluster's), and no process of the cluster left."""
    with _sweep_inside_points(tmp_path, "dask", moment) as (proc, workers):
        started = _descendants(proc.pid)
        assert workers <= started
        os.killpg(proc.pid, signal.SIGINT)
        sent = time.monotonic()
        out, err = proc.communicate(timeout=HANG_S)
        took = time.monotonic() - sent
        assert (proc.returncode, out) == (130, ""), err
        assert err == "passmd figure: interrupted (finished points are kept in the cache)\n"
        assert took < CTRL_C_S, f"Ctrl-C took {took:.1f} s"
        deadline = time.monotonic() + ORPHANS_S
        while any(_alive(pid) for pid in started):
            assert time.monotonic() < deadline, f"processes {started} of the cluster still run"
            time.sleep(0.1)


@pytest.mark.parametrize("executor", ["process", "dask"])
def test_workers_end_when_the_sweep_is_killed(tmp_path, executor):
    """``kill -9`` of the sweep's main process while its workers run a point: every process it
    started has ended within 10 s."""
    with _sweep_inside_points(tmp_path, executor) as (proc, workers):
        started = _descendants(proc.pid)
        assert workers <= started
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=HANG_S)
        deadline = time.monotonic() + ORPHANS_S
        while any(_alive(pid) for pid in started):
            assert time.monotonic() < deadline, \
                f"processes {sorted(p for p in started if _alive(p))} outlived the sweep by {ORPHANS_S} s"
            time.sleep(0.1)


def test_an_interrupted_dask_close_silences_every_logger_of_the_cluster():
    """After an interrupt the cluster closes without a log line, also from loggers with a level of
    their own: distributed configures tornado.application at ERROR, whose "Nanny failed to start"
    (a worker killed while starting) setting the parent tornado logger alone lets through."""
    import logging

    pytest.importorskip("distributed")
    from passmd.runtime import pools

    quiet = ("distributed", "tornado", "asyncio")
    names = [*quiet, *(n for n in list(logging.root.manager.loggerDict) if n.split(".")[0] in quiet)]
    levels = {n: logging.getLogger(n).level for n in names}
    try:
        assert logging.getLogger("tornado.application").isEnabledFor(logging.ERROR)  # what would print
        pools.close_dask(None, None, True, set())
        assert not any(logging.getLogger(n).isEnabledFor(logging.CRITICAL) for n in names)
    finally:
        for n, level in levels.items():
            logging.getLogger(n).setLevel(level)
