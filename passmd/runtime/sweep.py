"""Parameter sweeps: a grid of independent evaluations, in parallel, cached on disk.

:func:`run` evaluates ``func(**point)`` for every point of a grid and returns a tidy
:class:`pandas.DataFrame` in grid order (point columns, then result columns), whatever
order the points finish in. Execution is

* ``"process"`` (default): a local :class:`concurrent.futures.ProcessPoolExecutor`
  over the usable cores (never more workers than points to compute);
* ``"dask"``: a Dask ``distributed`` cluster — the one at ``scheduler``
  (``"tcp://host:8786"``) if given, else a ``LocalCluster`` on this machine;
* ``"serial"``: in this process, one point after the other;
* or any :class:`concurrent.futures.Executor` the caller owns (not shut down here).

Every finished point is written to the on-disk cache (:mod:`passmd.runtime.cache`) as soon as
it completes, so an interrupted sweep (Ctrl-C, SIGTERM, a failing point, a killed job) keeps
every finished point and a rerun recomputes only the rest. Worker processes never outlive the
sweep: a process pool's workers end when the process that started them dies, even by ``kill -9``
(:func:`passmd.runtime.pools.end_with_parent`), and a local Dask cluster's workers exit with it
(``distributed`` watches their parent). The cache key covers the swept
function's own code too (:func:`passmd.runtime.cache.keys.function_code`): a user's function that
changed between two sweeps is recomputed, and one whose code cannot be fingerprinted is
not cached (one :class:`~passmd.runtime.cache.store.CacheWarning` says why). Progress (points done, ETA;
:mod:`passmd.runtime.progress`) shows once a sweep has run 2 s: by default on a terminal only;
``progress=True`` (the command line) also off a terminal, as a line every few seconds;
off when the run configuration says so (``RunConfig.progress``, off on CI).

How a sweep runs comes from its arguments or the :class:`~passmd.runtime.config.RunConfig` an entry
point passes down; this module reads no environment variable. Without either: a process pool
over all cores and the cache in the user's cache folder
(:func:`passmd.runtime.cache.store.default_cache_dir`).
When the configuration names a ``sweep_log`` file, every sweep appends one JSON line to it
(the function, and how many points were taken from the cache and how many computed): the
book's execution-statistics page sums them per chapter.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import itertools
import logging
import os
import pickle
import sys
import warnings
from collections.abc import Callable, Mapping, Sequence

import pandas as pd

from passmd.runtime import pools
from passmd.runtime.cache import Cache, CacheWarning, Unfingerprintable, function_code, function_name
from passmd.runtime.config import EXECUTORS, MAX_WORKERS, RunConfig, useful_workers
from passmd.runtime.extras import install_hint
from passmd.runtime.progress import bar, in_worker, is_terminal
from passmd.runtime.validation import check_choice

__all__ = ["EXECUTORS", "grid", "process_pool", "progress_enabled", "run", "run_with_hits"]


def grid(**axes) -> list[dict]:
    """All combinations of the given axes, last axis fastest (row-major).

    >>> grid(preload=[0.1, 0.2], contacts=[1, 6])
    [{'preload': 0.1, 'contacts': 1}, {'preload': 0.1, 'contacts': 6}, \
{'preload': 0.2, 'contacts': 1}, {'preload': 0.2, 'contacts': 6}]
    """
    for name, axis in axes.items():
        if isinstance(axis, (str, bytes)) or not hasattr(axis, "__iter__"):
            raise ValueError(f"{name} = {axis!r} is not a sequence of values: give a list of values")
    return [dict(zip(axes, combo, strict=True)) for combo in itertools.product(*map(list, axes.values()))]


def progress_enabled(progress: bool | None = None, stream=None) -> bool:
    """Whether to show progress: ``progress`` if given, else whether ``stream`` is a TTY."""
    if progress is not None:
        return bool(progress)
    return is_terminal(sys.stderr if stream is None else stream)


def _call(func, point):
    """Evaluate one point (runs in the worker)."""
    return func(**point)


def _check_points(points) -> list[dict]:
    if isinstance(points, Mapping) or not isinstance(points, Sequence) or isinstance(points, str):
        raise ValueError(f"points = {points!r} is not a list of dicts (one dict of parameters per point)")
    checked = []
    for i, point in enumerate(points):
        if not isinstance(point, Mapping) or not all(isinstance(k, str) for k in point):
            raise ValueError(f"points[{i}] = {point!r} is not a dict of keyword arguments")
        checked.append(dict(point))
    return checked


def _make_cache(cache) -> Cache | None:
    if cache is True or isinstance(cache, (str, os.PathLike)):
        return Cache(None if cache is True else cache)
    if cache is False or cache is None or isinstance(cache, Cache):
        return cache or None
    raise ValueError(f"cache = {cache!r} is not allowed: must be True, False, a Cache or a directory")


class _NoBar:
    """The progress bar of a sweep that shows none (tqdm is not even imported)."""

    def update(self, n: int = 1) -> None:
        pass

    close = update


class _Collector:
    """Receives finished points: checks the result, caches it, advances the bar."""

    def __init__(self, func, points, keys, cache, bar):
        self.func, self.points, self.keys, self.cache, self.bar = func, points, keys, cache, bar
        self.results: dict[int, dict] = {}

    def done(self, index: int, result) -> None:
        if not isinstance(result, Mapping):
            raise TypeError(
                f"{getattr(self.func, '__qualname__', self.func)} returned {type(result).__name__} "
                f"for points[{index}] = {self.points[index]!r}: it must return a dict"
            )
        result = dict(result)
        clash = sorted(set(result) & set(self.points[index]))
        if clash:
            raise ValueError(
                f"result keys {clash} of points[{index}] clash with parameter names; rename them"
            )
        if self.cache is not None:  # an unwritable cache warns once and the result is kept
            self.cache.put(self.keys[index], result, function=function_name(self.func))
        self.results[index] = result
        self.bar.update(1)


def _annotate(exc: BaseException, index: int, point: dict) -> None:
    if hasattr(exc, "add_note") and not isinstance(exc, KeyboardInterrupt):
        exc.add_note(f"while evaluating sweep points[{index}] = {point!r}")


def _run_serial(func, todo, points, collect: _Collector) -> None:
    for i in todo:
        try:
            result = func(**points[i])
        except BaseException as exc:
            _annotate(exc, i, points[i])
            raise
        collect.done(i, result)


def _harvest(futures: dict, collect: _Collector) -> None:
    """Store every future that finished successfully but was not collected yet."""
    for future, i in futures.items():
        if i in collect.results or not future.done() or future.cancelled():
            continue
        try:
            if future.exception() is None:
                collect.done(i, future.result())
        except Exception:  # a broken result must not hide the original interruption
            continue


def _collect_completed(futures: dict, completed, points, collect: _Collector) -> None:
    """Hand each finished future's result to ``collect`` as ``completed(futures)`` yields it."""
    for future in completed(futures):
        i = futures[future]
        try:
            result = future.result()
        except BaseException as exc:
            _annotate(exc, i, points[i])
            raise
        collect.done(i, result)


