"""Output files: written completely at the end, all of a run's or none, never over a file unasked.

Every file the package writes (the command line's ``--csv``, ``--plot``, ``--out``,
``--write-baseline``, ``--write-drive``, and the API's ``write_baseline``, ``write_measurements``,
``write_reference_curves``) goes through :func:`write_files` (one file: :func:`write_file`):

1. each output's path is resolved through its links (:func:`file_target`): a regular file or a
   missing name gets a new regular file there (a link stays a link, its target is written; a
   dangling link's target is created); anything else (a device such as ``/dev/null``, a named
   pipe, a terminal, ``/dev/stdout`` and every path through ``/proc``) is written into, never
   replaced or truncated;
2. each file is written completely to a temporary name in a private folder beside its target
   (same file system, so the next step is a link or a rename, never a copy);
3. without ``overwrite``, each temporary is linked to its target with ``os.link``, which fails
   with ``EEXIST`` if the name exists (``os.rename``/``os.replace`` would replace it): a file that
   appeared meanwhile, or a concurrent run writing the same outputs, keeps its file and this run
   stops with :class:`OutputExists` naming it. With ``overwrite``, each temporary replaces its
   target atomically (``os.replace``; the file keeps its permission bits): whatever is there at
   the end is replaced, since no check made before the rename could be atomic with it;
4. the outputs that are written into come last, once every regular file is in place;
5. on any failure (a write, a link, Ctrl-C) the files this run put in place are removed again, and
   a file it replaced is put back, so a failed run leaves none of its outputs; the temporaries are
   always removed.

Of two runs writing the same new outputs at once, the one that links the first file wins all of
them (both link in the same order), and the other refuses. :func:`is_taken` tells, before any work,
whether an output would need ``overwrite``; :func:`check_writable` probes a folder by creating (and
removing) a file in it: permission bits, read-only file systems and special folders (``/proc``,
``/sys``) all answer, also for root.
"""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
import stat
import tempfile
from collections.abc import Callable, Mapping

__all__ = ["OutputExists", "OutputWriteError", "check_writable", "file_target", "is_taken", "write_file",
           "write_files"]


class OutputExists(FileExistsError):
    """An output's name is taken by a regular file (before the run, or one that appeared while it ran)."""


class OutputWriteError(OSError):
    """Writing or linking one output failed; ``filename`` is that output."""


def check_writable(folder) -> None:
    """Raise ``OSError`` (with ``filename``) unless a file can be created in the existing ``folder``."""
    folder = os.fspath(folder) or "."
    if not os.path.isdir(folder):
        raise FileNotFoundError(errno.ENOENT, "no such directory", folder)
    try:
        fd, probe = tempfile.mkstemp(prefix=".passmd-probe-", dir=folder)
    except OSError as exc:
        raise type(exc)(exc.errno, exc.strerror or str(exc), folder) from None
    os.close(fd)
    os.unlink(probe)


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


def file_target(path) -> str | None:
    """The real path at which ``path``'s new regular file is put, or None: ``path`` is written into.

    Only a regular file or a missing path, its links resolved (a link stays a link, its target
    is written; a dangling link's target is created), and not reached through /proc.
    """
    if _through_descriptor_link(path):
        return None
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return os.path.realpath(path)
    return os.path.realpath(path) if stat.S_ISREG(mode) else None


def is_taken(path) -> bool:
    """Whether a regular file (through links) is at ``path``: only ``overwrite`` may replace it."""
    target = file_target(path)
    return target is not None and os.path.isfile(target)


