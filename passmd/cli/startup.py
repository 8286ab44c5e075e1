"""Start-up of a command: the cyclic garbage collector waits until the modules are loaded.

Starting ``passmd run`` imports numpy and numba and loads the simulator's compiled kernels
from numba's on-disk cache: hundreds of thousands of long-lived objects and next to no
garbage. Left on, the cyclic collector traverses them again and again while they are
created (about 250 collections, 50 ms of the 0.6 s from launch to the first integrator
step; ``startup`` in ``benchmarks/bench_dynamics.py`` measures that time).

:func:`pause` stops automatic collection when :func:`passmd.cli.main` starts; :func:`resume`
turns it back on before a command's handler runs, or, for a command whose parser sets
``resumes_collector`` (``run``), when the handler calls it after its simulation. Reference
counting frees memory as usual while collection is paused; only reference cycles wait for
the next collection. A collector the caller had turned off stays off.
"""

from __future__ import annotations

import gc

__all__ = ["pause", "resume"]

_paused = False


def pause() -> None:
    """Stop automatic cyclic garbage collection until :func:`resume` (if it is on)."""
    global _paused
    if gc.isenabled():
        gc.disable()
        _paused = True


def resume() -> None:
    """Turn automatic collection back on if :func:`pause` turned it off (idempotent)."""
    global _paused
    if _paused:
        _paused = False
        gc.enable()
