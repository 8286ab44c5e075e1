"""Standard streams of the command line: ASCII fallback, closed pipes, full disks, warnings.

* :func:`use_ascii_fallback` makes a console that cannot encode the output's symbols
  (μ, ×, –, →) print ASCII stand-ins instead of failing (``PYTHONIOENCODING=ascii``).
* :class:`Out` wraps the command's output: a closed pipe (``| head``) raises
  :class:`PipeClosed` (the command ends quietly, as Unix tools do), any other failed write
  (full disk) :class:`StdoutError` (one error line, exit 1).
* :func:`one_line_warnings` prints a warning as one ``prog: warning: ...`` line.
* :func:`available_memory` lets a command refuse a run before allocating it.
* :func:`reserve_closed_streams` stands in for a standard stream the command was started
  without (``>&-``): a closed standard output behaves as a closed pipe.
* :func:`check_outputs` refuses, before anything runs, outputs that name one file twice, an
  input, or the regular file standard output or error goes to.
* :func:`write_atomically` writes an output file completely or not at all, and never
  replaces what is not a regular file (a link stays a link, a device or pipe is written to).
* :func:`check_new_outputs` and :func:`create_outputs`: the files a command names itself
  (``fit --out DIR``, ``sweep --out PREFIX``) are checked absent and their folder writable before
  any work, then created all together or not at all, never over a file
  (:mod:`passmd.runtime.outputs`).
"""

from __future__ import annotations

import codecs
import contextlib
import os
import shutil
import stat
import sys
import tempfile

from passmd.cli.errors import OutputError, UsageError
from passmd.runtime import outputs

