"""Start-up of a command: the cyclic garbage collector waits until the modules are loaded.

Starting ``passmd run`` imports numpy and numba and loads the simulator's compiled kernels
from numba's on-disk cache: hundreds of thousands of long-lived objects and next to no
garbage. Left on, the cyclic collector traverses them again and again while they are
created (about 250 collections, 50 ms of the 0.6 s from launch to the first integrator
step; ``startup`` in ``benchmarks/bench_dynamics.py`` measures that time).

:func:`pause` stops automatic collection when :func:`passmd.cli.main` starts; :func:`resume`
turns it back on before a command's handler runs, or, for a command whose parser sets
``resumes_collector`` (``run``), when the handler calls it after its simulation, and moves
what was allocated meanwhile into the oldest generation. Reference counting frees memory
as usual while collection is paused; only reference cycles wait for the next full
collection. A collector the caller had turned off stays off.

At exit the interpreter collects once more, through everything the command loaded: about
0.2 s after ``passmd run`` has printed its result. :func:`skip_exit_collection` freezes the
objects then (:func:`gc.freeze`, as a Ctrl-C does in :func:`passmd.cli.main`), so the
process ends at once; the operating system reclaims its memory. Commands write their files
explicitly (atomically), never from a finalizer.
"""

from __future__ import annotations

import atexit
import gc

__all__ = ["pause", "resume", "skip_exit_collection"]

_paused = False
_exit_registered = False


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
        if gc.get_freeze_count() == 0:  # (a caller's frozen objects stay frozen)
            # what start-up allocated is long-lived: straight into the oldest generation
            # (freezing then unfreezing moves the objects without traversing them), so the
            # next young collection does not traverse all of them
            gc.freeze()
            gc.unfreeze()
        gc.enable()


def skip_exit_collection() -> None:
    """At interpreter exit, freeze all objects instead of collecting them (registered once)."""
    global _exit_registered
    if not _exit_registered:
        _exit_registered = True
        atexit.register(gc.freeze)
