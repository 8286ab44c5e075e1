"""The run configuration: how a computation runs, never what it computes.

A :class:`RunConfig` travels explicitly from an entry point (the command line, the book,
a test) down to the sweeps and the cache. Environment variables are read once, at the
edge, by :meth:`RunConfig.from_environment`; nothing in the package writes them.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

__all__ = ["ENVIRONMENT", "PROFILES", "RunConfig"]

#: Resolution profiles: ``quick`` (CI regression tests, minutes for everything) and
#: ``paper`` (the paper's grids, the book's default).
PROFILES = ("quick", "paper")

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
        Parallel workers; None: one per CPU.
    cache_dir : Path or None
        Directory of the result cache; None: ``./.passmd-cache``.
    sweep_log : Path or None
        File every sweep appends one JSON line to (points cached and computed; the book's
        execution-statistics page sums them); None: no log.
    progress : bool or None
        Progress bars of the sweeps: None: on a terminal; False: never (``$CI`` set).
    """

    profile: str = "paper"
    executor: str | None = None
    scheduler: str | None = None
    workers: int | None = None
    cache_dir: Path | None = None
    sweep_log: Path | None = None
    progress: bool | None = None

    def __post_init__(self):
        if self.profile not in PROFILES:
            raise ValueError(f"profile = {self.profile!r} is not allowed: must be one of "
                             f"{', '.join(PROFILES)}")
        if self.workers is not None and (isinstance(self.workers, bool) or not isinstance(self.workers, int)
                                         or self.workers < 1):
            raise ValueError(f"workers = {self.workers!r} is not allowed: must be an integer >= 1")
        if self.cache_dir is not None:
            object.__setattr__(self, "cache_dir", Path(self.cache_dir).expanduser().resolve())
        if self.sweep_log is not None:
            object.__setattr__(self, "sweep_log", Path(self.sweep_log))
        if self.progress is not None and not isinstance(self.progress, bool):
            raise ValueError(f"progress = {self.progress!r} is not allowed: must be True, False or None")

    @classmethod
    def from_environment(cls, environ: Mapping[str, str] | None = None, **overrides) -> RunConfig:
        """Read :data:`ENVIRONMENT` once (at an entry point); explicit ``overrides`` win.

        Empty variables count as unset, and so does a variable whose field an override
        gives; ``$CI`` set turns the progress bars off. ``ValueError`` names the variable and
        its value.
        """
        environ = os.environ if environ is None else environ
        overrides = {k: v for k, v in overrides.items() if v is not None}
        fields = {}
        for field, name in ENVIRONMENT.items():
            text = (environ.get(name) or "").strip()
            if not text or field in overrides:
                continue
            if field == "workers":
                if not text.isdigit() or int(text) < 1:
                    raise ValueError(f"{name} = {text!r} is not allowed: must be an integer >= 1")
                fields[field] = int(text)
            elif field == "progress":
                fields[field] = False  # continuous integration: no progress bars in the logs
            elif field == "profile" and text not in PROFILES:
                raise ValueError(f"{name} = {text!r} is not allowed: must be one of {', '.join(PROFILES)}")
            else:
                fields[field] = text
        return cls(**fields, **overrides)
