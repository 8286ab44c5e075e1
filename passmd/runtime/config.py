"""The run configuration: how a computation runs, never what it computes.

A :class:`RunConfig` travels explicitly from an entry point (the command line, the book,
a test) down to the sweeps and the cache. Environment variables are read once, at the
edge, by :meth:`RunConfig.from_environment`; nothing in the package writes them.
"""

from __future__ import annotations

import json
import os
import re
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from passmd.runtime.validation import InputError

__all__ = ["ENVIRONMENT", "EXECUTORS", "MAX_WORKERS", "PROFILES", "WORKERS_PER_CORE", "RunConfig",
           "WorkersCapped", "usable_cores", "useful_workers"]

#: Resolution profiles: ``quick`` (CI regression tests, minutes for everything) and
#: ``paper`` (the paper's grids, the book's default).
PROFILES = ("quick", "paper")
#: Executors of the sweeps: a process pool, this process, or Dask.
EXECUTORS = ("process", "serial", "dask")

#: Worker counts above this are refused (a typo, not a machine): each worker is a process.
MAX_WORKERS = 1024
#: Workers worth running per usable core: sweep points are CPU-bound, more workers only compete
#: for the cores (and each holds a copy of the simulator in memory).
WORKERS_PER_CORE = 2
_WORKERS_ALLOWED = f"must be an integer from 1 to {MAX_WORKERS}"


class WorkersCapped(UserWarning):
    """More workers were asked for than the machine's cores can use: fewer run (one line)."""