def _run_futures(pool: cf.Executor, func, todo, points, collect: _Collector) -> None:
    """Evaluate the points on an executor the caller owns (not shut down here)."""
    futures = {pool.submit(_call, func, points[i]): i for i in todo}
    try:
        _collect_completed(futures, cf.as_completed, points, collect)
    except KeyboardInterrupt:
        _harvest(futures, collect)
        for future in futures:
            future.cancel()
        raise
    except BaseException:
        for future in futures:
            future.cancel()
        cf.wait(futures)  # a failed point: the running ones finish and are cached too
        _harvest(futures, collect)
        raise


def _run_process(func, todo, points, collect: _Collector, workers) -> None:
    """Evaluate the points in a process pool of ``workers`` processes, started and stopped here.

    The pool starts (its workers are forked in ``submit``) and shuts down with SIGINT and
    SIGTERM held back (:func:`passmd.runtime.pools.signals_held`); on Ctrl-C or SIGTERM the
    finished points are kept and the workers terminated at once (running points are not waited
    for); when a point fails, the points still running finish and are cached before its exception
    is raised.
    """
    pool, futures, interrupted = None, {}, False
    try:
        with pools.signals_held():
            pool = cf.ProcessPoolExecutor(max_workers=workers, initializer=pools.worker_signals,
                                          initargs=(os.getpid(),))
            futures = {pool.submit(_call, func, points[i]): i for i in todo}
        try:
            _collect_completed(futures, cf.as_completed, points, collect)
        except KeyboardInterrupt:
            raise
        except BaseException:
            for future in futures:
                future.cancel()
            pool.shutdown(wait=True, cancel_futures=True)  # let running points finish: cached too
            _harvest(futures, collect)
            raise
    except KeyboardInterrupt:
        interrupted = True
        raise
    finally:
        if pool is not None:
            with pools.signals_held():
                if interrupted:
                    _harvest(futures, collect)
                    # Terminating the workers makes the pool fail its pending futures itself.
                    # Cancelling them first races with that: Python 3.11's executor thread then
                    # calls set_exception on a cancelled future and prints an InvalidStateError.
                    pools.stop_workers(pool)
                pool.shutdown(wait=True, cancel_futures=not interrupted)