def _plain_mode() -> int:
    """The permission bits of a plainly created file (0666 less the umask)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def _before_linking() -> None:
    """Called once every output is written, before the first is put in place (a test's gate hooks here)."""


def _identity(path) -> tuple[int, int]:
    info = os.stat(path)
    return info.st_dev, info.st_ino


def _link(source: str, target: str, path: str) -> tuple[int, int]:
    """``target`` made a new name of ``source``; ``OutputExists`` (naming ``path``) if ``target`` exists.

    Where the file system has no hard links, ``target`` is created with ``O_EXCL`` and the
    bytes copied: still never over an existing file. Returns the identity of the file at ``target``.
    """
    try:
        os.link(source, target)
        return _identity(source)
    except FileExistsError:
        raise OutputExists(errno.EEXIST, "appeared while the run was writing", path) from None
    except OSError as exc:
        if exc.errno not in (errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EXDEV, errno.EMLINK):
            raise
    try:
        fd = os.open(target, os.O_WRONLY | os.O_CREAT | os.O_EXCL, stat.S_IMODE(os.stat(source).st_mode))
    except FileExistsError:
        raise OutputExists(errno.EEXIST, "appeared while the run was writing", path) from None
    identity = os.fstat(fd)
    try:
        with open(source, "rb") as src, os.fdopen(fd, "wb") as sink:
            shutil.copyfileobj(src, sink)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(target)
        raise
    return identity.st_dev, identity.st_ino


def _replace(source: str, target: str) -> str | None:
    """``source`` renamed over ``target`` (keeping ``target``'s permission bits); returns a second name
    of the file replaced (beside ``source``), to put it back if the run fails, or None."""
    previous = None
    with contextlib.suppress(FileNotFoundError):
        os.chmod(source, stat.S_IMODE(os.stat(target).st_mode))
        previous = source + ".previous"  # (beside ``source``, in this run's private folder)
        try:
            os.link(target, previous)
        except OSError:  # no hard links here: the file replaced cannot be put back
            previous = None
    os.replace(source, target)
    return previous


def _undo(target: str, identity: tuple[int, int], previous: str | None) -> None:
    """Remove this run's file at ``target`` (or put back the one it replaced), if it is still there."""
    with contextlib.suppress(OSError):
        if _identity(target) != identity:
            return  # not this run's file any more
        if previous is not None:
            os.replace(previous, target)
        else:
            os.unlink(target)


def write_files(writers: Mapping[object, Callable[[str], None]], *, overwrite: bool = False) -> None:
    """Write every file of ``writers`` (path -> ``write(temporary_path)``), all or none.

    See the module docstring. Raises :class:`OutputExists` (without ``overwrite``, a regular file
    is there), :class:`OutputWriteError` (a write or link failed; ``filename`` is the output as
    given), ``BrokenPipeError`` (a pipe written into lost its reader), or whatever interrupted the
    run; in every case none of the outputs is left (a file replaced is put back) and no temporary
    either.
    """
    paths = [os.fspath(path) for path in writers]
    targets = {path: file_target(path) for path in paths}
    if not overwrite:
        for path in paths:
            if is_taken(path):
                raise OutputExists(errno.EEXIST, "already there (overwrite replaces it)", path)
    mode = _plain_mode()
    folders: dict[str, str] = {}
    staged: dict[str, str] = {}
    placed: list[tuple[str, tuple[int, int], str | None]] = []
    try:
        for path, write in zip(paths, writers.values(), strict=True):
            target = targets[path]
            name = os.path.basename(target or path) or "output"
            try:
                folders[path] = tempfile.mkdtemp(prefix=f".{name}-", suffix=".part",
                                                 dir=None if target is None else os.path.dirname(target))
                tmp = os.path.join(folders[path], name)
                with open(tmp, "xb"):
                    pass
                os.chmod(tmp, mode)
                write(tmp)
                os.chmod(tmp, mode)  # (in case ``write`` replaced the file)
                staged[path] = tmp
            except BrokenPipeError:
                raise
            except OSError as exc:
                raise OutputWriteError(exc.errno, exc.strerror or str(exc), path) from exc
        _before_linking()
        for path in paths:
            target = targets[path]
            if target is None:
                continue
            try:
                if overwrite:
                    identity = _identity(staged[path])
                    placed.append((target, identity, _replace(staged[path], target)))
                else:
                    placed.append((target, _link(staged[path], target, path), None))
            except OutputExists:
                raise
            except OSError as exc:
                raise OutputWriteError(exc.errno, exc.strerror or str(exc), path) from exc
        for path in paths:  # written into (a device, a pipe, /dev/stdout): last, it cannot be undone
            if targets[path] is None:
                try:
                    with open(staged[path], "rb") as source, open(path, "ab") as sink:
                        shutil.copyfileobj(source, sink)
                except BrokenPipeError:
                    raise
                except OSError as exc:
                    raise OutputWriteError(exc.errno, exc.strerror or str(exc), path) from exc
    except BaseException:
        for target, identity, previous in reversed(placed):
            _undo(target, identity, previous)
        raise
    finally:
        for folder in folders.values():
            shutil.rmtree(folder, ignore_errors=True)


def write_file(path, write: Callable[[str], None], *, overwrite: bool = False) -> None:
    """Write one file with ``write(temporary_path)``: :func:`write_files` of ``{path: write}``."""
    write_files({path: write}, overwrite=overwrite)
