"""Output files created exclusively: all of a run's files or none, never over a file that is there.

A command whose outputs the package names (``fit --out DIR``: ``fit.json``, ``fit.png``,
``fitted-drive.toml``; ``sweep --out PREFIX``: ``PREFIX.csv``, ``.json``, ``.png``) creates them
with :func:`create_exclusively` at the end of a successful run:

1. every target is checked absent (a file, a link, even a dangling one: :func:`check_absent`);
2. each file is written completely to a temporary name beside its target (same folder, so the
   next step is a link, never a copy);
3. each temporary is linked to its target with ``os.link``, which fails with ``EEXIST`` if the
   name exists (``os.rename``/``os.replace`` would replace it): a file that appeared meanwhile,
   or a concurrent run writing the same outputs, keeps its file and this run stops with
   :class:`OutputExists` naming it;
4. on any failure (a write, a link, Ctrl-C) the links this run made are removed again, so a
   failed run leaves none of its outputs; the temporaries are always removed.

Of two runs writing the same outputs at once, the one that links the first file wins all of
them (both link in the same order), and the other refuses. :func:`check_writable` probes a
folder before any work, by creating (and removing) a file in it: permission bits, read-only
file systems and special folders (``/proc``, ``/sys``) all answer, also for root.
"""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
import tempfile
from collections.abc import Callable, Mapping

__all__ = ["OutputExists", "OutputWriteError", "check_absent", "check_writable", "create_exclusively"]


class OutputExists(FileExistsError):
    """An output's name is taken (before the run, or by a file that appeared while it ran)."""


class OutputWriteError(OSError):
    """Writing or linking one output failed; ``filename`` is that output."""


def check_absent(path) -> None:
    """Raise :class:`OutputExists` if anything, even a dangling link, has the name ``path``."""
    if os.path.lexists(path):
        raise OutputExists(errno.EEXIST, "already there", os.fspath(path))


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


def _plain_mode() -> int:
    """The permission bits of a plainly created file (0666 less the umask)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def _before_linking() -> None:
    """Called once every output is written, before the first is linked (a test's gate hooks here)."""


def _link(source: str, target: str) -> bool:
    """``target`` made a new name of ``source`` (True); ``OutputExists`` if ``target`` exists.

    Where the file system has no hard links, ``target`` is created with ``O_EXCL`` and the
    bytes copied (False): still never over an existing file.
    """
    try:
        os.link(source, target)
        return True
    except FileExistsError:
        raise OutputExists(errno.EEXIST, "appeared while the run was writing", target) from None
    except OSError as exc:
        if exc.errno not in (errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EXDEV, errno.EMLINK):
            raise
    try:
        fd = os.open(target, os.O_WRONLY | os.O_CREAT | os.O_EXCL, _plain_mode())
    except FileExistsError:
        raise OutputExists(errno.EEXIST, "appeared while the run was writing", target) from None
    try:
        with open(source, "rb") as src, os.fdopen(fd, "wb") as sink:
            shutil.copyfileobj(src, sink)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(target)
        raise
    return False


def create_exclusively(writers: Mapping[object, Callable[[str], None]]) -> None:
    """Create every file of ``writers`` (path -> ``write(temporary_path)``), all or none.

    See the module docstring. Raises :class:`OutputExists` (a target is there, or appeared),
    :class:`OutputWriteError` (a write or link failed; ``filename`` is the output), or whatever
    interrupted the run; in every case none of the outputs is left and no temporary either.
    """
    targets = [os.fspath(path) for path in writers]
    for target in targets:
        check_absent(target)
    mode = _plain_mode()
    temporaries: dict[str, str] = {}
    linked: list[tuple[str, bool]] = []
    try:
        for target, write in zip(targets, writers.values(), strict=True):
            folder = os.path.dirname(os.path.abspath(target))
            try:
                fd, tmp = tempfile.mkstemp(prefix=f".{os.path.basename(target)}.", suffix=".part", dir=folder)
                os.close(fd)
                temporaries[target] = tmp
                os.chmod(tmp, mode)
                write(tmp)
            except OSError as exc:
                raise OutputWriteError(exc.errno, exc.strerror or str(exc), target) from exc
        _before_linking()
        for target in targets:
            try:
                linked.append((target, _link(temporaries[target], target)))
            except OutputExists:
                raise
            except OSError as exc:
                raise OutputWriteError(exc.errno, exc.strerror or str(exc), target) from exc
    except BaseException:
        for target, hard in linked:  # only the names this run created (a link: still its own file)
            with contextlib.suppress(OSError):
                if not hard or os.path.samefile(target, temporaries[target]):
                    os.unlink(target)
        raise
    finally:
        for tmp in temporaries.values():
            with contextlib.suppress(OSError):
                os.unlink(tmp)
