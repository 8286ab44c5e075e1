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
import sys

__all__ = ["load_numba_without_blas_probe", "pause", "resume", "skip_exit_collection"]

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


#: scipy's BLAS module, which numba imports (with scipy.linalg) to see whether it can compile
#: linear algebra (``numba.np.arraymath``, at the first use of a compiled function).
_BLAS_MODULE = "scipy.linalg.cython_blas"


def load_numba_without_blas_probe() -> None:
    """Load numba's array-math registry with scipy's BLAS module hidden from its probe.

    At the first call of any compiled function, numba imports ``numba.np.arraymath``, which
    imports ``scipy.linalg.cython_blas`` (and scipy.linalg with it: 0.1–0.15 s, a fifth of
    ``passmd run``'s start-up) only to decide whether ``np.dot`` and the like can be compiled.
    passmd's kernels call no BLAS routine, so a command that only runs them loads the registry
    first with that module hidden (numba then records "no BLAS" for this process) and unhides
    it at once: scipy, imported later by anything else, is untouched. A no-op if numba's
    registry or scipy's BLAS module is already loaded.
    """
    if "numba.np.arraymath" in sys.modules or _BLAS_MODULE in sys.modules:
        return
    sys.modules[_BLAS_MODULE] = None  # (an import of a None entry raises ImportError)
    try:
        import numba.np.arraymath  # noqa: F401
    finally:
        if sys.modules.get(_BLAS_MODULE, 0) is None:
            del sys.modules[_BLAS_MODULE]