@contextlib.contextmanager
def process_pool(workers: int | None = None):
    """A process pool for several :func:`run` calls in a row (its workers start once), stopped
    on leaving the block.

    ``workers``: as for :func:`run` (capped at :data:`~passmd.runtime.config.WORKERS_PER_CORE`
    per core). The workers are forked at once, with SIGINT and SIGTERM held back (as in
    :func:`run`'s own pool); on leaving the block on Ctrl-C or SIGTERM they are terminated
    without waiting for their running points, else shut down when idle.
    """
    workers = useful_workers(workers, MAX_WORKERS)
    pool, interrupted = None, False
    try:
        with pools.signals_held():
            pool = cf.ProcessPoolExecutor(max_workers=workers, initializer=pools.worker_signals,
                                          initargs=(os.getpid(),))
            pool.submit(int)  # forks the workers now (the fork start method starts them all at once)
        yield pool
    except KeyboardInterrupt:
        interrupted = True
        raise
    finally:
        if pool is not None:
            with pools.signals_held():
                if interrupted:
                    pools.stop_workers(pool)
                pool.shutdown(wait=True, cancel_futures=True)


def _run_dask(func, todo, points, collect: _Collector, workers, scheduler) -> None:
    """Evaluate the points on the Dask cluster at ``scheduler``, or on a local one started and stopped here.

    A local cluster's event loop is started with SIGINT and SIGTERM held back
    (:func:`passmd.runtime.pools.signals_held`),
    and its worker processes are started from that loop's threads: they keep both blocked, so a
    Ctrl-C to the process group reaches this process only (no traceback from a worker). On Ctrl-C
    or SIGTERM the finished points are kept, the workers killed at once (running points are not
    waited for) and the cluster closed with its loggers silenced (:func:`passmd.runtime.pools.close_dask`).
    """
    try:
        from distributed import Client, LocalCluster, as_completed
    except ImportError as exc:  # pragma: no cover - dask is a declared extra
        raise ImportError(f"executor='dask' needs dask.distributed: {install_hint('dask')}") from exc
    import multiprocessing

    cluster = client = None
    futures, interrupted = {}, False
    if not scheduler:
        pools.start_resource_tracker()
    # the processes already there (the resource tracker, another pool's workers) are not the cluster's
    before = pools.descendants() | {p.pid for p in multiprocessing.active_children()}
    try:
        if not scheduler:
            with pools.signals_held():  # (":0": its HTTP server on a free port, never "port in use")
                cluster = LocalCluster(n_workers=0, threads_per_worker=1, dashboard_address=":0",
                                       silence_logs=logging.ERROR)
            cluster.scale(workers)
        client = Client(scheduler or cluster)
        futures = {client.submit(_call, func, points[i], pure=False): i for i in todo}
        _collect_completed(futures, as_completed, points, collect)
    except KeyboardInterrupt:
        interrupted = True
        _harvest(futures, collect)
        raise
    except BaseException:
        _harvest(futures, collect)
        if client is not None:
            client.cancel(list(futures))
        raise
    finally:
        with pools.signals_held():
            pools.close_dask(client, cluster, interrupted, before)


