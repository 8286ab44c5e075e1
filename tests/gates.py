"""Gates for the signal tests: a command stops at a named moment until the test opens the gate.

``python tests/gates.py DIR MOMENTS passmd-arguments...`` runs the command line
(:func:`passmd.cli.main`) with a hook at each moment named in ``MOMENTS`` (comma-separated):

* ``spawn``: in the command, after a process pool forked its first worker (the pool is starting);
* ``worker``: in a worker, before its initializer (:func:`passmd.runtime.pools.worker_signals`) ran
  (it has just been forked);
* ``point``: in a worker, before a sweep point whose ``frequency`` is above ``GATE_ABOVE_HZ``
  (default 0: every point; a point without one, e.g. a fit's parameter set, always) is computed
  (the pool is running);
* ``evaluate``: in the command, before a fit's second model evaluation (its pool is idle
  between two sweeps);
* ``shutdown``: in the command, before a process pool's first shut-down (the pool is stopping);
* ``publish``: in the command, once every output file is written to its temporary name, before
  the first is put in place (:func:`passmd.runtime.outputs.write_files`).

A hook writes the marker ``DIR/<moment>-<pid>`` and waits until the file ``DIR/open`` exists.
The test waits for the markers it needs, sends its signal, then creates ``DIR/open``: the
signal arrives at a state the test observed, whatever the machine's speed or load.
"""

from __future__ import annotations

import concurrent.futures.process as cfp
import os
import sys
import time
from pathlib import Path

GATES = Path(os.environ.get("GATES", "."))


def gate(moment: str) -> None:
    """Mark ``moment`` reached by this process, then wait for the test to open the gates."""
    (GATES / f"{moment}-{os.getpid()}").write_text("")
    while not (GATES / "open").exists():
        time.sleep(0.01)


def reached(directory: Path, moment: str) -> list[int]:
    """The processes that reached ``moment`` (their marker files in ``directory``)."""
    return [int(p.name.rsplit("-", 1)[1]) for p in directory.glob(f"{moment}-*")]


def gated_call(func, point):
    """``passmd.runtime.sweep._call`` with the ``point`` gate (runs in the worker)."""
    if point.get("frequency", float("inf")) > float(os.environ.get("GATE_ABOVE_HZ", "0")):
        gate("point")
    return func(**point)


def _install(moments: set[str]) -> None:
    from passmd.runtime import sweep

    if "spawn" in moments:
        spawn = cfp.ProcessPoolExecutor._spawn_process

        def spawn_then_gate(self):
            spawn(self)
            if len(self._processes) == 1:
                gate("spawn")

        cfp.ProcessPoolExecutor._spawn_process = spawn_then_gate
    if "worker" in moments:
        from passmd.runtime import pools

        initializer = pools.worker_signals

        def gate_then_initialize(*args):
            gate("worker")
            initializer(*args)

        pools.worker_signals = gate_then_initialize
    if "point" in moments:
        sweep._call = gated_call
    if "evaluate" in moments:
        from passmd.protocols.fit import prediction

        evaluate, calls = prediction._Model.evaluate, []

        def gate_then_evaluate(self, xs):
            calls.append(1)
            if len(calls) == 2:
                gate("evaluate")
            return evaluate(self, xs)

        prediction._Model.evaluate = gate_then_evaluate
    if "shutdown" in moments:
        shutdown, done = cfp.ProcessPoolExecutor.shutdown, []

        def gate_then_shutdown(self, *args, **kwargs):
            if not done:
                done.append(1)
                gate("shutdown")
            return shutdown(self, *args, **kwargs)

        cfp.ProcessPoolExecutor.shutdown = gate_then_shutdown
    if "publish" in moments:
        from passmd.runtime import outputs

        outputs._before_linking = lambda: gate("publish")


if __name__ == "__main__":
    GATES = Path(sys.argv[1])
    os.environ["GATES"] = str(GATES)
    _install(set(sys.argv[2].split(",")) - {""})
    from passmd.cli import main

    sys.exit(main(sys.argv[3:]))
