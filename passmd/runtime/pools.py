"""Worker processes of a sweep: their signals, their end with the sweep, a Dask cluster's close.

A process pool's workers are started with SIGINT and SIGTERM held back (:func:`signals_held`) and
set their own handlers first (:func:`worker_signals`); each ends when the process that started it
dies, even by ``kill -9`` (:func:`end_with_parent`). A local Dask cluster's workers are killed at
once on an interrupt and the cluster closed quietly (:func:`close_dask`).
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import logging
import os
import signal
import sys

__all__ = ["DASK_CLOSE_TIMEOUT", "PARENT_POLL_S", "close_dask", "descendants", "end_with_parent",
           "signals_held", "start_resource_tracker", "stop_workers", "worker_signals"]


#: The signals a process pool's start and shut-down hold back: delivered right after, in the sweep.
_HELD_SIGNALS = (signal.SIGINT, signal.SIGTERM)


@contextlib.contextmanager
def signals_held():
    """Hold SIGINT and SIGTERM back in this thread while worker processes are forked or stopped.

    A worker forked meanwhile starts with both blocked, so that neither reaches it before its
    initializer (:func:`worker_signals`) has set its own handlers: a Ctrl-C or a SIGTERM to
    the process group while the pool starts never raises inside a worker (a traceback). This
    process receives a signal that came meanwhile as soon as the block ends, where the sweep
    handles it (stopping the workers), never inside the executor's start or shut-down.
    """
    if not hasattr(signal, "pthread_sigmask"):  # pragma: no cover - Windows
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, _HELD_SIGNALS)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def worker_signals(parent: int | None = None):  # pragma: no cover - runs in pool workers
    """Pool worker initializer: Ctrl-C is handled by the parent, which stops the workers; SIGTERM
    (the parent's stop, or a stop of the whole process group) ends a worker at once, whatever
    handler the parent had installed before the fork. Then the signals the parent held back
    while forking (:func:`signals_held`) are let through: a SIGTERM that came meanwhile ends
    the worker silently, a Ctrl-C is dropped. ``parent``: the pid of the process that started
    the pool; the worker ends when that process dies, even by ``kill -9`` (:func:`end_with_parent`)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if parent is not None:
        end_with_parent(parent)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, _HELD_SIGNALS)


#: Linux's prctl option that sends the calling process a signal when its parent dies.
_PR_SET_PDEATHSIG = 1
#: Seconds between two looks at the parent of a worker where the kernel cannot signal its death.
PARENT_POLL_S = 1.0


def end_with_parent(parent: int) -> None:  # pragma: no cover - runs in pool workers
    """End this worker when the process that started its pool (``parent``) dies, even by ``kill -9``.

    On Linux the kernel sends the worker SIGKILL when its own parent dies (prctl
    ``PR_SET_PDEATHSIG``; that parent is ``parent``'s thread that forked it, which lives as long as
    the pool, or a fork server that ends with ``parent``). Elsewhere a daemon thread looks every
    :data:`PARENT_POLL_S` s whether the worker was orphaned (adopted by another process) or
    ``parent`` is gone, and ends the process. A worker orphaned before this call ends at once.
    """
    direct = os.getppid()
    armed = False
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            import ctypes

            armed = ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0
    if (direct == 1 and parent != 1) or os.getppid() != direct:  # orphaned before the signal was armed
        os._exit(1)
    if armed:
        return
    import threading
    import time

    def gone() -> bool:
        try:
            os.kill(parent, 0)
        except ProcessLookupError:
            return True
        except OSError:
            return False
        return os.getppid() != direct

    def watch():
        while not gone():
            time.sleep(PARENT_POLL_S)
        os._exit(1)

    threading.Thread(target=watch, name="passmd-parent-watch", daemon=True).start()


def stop_workers(pool: cf.ProcessPoolExecutor) -> None:
    """Terminate a process pool's workers at once (Ctrl-C must not wait for running points)."""
    terminate = getattr(pool, "terminate_workers", None)  # Python >= 3.14
    if terminate is not None:
        terminate()
        return
    for process in list((getattr(pool, "_processes", None) or {}).values()):
        process.terminate()


def start_resource_tracker() -> None:
    """Start multiprocessing's resource tracker now, from this thread, if it is not running: started
    later from the cluster's event loop, it would unblock SIGINT and SIGTERM in that thread (its
    ``ensure_running`` ends with ``SIG_UNBLOCK``), and the workers started from there would get them."""
    with contextlib.suppress(ImportError, AttributeError, OSError):
        from multiprocessing import resource_tracker

        resource_tracker.ensure_running()


#: Seconds a Dask client and a local cluster get to close after Ctrl-C or SIGTERM.
DASK_CLOSE_TIMEOUT = 2.0


def descendants() -> set[int]:
    """The pids of this process's descendants, read from ``/proc`` (empty where there is none).

    A worker process still being spawned (forked, its interpreter not yet handed its task) is a
    descendant before ``multiprocessing.active_children()`` lists it."""
    parents = {}
    with contextlib.suppress(OSError):
        for entry in os.scandir("/proc"):
            if not entry.name.isdigit():
                continue
            try:
                with open(f"/proc/{entry.name}/stat", "rb") as fh:
                    stat = fh.read()
            except OSError:  # gone meanwhile
                continue
            # "pid (comm) state ppid …": comm may hold spaces and parentheses, so split after the last ")"
            fields = stat[stat.rfind(b")") + 2:].split()
            if len(fields) > 1:
                parents[int(entry.name)] = int(fields[1])
    found, frontier = set(), {os.getpid()}
    while frontier:
        frontier = {pid for pid, parent in parents.items() if parent in frontier} - found
        found |= frontier
    return found


def close_dask(client, cluster, interrupted: bool, before: set) -> None:
    """Close the client, and the local cluster this sweep started; after an interrupt at once and
    quietly: the loggers of ``distributed`` silenced, the processes the cluster started (this
    process's descendants whose pids are not in ``before``, :func:`descendants`) killed first, also
    those still starting, and again once the cluster is closed (its loop may have started one
    meanwhile), the close bounded by :data:`DASK_CLOSE_TIMEOUT`, and the cluster taken off
    ``distributed``'s list of clusters to close at exit (no second close)."""
    import multiprocessing

    if not interrupted:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
        return
    quiet = ("distributed", "tornado", "asyncio")
    # and their children with a level of their own (distributed's logging configuration gives
    # tornado.application ERROR: a worker killed while starting would log "Nanny failed to start")
    for name in [*quiet, *(n for n in list(logging.root.manager.loggerDict) if n.split(".")[0] in quiet)]:
        logging.getLogger(name).setLevel(logging.CRITICAL + 1)

    def kill_workers():
        if cluster is None:
            return
        for process in multiprocessing.active_children():  # reaped by multiprocessing once killed
            if process.pid not in before:
                with contextlib.suppress(Exception):
                    process.kill()
        for pid in descendants() - before:  # also those still being spawned
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGKILL)

    kill_workers()
    for closing in (client, cluster):
        if closing is not None:
            with contextlib.suppress(Exception):
                closing.close(timeout=DASK_CLOSE_TIMEOUT)
    kill_workers()
    with contextlib.suppress(Exception):
        type(cluster)._instances.discard(cluster)