def run(
    func: Callable[..., Mapping],
    points: Sequence[Mapping],
    *,
    executor: str | cf.Executor | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
    cache: bool | Cache | str | os.PathLike = True,
    progress: bool | None = None,
    description: str | None = None,
    config: RunConfig | None = None,
) -> pd.DataFrame:
    """Evaluate ``func(**point)`` over a grid of points, in parallel and cached.

    Parameters
    ----------
    func : callable
        A top-level (picklable) function taking the points' keys as keyword
        arguments and returning a dict of scalars or small arrays (SI units, keys
        carrying the unit). It must be deterministic: its results are cached.
    points : list of dict
        The grid (see :func:`grid`); each dict is one evaluation's keyword arguments.
    executor : {"process", "serial", "dask"} or concurrent.futures.Executor, optional
        Where to run. ``"dask"`` connects to ``scheduler`` or starts a local cluster.
        Default: the configuration's executor, else ``"dask"`` if a scheduler is known,
        else ``"process"``. A process pool with a single point left to compute evaluates it
        in this process (no pool start-up for one point).
    scheduler : str, optional
        Dask scheduler address, e.g. ``"tcp://10.0.0.5:8786"`` (implies ``"dask"``).
        Default: the configuration's scheduler unless another executor was asked for.
    workers : int, optional
        Worker processes for ``"process"`` and a local Dask cluster (1 to
        :data:`~passmd.runtime.config.MAX_WORKERS`); default the configuration's workers, else
        one per usable core. At most one per point to compute and
        :data:`~passmd.runtime.config.WORKERS_PER_CORE` per core run
        (:func:`~passmd.runtime.config.useful_workers`; a warning says when the cores cap them).
    cache : bool, Cache or path
        ``True`` (default): the cache in the configuration's ``cache_dir``, else in
        the user's cache folder (:func:`passmd.runtime.cache.store.default_cache_dir`); ``False``: no
        caching; a :class:`~passmd.runtime.cache.store.Cache` or a directory to use that one.
    progress : bool, optional
        Progress on stderr once the sweep has run 2 s: True on any stderr (off a terminal a
        line every few seconds), False never; default: the configuration's ``progress``, else
        on a TTY.
    description : str, optional
        Label of the progress bar (default the function's name).
    config : RunConfig, optional
        The run configuration an entry point passed down: its executor, scheduler,
        workers, cache directory and progress fill the arguments above that were left at
        their defaults (explicit arguments win); its ``sweep_log`` receives the sweep's
        record. None: ``RunConfig()`` (process pool over all cores, no log).

    Returns
    -------
    pandas.DataFrame
        One row per point, in the order of ``points``: the point's parameters, then
        the function's results. ``df.attrs["sweep"]`` records how many points were
        taken from the cache and how many were computed (:func:`run_with_hits` also says which).

    Raises
    ------
    KeyboardInterrupt
        On Ctrl-C (or a subclass a SIGTERM handler raises), after cancelling pending points
        and stopping the workers; every point finished so far is in the cache.
    Exception
        The first exception a point raised (with a note naming the point), after the
        points still running finished and were cached.
    """
    return _sweep(func, points, executor, scheduler, workers, cache, progress, description, config)[0]


def run_with_hits(
    func: Callable[..., Mapping],
    points: Sequence[Mapping],
    *,
    executor: str | cf.Executor | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
    cache: bool | Cache | str | os.PathLike = True,
    progress: bool | None = None,
    description: str | None = None,
    config: RunConfig | None = None,
) -> tuple[pd.DataFrame, frozenset[int]]:
    """:func:`run`, and the indices of the points whose results came from the cache (for a caller that
    counts the work a sweep did: the table's ``attrs`` carry only the counts, since pandas copies
    them into every table derived from it)."""
    return _sweep(func, points, executor, scheduler, workers, cache, progress, description, config)


