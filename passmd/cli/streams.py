"""Standard streams of the command line: ASCII fallback, closed pipes, full disks, warnings.

* :func:`use_ascii_fallback` makes a console that cannot encode the output's symbols
  (μ, ×, –, →) print ASCII stand-ins instead of failing (``PYTHONIOENCODING=ascii``).
* :class:`Out` wraps the command's output: a closed pipe (``| head``) raises
  :class:`PipeClosed` (the command ends quietly, as Unix tools do), any other failed write
  (full disk) :class:`StdoutError` (one error line, exit 1).
* :func:`one_line_warnings` prints a warning as one ``prog: warning: ...`` line.
* :func:`available_memory` lets a command refuse a run before allocating it.
* :func:`write_atomically` writes an output file completely or not at all.
"""

from __future__ import annotations

import codecs
import contextlib
import os
import sys

__all__ = ["Out", "PipeClosed", "StdoutError", "available_memory", "one_line_warnings", "silence_stdout",
           "use_ascii_fallback", "write_atomically"]

#: ASCII stand-ins for the symbols of the human output (consoles that cannot encode them).
_ASCII = {"μ": "mu", "µ": "u", "×": "x", "–": "-", "—": "-", "…": "...", "→": "->", "≈": "~",
          "√": "sqrt", "ζ": "zeta", "Δ": "Delta", "·": "*", "≥": ">=", "≤": "<=", "−": "-", "∞": "inf",
          "ν": "nu", "x̄": "mean x", "\u0304": "", "’": "'", "²": "^2", "³": "^3", "°": " deg"}


def _ascii_fallback(exc):
    """codecs error handler ``passmd-ascii``: symbols to ASCII stand-ins, others to '?'."""
    if not isinstance(exc, UnicodeEncodeError):
        raise exc
    text = exc.object[exc.start:exc.end]
    return "".join(_ASCII.get(ch, "?") for ch in text), exc.end


codecs.register_error("passmd-ascii", _ascii_fallback)


def use_ascii_fallback(stream) -> None:
    """Make ``stream`` print ASCII stand-ins for characters its encoding cannot encode."""
    encoding = getattr(stream, "encoding", None)
    reconfigure = getattr(stream, "reconfigure", None)
    if not encoding or reconfigure is None:
        return
    try:
        "μ×–→…≈".encode(encoding)
    except (UnicodeEncodeError, LookupError):
        with contextlib.suppress(Exception):
            reconfigure(errors="passmd-ascii")


class StdoutError(OSError):
    """Writing the command's output (not an output file) failed."""


class PipeClosed(Exception):
    """The reader of standard output went away (``| head``)."""


class Out:
    """The command's output stream; tells a closed pipe and a failing write apart."""

    def __init__(self, stream):
        self.stream = stream

    def write(self, text: str) -> int:
        try:
            return self.stream.write(text)
        except BrokenPipeError as exc:
            raise PipeClosed() from exc
        except OSError as exc:
            raise StdoutError(exc.errno, exc.strerror or str(exc)) from exc

    def flush(self) -> None:
        flush = getattr(self.stream, "flush", None)
        if flush is None:
            return
        try:
            flush()
        except BrokenPipeError as exc:
            raise PipeClosed() from exc
        except OSError as exc:
            raise StdoutError(exc.errno, exc.strerror or str(exc)) from exc


def one_line_warnings(prog: str):
    """``warnings.showwarning`` printing ``prog: warning: message`` on one line."""

    def show(message, category, filename, lineno, file=None, line=None):
        text = " ".join(str(message).split())
        sys.stderr.write(f"{prog}: warning: {text}\n")

    return show


def silence_stdout() -> None:
    """Point file descriptor 1 at /dev/null so the interpreter's final flush cannot fail."""
    with contextlib.suppress(OSError, ValueError, AttributeError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)


def available_memory() -> int | None:
    """Memory available to this process in bytes (``MemAvailable``), None if unknown."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None



def write_atomically(path, write) -> None:
    """Call ``write(temporary_path)`` and move the file into place only when it is complete.

    An interrupted or failed write (Ctrl-C, full disk) leaves no partial ``path`` and no
    temporary file; the error propagates.
    """
    import tempfile
    from pathlib import Path

    target = Path(path)
    if target.exists() and not target.is_file():  # a device such as /dev/null: write directly
        write(str(target))
        return
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}-", suffix=".part" + target.suffix,
                               dir=target.parent if str(target.parent) else ".")
    os.close(fd)
    mask = os.umask(0)
    os.umask(mask)
    try:
        os.chmod(tmp, 0o666 & ~mask)  # as a plainly created file (mkstemp makes it private)
        write(tmp)
        os.replace(tmp, target)
        tmp = None
    finally:
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