__all__ = ["Out", "PipeClosed", "StdoutError", "available_memory", "check_new_outputs", "check_outputs",
           "create_outputs", "one_line_warnings", "reserve_closed_streams", "silence_stdout",
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
        text = _cache_origin(" ".join(str(message).split()))
        sys.stderr.write(f"{prog}: warning: {text}\n")

    return show


def _cache_origin(text: str) -> str:
    """A warning about the user cache folder, with the variable that folder comes from as set
    (``XDG_CACHE_HOME``, else ``HOME``, where platformdirs reads them)."""
    if "(the user cache folder;" not in text or sys.platform in ("win32", "darwin"):
        return text
    for name in ("XDG_CACHE_HOME", "HOME"):
        value = os.environ.get(name, "").strip()
        if value:
            return text.replace("(the user cache folder;", f"(the user cache folder, from {name} = {value};")
    return text


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


class _ClosedStdout:
    """``sys.stdout`` of a process started with standard output closed: a write meets a closed pipe."""

    encoding = "utf-8"

    def write(self, text: str) -> int:
        raise BrokenPipeError(32, "standard output is closed")

    def flush(self) -> None:
        pass

    def isatty(self) -> bool:
        return False

    def fileno(self) -> int:
        raise OSError(9, "standard output is closed")


def reserve_closed_streams() -> None:
    """Stand in for standard streams the process was started without (``passmd theory >&-``).

    A closed descriptor 1 or 2 is opened on /dev/null, so that no file the command opens
    later gets it (and receives what a library prints there). ``sys.stdout = None`` becomes a
    stream whose writes meet a closed pipe: the command ends quietly with the closed-pipe
    status (141). ``sys.stderr = None`` becomes /dev/null.
    """
    for fd in (1, 2):
        try:
            os.fstat(fd)
        except OSError:
            with contextlib.suppress(OSError):
                devnull = os.open(os.devnull, os.O_WRONLY)
                if devnull != fd:
                    os.dup2(devnull, fd)
                    os.close(devnull)
    if sys.stdout is None:
        sys.stdout = _ClosedStdout()
    if sys.stderr is None:
        sys.stderr = open(os.devnull, "w", encoding="utf-8")  # noqa: SIM115 - for the process's life


def _same_file(a, b) -> bool:
    """Whether paths ``a`` and ``b`` name one file (links and spellings resolved)."""
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist (yet): compare where they lead
        return os.path.realpath(a) == os.path.realpath(b)


def _standard_stream_of(path) -> str | None:
    """``"standard output"``/``"standard error"`` when ``path`` is the regular file that stream
    is redirected to (``> out.txt``): replacing or reopening it would lose what is printed there."""
    try:
        target = os.stat(path)
    except OSError:
        return None
    if not stat.S_ISREG(target.st_mode):
        return None
    for fd, name in ((1, "standard output"), (2, "standard error")):
        with contextlib.suppress(OSError):
            stream = os.fstat(fd)
            if (stream.st_dev, stream.st_ino) == (target.st_dev, target.st_ino):
                return name
    return None


def check_outputs(outputs: dict[str, object], inputs: dict[str, object] | None = None) -> None:
    """Refuse (:class:`UsageError`) outputs that would destroy each other, an input or the output.

    ``outputs`` and ``inputs`` map how the user named each file (``"--csv out/x.csv"``) to its
    path; None values are skipped. Refused, before anything runs: two outputs naming the same
    file (through any spelling or link), an output naming an input, and an output that is the
    regular file standard output or standard error is redirected to.
    """
    named = [(name, path) for name, path in outputs.items() if path is not None]
    for i, (name, path) in enumerate(named):
        for other, other_path in named[:i]:
            if _same_file(path, other_path):
                raise UsageError(f"{other} and {name} name the same file: give each output a file of its own")
        for source, source_path in (inputs or {}).items():
            if source_path is not None and _same_file(path, source_path):
                raise UsageError(f"{name} names {source}, which the command reads: write the output "
                                 "to another file")
        stream = _standard_stream_of(path)
        if stream is not None:
            raise UsageError(f"{name} is the file {stream} is redirected to, which also receives the "
                             f"command's {'results' if stream == 'standard output' else 'messages'}: "
                             "give the output a file of its own")


def _through_descriptor_link(path) -> bool:
    """Whether ``path`` is in /proc or /dev/fd or its links pass through them (``/dev/stdout`` →
    ``/proc/self/fd/1``): it names an open descriptor's file, to be written to, never replaced."""
    current = os.path.abspath(path)
    for _ in range(40):  # the kernel's limit of links followed (ELOOP)
        parent = os.path.realpath(os.path.dirname(current))
        if parent in ("/proc", "/dev/fd") or parent.startswith("/proc/"):
            return True
        current = os.path.join(parent, os.path.basename(current))
        if not os.path.islink(current):
            return False
        current = os.path.join(parent, os.readlink(current))
    return False


def _replaceable(path) -> str | None:
    """The real path at which an atomic replace may put the new file, or None: write into ``path``.

    Only a regular file or a missing path, its links resolved (a link stays a link, its target
    is replaced; a dangling link's target is created), and not reached through /proc.
    """
    if _through_descriptor_link(path):
        return None
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return os.path.realpath(path)
    return os.path.realpath(path) if stat.S_ISREG(mode) else None


def replaced_in(path) -> str | None:
    """The folder :func:`write_atomically` makes ``path``'s new file in, or None (written into)."""
    target = _replaceable(path)
    return None if target is None else os.path.dirname(target)


def write_atomically(path, write) -> None:
    """Call ``write(temporary_path)``, then put the complete file at ``path`` without destroying anything.

    * A regular file or a missing path (links followed: the link stays, its target is
      replaced) gets the new file moved into place atomically, from a private temporary
      folder beside the target; an existing file keeps its permission bits, a new one gets
      those of a plainly created file.
    * Anything else (a device such as /dev/null, a FIFO, a terminal, ``/dev/stdout`` and every
      path through /proc, whatever it leads to) is opened for appending and the new file's
      bytes are copied into it: it is written to, never replaced or truncated.

    An interrupted or failed write (Ctrl-C, SIGTERM, full disk) leaves no partial regular file
    and no temporary file, not even one ``write`` made beside its own; the error propagates.
    """
    name = os.path.basename(os.fspath(path)) or "output"
    target = _replaceable(path)
    if target is not None and os.path.isfile(target):
        mode = stat.S_IMODE(os.stat(target).st_mode)
    else:
        mask = os.umask(0)
        os.umask(mask)
        mode = 0o666 & ~mask  # as a plainly created file
    folder = None
    try:
        folder = tempfile.mkdtemp(prefix=f".{name}-", suffix=".part",
                                  dir=None if target is None else os.path.dirname(target))
        tmp = os.path.join(folder, name)
        with open(tmp, "xb"):
            pass
        os.chmod(tmp, mode)
        write(tmp)
        if target is None:
            with open(tmp, "rb") as source, open(path, "ab") as sink:
                shutil.copyfileobj(source, sink)
        else:
            os.chmod(tmp, mode)  # (in case ``write`` replaced the file)
            os.replace(tmp, target)
    finally:
        if folder is not None:
            shutil.rmtree(folder, ignore_errors=True)


def check_new_outputs(option: str, paths, folder=None) -> None:
    """Before any work (:class:`UsageError`, exit 2): none of ``paths`` exists (not even as a dangling
    link) and files can be created in ``folder`` (default: the first path's; a folder the run will
    create is probed in its parent). ``option`` is the option as typed (``"--out results"``)."""
    paths = [os.fspath(p) for p in paths]
    for path in paths:
        try:
            outputs.check_absent(path)
        except outputs.OutputExists:
            raise UsageError(f"{option}: {path} is already there: choose another name (the outputs are "
                             "created new, never over a file)") from None
    folder = os.fspath(folder) if folder is not None else os.path.dirname(paths[0]) or "."
    probe = folder
    if not os.path.lexists(folder):  # created by the run: one level, in an existing directory
        probe = os.path.dirname(os.path.abspath(folder))
        if not os.path.isdir(probe):
            raise UsageError(f"{option}: the directory {probe!r} does not exist")
    elif not os.path.isdir(folder):
        raise UsageError(f"{option}: {folder} is not a directory")
    try:
        outputs.check_writable(probe)
    except OSError as exc:
        raise UsageError(f"{option}: cannot create files in {probe}: {exc.strerror or exc}") from None


def create_outputs(option: str, writers) -> None:
    """Create every file of ``writers`` (path -> ``write(temporary_path)``) all together or not at all
    (:func:`passmd.runtime.outputs.create_exclusively`): a file that appeared meanwhile (another run)
    is kept and refused (:class:`UsageError`, exit 2), a failed write names its file
    (:class:`OutputError`, exit 1); either way none of this run's files is left."""
    try:
        outputs.create_exclusively(writers)
    except outputs.OutputExists as exc:
        raise UsageError(f"{option}: {exc.filename} appeared while this run was writing (another run?): "
                         "it is kept, and this run wrote none of its files") from None
    except BrokenPipeError as exc:
        raise PipeClosed() from exc
    except OSError as exc:
        raise OutputError(f"cannot write {exc.filename or option} ({option}): {exc.strerror or exc}; none of "
                          "the run's files was written") from None