def _sweep(func, points, executor, scheduler, workers, cache, progress, description, config):
    """The body of :func:`run` and :func:`run_with_hits`: (table, indices read from the cache)."""
    config = RunConfig() if config is None else config
    executor, scheduler, workers = _execution(executor, scheduler, workers, config)
    if cache is True and config.cache_dir is not None:
        cache = config.cache_dir
    progress = config.progress if progress is None else progress
    _check_arguments(func, executor, scheduler, workers)
    points = _check_points(points)
    store = _make_cache(cache)
    _check_picklable(func, executor)
    label = description or getattr(func, "__name__", "sweep")
    code = _function_code(store, func, label)
    if code is None:
        store = None
    keys = [store.key(func, p, code=code) for p in points] if store is not None else [None] * len(points)
    cached = _cached(store, func, keys)
    todo = [i for i in range(len(points)) if i not in cached]

    shown = bool(todo) and progress_enabled(progress) and not in_worker()
    points_bar = bar(len(points), initial=len(cached), desc=label, unit="point") if shown else _NoBar()
    collect = _Collector(func, points, keys, store, points_bar)
    try:
        if todo:
            _execute(executor, func, todo, points, collect, workers, scheduler)
    finally:
        points_bar.close()

    results = {**cached, **collect.results}
    frame = pd.DataFrame([{**points[i], **results[i]} for i in range(len(points))])
    frame.attrs["sweep"] = {
        "points": len(points),
        "cached": len(cached),
        "computed": len(collect.results),
        "function": label,
    }
    config.log_sweep(frame.attrs["sweep"])
    return frame, frozenset(cached)


def _check_arguments(func, executor, scheduler, workers) -> None:
    if not isinstance(executor, cf.Executor):
        check_choice("executor", executor, EXECUTORS)
    if not callable(func):
        raise ValueError(f"func = {func!r} is not callable")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or not 1 <= workers <= MAX_WORKERS):
        raise ValueError(f"workers = {workers!r} is out of range: must be an integer from 1 to {MAX_WORKERS}")
    if scheduler is not None and executor != "dask":
        raise ValueError(f"scheduler = {scheduler!r} needs executor='dask', not {executor!r}")


def _check_picklable(func, executor) -> None:
    """A function sent to other processes must pickle; in this process (serial, a thread pool) not."""
    if executor != "serial" and not isinstance(executor, cf.ThreadPoolExecutor):
        try:
            pickle.dumps(func)
        except Exception as exc:
            raise ValueError(
                f"func = {func!r} cannot be sent to worker processes ({exc}); use a top-level "
                "function or executor='serial'"
            ) from exc


def _function_code(store: Cache | None, func, label: str) -> str | None:
    """The fingerprint of ``func``'s own code, or None (with a one-line note) if it has none."""
    if store is None:
        return None
    try:
        return function_code(func)
    except Unfingerprintable as exc:
        warnings.warn(f"sweep {label!r} is not cached: {exc}", CacheWarning, stacklevel=4)  # (run's caller)
        return None


def _cached(store: Cache | None, func, keys) -> dict[int, dict]:
    """The points whose results the cache holds, by index."""
    cached: dict[int, dict] = {}
    if store is not None:
        for i, key in enumerate(keys):
            value = store.get(key, function=function_name(func))
            if isinstance(value, Mapping):
                cached[i] = dict(value)
    return cached


def _execute(executor, func, todo, points, collect: _Collector, workers, scheduler) -> None:
    if isinstance(executor, cf.Executor):
        _run_futures(executor, func, todo, points, collect)
    elif executor == "serial" or (len(todo) == 1 and scheduler is None and executor == "process"):
        _run_serial(func, todo, points, collect)
    elif executor == "process":
        _run_process(func, todo, points, collect, useful_workers(workers, len(todo)))
    else:
        local = None if scheduler else useful_workers(workers, len(todo))
        _run_dask(func, todo, points, collect, local, scheduler)


def _execution(executor, scheduler, workers, config: RunConfig):
    """Fill arguments left at None from the run configuration (explicit arguments win)."""
    if scheduler is None and executor in (None, "dask"):
        scheduler = config.scheduler
    if executor is None:
        executor = config.executor or ("dask" if scheduler else "process")
    if workers is None:
        workers = config.workers
    return executor, scheduler, workers
