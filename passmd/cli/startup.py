"""Start-up of a command: three measured tricks (``benchmarks/bench_startup.py`` times each
against the same launch without it; CONTRIBUTING, "Start-up", has the numbers).

* :func:`pause` stops automatic cyclic garbage collection when :func:`passmd.cli.main` starts
  (imports of numpy, numba and the compiled kernels create hundreds of thousands of
  long-lived objects and next to no garbage); :func:`resume` turns it back on before a
  command's handler runs or, for a parser that sets ``resumes_collector`` (``run``), when the
  handler calls it after its simulation, moving what was allocated meanwhile into the oldest
  generation. Reference counting frees memory meanwhile; a collector the caller had turned
  off stays off.
* :func:`skip_exit_collection` freezes the objects at exit (:func:`gc.freeze`, as a Ctrl-C does
  in :func:`passmd.cli.main`) instead of collecting through everything the command loaded;
  the operating system reclaims the memory. Commands write their files explicitly
  (atomically), never from a finalizer.
* :func:`load_numba_without_blas_probe` spares a command that only runs the kernels the
  import of scipy.linalg that numba makes to probe for BLAS.
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