def usable_cores() -> int:
    """The cores this process may run on (its CPU affinity where the system tells it)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def useful_workers(requested: int | None, pending: int) -> int:
    """Worker processes worth starting for ``pending`` points: ``requested`` (default one per
    usable core), at most one per point and :data:`WORKERS_PER_CORE` per core. Capping at the
    cores warns (:class:`WorkersCapped`); capping at the points is silent (nothing is lost)."""
    cores = usable_cores()
    cap = WORKERS_PER_CORE * cores
    count = cores if requested is None else requested
    if count > cap:
        warnings.warn(f"workers = {count} is more than the {cores} usable cores can run: {cap} worker "
                      f"processes run ({WORKERS_PER_CORE} per core)", WorkersCapped, stacklevel=3)
        count = cap
    return max(1, min(count, pending))


#: The environment variables an entry point may read, by field of :class:`RunConfig`.
ENVIRONMENT = {
    "profile": "PASSMD_PROFILE",
    "executor": "PASSMD_EXECUTOR",
    "scheduler": "PASSMD_SCHEDULER",
    "workers": "PASSMD_WORKERS",
    "cache_dir": "PASSMD_CACHE_DIR",
    "sweep_log": "PASSMD_SWEEP_LOG",
    "progress": "CI",
}


@dataclass(frozen=True)
class RunConfig:
    """How to run: resolution profile, parallel executor and result cache.

    Parameters
    ----------
    profile : str
        ``"quick"`` or ``"paper"`` (:data:`PROFILES`): which grids the figures use.
    executor : str or None
        ``"serial"``, ``"process"`` or ``"dask"``; None: ``"dask"`` when a scheduler is
        given, else ``"process"``.
    scheduler : str or None
        Address of a running dask scheduler (``executor="dask"`` only).
    workers : int or None
        Parallel workers, 1 to :data:`MAX_WORKERS`; None: one per usable core. A sweep runs at
        most one per point and :data:`WORKERS_PER_CORE` per core (:func:`useful_workers`).
    cache_dir : Path or None
        Directory of the result cache; None: the user's cache folder
        (:func:`passmd.runtime.cache.store.default_cache_dir`).
    sweep_log : Path or None
        File every sweep appends one JSON line to (points cached and computed; the book's
        execution-statistics page sums them); None: no log.
    progress : bool or None
        Progress bars of the sweeps: None: on a terminal; False: never (``$CI`` set).
    variables : dict
        The environment variable each field was read from (:meth:`from_environment`), so
        that a later error names what the user set; not part of the configuration's value.
    """

    profile: str = "paper"
    executor: str | None = None
    scheduler: str | None = None
    workers: int | None = None
    cache_dir: Path | None = None
    sweep_log: Path | None = None
    progress: bool | None = None
    variables: Mapping[str, str] = field(default_factory=dict, compare=False, repr=False)

    def __post_init__(self):
        if self.profile not in PROFILES:
            raise InputError(f"profile = {self.profile!r} is not allowed: must be one of "
                             f"{', '.join(PROFILES)}", name="profile", value=self.profile)
        if self.executor is not None and self.executor not in EXECUTORS:
            raise InputError(f"executor = {self.executor!r} is not allowed: must be one of "
                             f"{', '.join(map(repr, EXECUTORS))}", name="executor", value=self.executor)
        if self.workers is not None and (isinstance(self.workers, bool) or not isinstance(self.workers, int)
                                         or not 1 <= self.workers <= MAX_WORKERS):
            raise InputError(f"workers = {self.workers!r} is not allowed: {_WORKERS_ALLOWED}",
                             name="workers", value=self.workers)
        if self.cache_dir is not None:
            object.__setattr__(self, "cache_dir", Path(self.cache_dir).expanduser().resolve())
        if self.sweep_log is not None:
            object.__setattr__(self, "sweep_log", Path(self.sweep_log))
        if self.progress is not None and not isinstance(self.progress, bool):
            raise InputError(f"progress = {self.progress!r} is not allowed: must be True, False or None",
                             name="progress", value=self.progress)
        object.__setattr__(self, "variables", dict(self.variables))

    @classmethod
    def from_environment(cls, environ: Mapping[str, str] | None = None, **overrides) -> RunConfig:
        """Read :data:`ENVIRONMENT` once (at an entry point); explicit ``overrides`` win.

        Empty variables count as unset, and so does a variable whose field an override
        gives; ``$CI`` set turns the progress bars off. ``ValueError`` names the variable, its
        value as set and the values it allows.
        """
        environ = os.environ if environ is None else environ
        overrides = {k: v for k, v in overrides.items() if v is not None}
        fields, variables = {}, {}
        for key, name in ENVIRONMENT.items():
            text = (environ.get(name) or "").strip()
            if not text or key in overrides:
                continue
            variables[key] = name
            if key == "workers":
                if not re.fullmatch(r"[0-9]{1,9}", text) or not 1 <= int(text) <= MAX_WORKERS:
                    raise _refused(name, environ.get(name), f"{_WORKERS_ALLOWED} (decimal digits)")
                fields[key] = int(text)
            elif key == "progress":
                fields[key] = False  # continuous integration: no progress bars in the logs
            elif key == "profile" and text not in PROFILES:
                raise _refused(name, environ.get(name), f"must be one of {', '.join(PROFILES)}")
            elif key == "executor" and text not in EXECUTORS:
                raise _refused(name, environ.get(name), f"must be one of {', '.join(EXECUTORS)}")
            else:
                fields[key] = text
        return cls(**fields, **overrides, variables=variables)

    def log_sweep(self, record: Mapping) -> None:
        """Append ``record`` as one JSON line to the ``sweep_log`` file (nothing without one).

        One ``write`` of a short line in append mode: lines of concurrent writers do not mix.
        ``OSError`` names the log as the user set it (the environment variable, if it came
        from one).
        """
        if self.sweep_log is None:
            return
        try:
            with open(self.sweep_log, "a", encoding="utf-8") as fh:
                fh.write(json.dumps(record) + "\n")
        except OSError as exc:
            raise OSError(exc.errno, f"cannot append to the sweep log {self.sweep_log_label}: "
                                     f"{exc.strerror or exc}") from exc

    @property
    def sweep_log_label(self) -> str:
        """The sweep log as the user set it: ``PASSMD_SWEEP_LOG = '…'`` or ``sweep_log = '…'``."""
        return f"{self.variables.get('sweep_log', 'sweep_log')} = {str(self.sweep_log)!r}"


def _refused(name: str, text: str, allowed: str) -> InputError:
    """An environment variable's value refused: its name, the value as set, what it allows."""
    return InputError(f"{name} = {text!r} is not allowed: {allowed}", name=name, value=text)
