"""The run configuration of the commands that run sweeps (``figure``, ``ledger``, ``sweep``, ``fit``).

The environment is read once, here at the edge (:meth:`passmd.runtime.config.RunConfig.from_environment`),
and the command's options replace what it says (a sweep's progress shows on any stderr unless
``$CI`` is set); the resulting :class:`~passmd.runtime.config.RunConfig`
is passed down to the figure table, the ledger and the cache. Nothing is written to the
environment.
"""

from __future__ import annotations

import importlib.util
import os
import stat
import warnings
from dataclasses import replace

from passmd.cli.errors import MissingDependencyError, UsageError
from passmd.runtime.config import MAX_WORKERS, WORKERS_PER_CORE, RunConfig, WorkersCapped, usable_cores
from passmd.runtime.extras import install_hint

__all__ = ["execution_config", "run_config"]


def _require_executor(config: RunConfig) -> None:
    """Dask needs the optional ``distributed`` package: say which extra installs it."""
    if (config.executor == "dask" or (config.executor is None and config.scheduler)) \
            and importlib.util.find_spec("distributed") is None:
        raise MissingDependencyError("the Dask executor needs the 'distributed' package, which is not "
                                     f"installed: {install_hint('dask')}")


def _check_sweep_log(config: RunConfig) -> None:
    """Refuse, before any work, a sweep log that cannot be appended to (names the variable).

    A missing file is fine (the first sweep creates it) if its directory exists and is
    writable; a device is probed with a write of no bytes (``/dev/full`` refuses even that).
    """
    path = config.sweep_log
    if path is None:
        return
    label = config.sweep_log_label
    if path.is_dir():
        raise UsageError(f"{label} is a directory: must name a file the sweeps append a line to")
    parent = path.parent
    if not path.exists():
        if not parent.is_dir():
            raise UsageError(f"{label}: the directory {str(parent)!r} does not exist")
        if not os.access(parent, os.W_OK | os.X_OK):
            raise UsageError(f"{label}: the directory {str(parent)!r} is not writable")
        return
    if not os.access(path, os.W_OK):
        raise UsageError(f"{label} is not writable")
    if stat.S_ISCHR(path.stat().st_mode):
        try:
            fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_NONBLOCK)
            try:
                os.write(fd, b"")
            finally:
                os.close(fd)
        except OSError as exc:
            raise UsageError(f"{label} cannot be written: {exc.strerror or exc}") from exc


def _cap_workers(config: RunConfig, args) -> RunConfig:
    """The workers the configuration asks for, capped at what the usable cores can run, with one
    line naming the option or environment variable as typed."""
    cores = usable_cores()
    useful = WORKERS_PER_CORE * cores
    if config.workers is None or config.workers <= useful:
        return config
    typed = (f"--workers {args.workers}" if getattr(args, "workers", None) is not None
             else f"{config.variables.get('workers', 'workers')} = {config.workers}")
    warnings.warn(f"{typed} is more than the {cores} usable cores can run: {useful} worker processes run "
                  f"({WORKERS_PER_CORE} per core)", WorkersCapped, stacklevel=2)
    return replace(config, workers=useful)


def execution_config(args) -> RunConfig:
    """The environment's run configuration, replaced by the command's sweep options (--executor,
    --scheduler, --workers, --cache-dir, and --profile where the command has it).

    ``--workers`` (and ``PASSMD_WORKERS``) above :data:`~passmd.runtime.config.MAX_WORKERS` is
    refused; above what the usable cores can run it is capped, with a one-line warning.
    """
    if args.workers is not None and not 1 <= args.workers <= MAX_WORKERS:
        raise UsageError(f"--workers = {args.workers} is out of range: must be an integer from 1 to "
                         f"{MAX_WORKERS}")
    if args.cache_dir is not None and not args.cache_dir.strip():
        raise UsageError(f"--cache-dir = {args.cache_dir!r} is not a directory name")
    config = RunConfig.from_environment(profile=getattr(args, "profile", None), executor=args.executor,
                                        scheduler=args.scheduler, workers=args.workers,
                                        cache_dir=args.cache_dir)
    _require_executor(config)
    return _cap_workers(config, args)


def run_config(args) -> RunConfig:
    """The environment's run configuration, replaced by the options ``figure``/``ledger``/``sweep``
    were given (:func:`execution_config`); a sweep's progress shows on any stderr unless ``$CI``."""
    config = execution_config(args)
    _check_sweep_log(config)
    if config.progress is None:  # a command shows a long sweep's progress off a terminal too ($CI: never)
        config = replace(config, progress=True)
    return config
