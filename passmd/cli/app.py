"""Running the command line: parse, dispatch to the subcommand, map failures to exit status."""

from __future__ import annotations

import gc
import os
import signal
import sys
import warnings

import numpy as np

from passmd.cli import kernels, startup
from passmd.cli.drive import explain
from passmd.cli.errors import OPTIONAL_EXTRAS, MissingDependencyError, OutputError, UsageError
from passmd.cli.parser import PROG, make_parser
from passmd.cli.result_bounds import ResultError
from passmd.cli.streams import (
    Out,
    PipeClosed,
    StdoutError,
    one_line_warnings,
    reserve_closed_streams,
    silence_stdout,
    use_ascii_fallback,
)
from passmd.runtime.cache import CacheWarning
from passmd.runtime.extras import install_hint
from passmd.runtime.units import QuantityError

__all__ = ["Terminated", "main"]


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the command is: it stops as on Ctrl-C (temporary files removed,
    a sweep's workers stopped, finished points kept), with exit status 143."""


def _terminate(signum, frame):
    raise Terminated()


def _stop_on_sigterm():
    """Handle SIGTERM as Ctrl-C while the command runs; the previous handler, to restore.

    Only where SIGTERM has its default action (a caller's own handler or an ignored SIGTERM
    stays) and in the main thread (where Python runs signal handlers).
    """
    try:
        if signal.getsignal(signal.SIGTERM) is signal.SIG_DFL:
            return signal.signal(signal.SIGTERM, _terminate)
    except ValueError:  # not the main thread
        pass
    return None


def _cannot_write(err: OSError) -> int:
    silence_stdout()
    sys.stderr.write(f"{PROG}: error: cannot write the output: {err.strerror or err}\n")
    return 1


def _parse(parser, argv, to_stdout: bool):
    """(args, None), or (None, exit status) when --help/--version output could not be written."""
    try:
        return parser.parse_args(argv), None
    except BrokenPipeError:  # --help piped into head
        silence_stdout()
        return None, 141
    except OSError as err:  # --help > /dev/full
        return None, _cannot_write(err)
    except SystemExit as exc:  # --help, --version: what argparse printed must reach the file
        if exc.code == 0 and to_stdout:
            try:
                sys.stdout.flush()
            except BrokenPipeError:
                silence_stdout()
                return None, 141
            except OSError as err:
                return None, _cannot_write(err)
        raise


def main(argv=None, out=None) -> int:
    """Run the command line; return the exit status (0 ok, 2 usage error, 1 failed run).

    130 on Ctrl-C, 143 on SIGTERM, which is handled as Ctrl-C (one line "interrupted", no
    temporary or partial output file left, a sweep's worker processes stopped). 141 when
    standard output was closed by its reader, and also when the command was started with it
    closed (``>&-``): nothing is printed in either case, as for a pipe whose reader went away.
    Automatic garbage collection is paused while the command starts, and skipped at the
    interpreter's exit (:mod:`passmd.cli.startup`).
    """
    startup.skip_exit_collection()
    startup.pause()
    previous = _stop_on_sigterm()
    try:
        return _main(argv, out)
    except KeyboardInterrupt as exc:  # before the command started (parsing)
        return _interrupted(PROG, exc, "")
    finally:
        kernels.disarm()
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
        startup.resume()


def _main(argv, out) -> int:
    to_stdout = out is None
    reserve_closed_streams()
    for stream in (sys.stdout, sys.stderr):
        use_ascii_fallback(stream)
    out = Out(sys.stdout if out is None else out)
    args, status = _parse(make_parser(), argv, to_stdout)
    if args is None:
        return status
    prog = f"{PROG} {args.command}"
    with warnings.catch_warnings():
        # cache problems: one line each; numerical warnings: the results are checked instead
        warnings.showwarning = one_line_warnings(prog)
        warnings.simplefilter("always", CacheWarning)
        warnings.simplefilter("ignore", RuntimeWarning)
        with np.errstate(all="ignore"):
            return _dispatch(args, out, prog, to_stdout)


def _interrupted(prog: str, exc: KeyboardInterrupt, kept: str) -> int:
    sys.stderr.write(f"{prog}: interrupted{kept}\n")
    # exit at once: the interpreter's exit-time collection of numba's object graph takes ≈ 1 s
    gc.freeze()
    return 143 if isinstance(exc, Terminated) else 130


def _numba_cache_folders() -> str:
    """The folders numba tries for its cache, with the variable each comes from, as set."""
    package = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    user = next((f"{name} = {os.environ[name]}" for name in ("NUMBA_CACHE_DIR", "XDG_CACHE_HOME", "HOME")
                 if os.environ.get(name, "").strip()), "the user cache folder")
    return f"the package folder {package} and the user cache folder (from {user})"


def _error(prog: str, text: str, status: int) -> int:
    sys.stderr.write(f"{prog}: error: {text}\n")
    return status


def _dispatch(args, out: Out, prog: str, to_stdout: bool) -> int:  # noqa: C901 - one except per failure
    try:
        if not getattr(args, "resumes_collector", False):
            startup.resume()
        status = args.handler(args, out)
        out.flush()
        return status
    except PipeClosed:
        if to_stdout:
            silence_stdout()
        return 141
    except StdoutError as exc:
        if to_stdout:
            silence_stdout()
        return _error(prog, f"cannot write the output: {exc.strerror or exc}", 1)
    except (UsageError, QuantityError) as exc:  # a usage error raised from an input check: that check
        return _error(prog, explain(exc, args), 2)
    except OutputError as exc:
        return _error(prog, str(exc), 1)
    except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM (Terminated)
        kept = " (finished points are kept in the cache)" if args.command == "figure" else ""
        return _interrupted(prog, exc, kept)
    except ValueError as exc:  # the package's input checks (passmd.runtime.validation), in the options' terms
        return _error(prog, explain(exc, args), 2)
    except (ResultError, MissingDependencyError) as exc:
        return _error(prog, str(exc), 1)
    except RuntimeError as exc:  # passmd.solver.results.SimulationError and other failed runs
        if "no locator available" in str(exc):  # numba found no writable folder for its kernel cache
            return _error(prog, "cannot cache the compiled simulation kernels: "
                                f"{_numba_cache_folders()} cannot be written; set NUMBA_CACHE_DIR to a "
                                "writable folder", 1)
        return _error(prog, f"run failed: {exc}", 1)
    except ModuleNotFoundError as exc:
        extra = OPTIONAL_EXTRAS.get((exc.name or "").split(".")[0])
        hint = install_hint(extra) if extra else "reinstall passmd with its dependencies"
        return _error(prog, f"the package {exc.name!r} is not installed: {hint}", 1)
    except MemoryError:
        return _error(prog, "not enough memory for this run (lower --max-points or the number of periods)", 1)
    except OSError as exc:  # e.g. the cache or an output directory vanished under the run
        where = f" ({exc.filename})" if getattr(exc, "filename", None) else ""
        return _error(prog, f"{exc.strerror or exc}{where}", 1)
    except Exception as exc:  # a bug: one line, the traceback on request
        if os.environ.get("PASSMD_DEBUG"):
            raise
        return _error(prog, f"internal error: {type(exc).__name__}: {exc} (set PASSMD_DEBUG=1 for the "
                            "traceback)", 1)
