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
* :func:`check_new_outputs` and :func:`create_outputs`: a command's output files are checked
  before any work (none a regular file already there unless ``--overwrite``; a folder the command
  creates, writable), then written all together or not at all, new ones never over a file
  (:mod:`passmd.runtime.outputs`); a link stays a link, a device or pipe is written to.
"""

from __future__ import annotations

import codecs
import contextlib
import os
import stat
import sys

from passmd.cli.errors import OutputError, UsageError
from passmd.runtime import outputs

__all__ = ["Out", "PipeClosed", "StdoutError", "available_memory", "check_new_outputs", "check_outputs",
           "create_outputs", "one_line_warnings", "reserve_closed_streams", "silence_stdout",
           "use_ascii_fallback"]

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


def _named(option: str, path: str) -> str:
    """The output as the user named it: ``--csv out.csv``, or ``map.json (--out map)``."""
    return option if option.endswith(f" {path}") else f"{path} ({option})"


def check_new_outputs(named, *, overwrite: bool = False, folder=None, parents: bool = False) -> None:
    """Before any work (:class:`UsageError`, exit 2): no output of ``named`` (path -> the option as
    typed, ``"--csv out.csv"``, ``"--out results"``) is a regular file already there, unless
    ``overwrite`` (a device, a pipe or a link to one is written into: never refused).

    With ``folder`` (the folder the outputs are made in, which the run may create: one level, or any
    number with ``parents``), files must be creatable in it (or in its nearest existing ancestor),
    and in the real folder of every output that a link leads elsewhere."""
    for path, option in named.items():
        path = os.fspath(path)
        if outputs.is_taken(path) and not overwrite:
            raise UsageError(f"{_shown(option, path)} is already there: pass --overwrite to replace it, or "
                             "choose another name (an output never replaces a file unasked)")
    if folder is None:
        return
    option = next(iter(named.values()))
    folder = os.fspath(folder)
    probe = folder
    if not os.path.lexists(folder):  # created by the run
        probe = os.path.dirname(os.path.abspath(folder))
        while parents and not os.path.lexists(probe):
            probe = os.path.dirname(probe)
        if not os.path.isdir(probe):
            raise UsageError(f"{option}: the directory {probe!r} does not exist")
    elif not os.path.isdir(folder):
        raise UsageError(f"{option}: {folder} is not a directory")
    _probe(option, probe)
    created = os.path.realpath(folder)
    for path, option in named.items():
        target = outputs.file_target(path)
        if target is not None and os.path.dirname(target) not in (created, os.path.realpath(probe)):
            _probe(_shown(option, os.fspath(path)), os.path.dirname(target))  # (through a link)


def _shown(option: str, path: str) -> str:
    """``--csv out.csv``, or ``--out map: map.json``: the option as typed, and the file if it is not it."""
    return option if option.endswith(f" {path}") else f"{option}: {path}"


def _probe(option: str, folder: str) -> None:
    try:
        outputs.check_writable(folder)
    except OSError as exc:
        raise UsageError(f"{option}: cannot create files in {folder}: {exc.strerror or exc}") from None


def create_outputs(writers, named, *, overwrite: bool = False) -> None:
    """Write every file of ``writers`` (path -> ``write(temporary_path)``) all together or not at all
    (:func:`passmd.runtime.outputs.write_files`); ``named``: path -> the option as typed. Without
    ``overwrite`` a file that appeared meanwhile (another run) is kept and refused (:class:`UsageError`,
    exit 2); a failed write names its file (:class:`OutputError`, exit 1); either way none of this
    run's files is left."""
    named = {os.fspath(path): option for path, option in named.items()}
    try:
        outputs.write_files(writers, overwrite=overwrite)
    except outputs.OutputExists as exc:
        option = named[exc.filename]
        raise UsageError(f"{option}: {exc.filename} appeared while this run was writing (another run?): "
                         "it is kept, and this run wrote none of its files; pass --overwrite to replace "
                         "it") from None
    except BrokenPipeError as exc:
        raise PipeClosed() from exc
    except OSError as exc:
        where = _named(named[exc.filename], exc.filename) if exc.filename in named else exc.filename
        raise OutputError(f"cannot write {where}: {exc.strerror or exc}"
                          + ("; none of the run's files was written" if len(named) > 1 else "")) from None
