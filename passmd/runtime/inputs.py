"""Input files: read only from a regular file, never beyond the size stated for their kind.

Every file the package reads — a drive file, a measurement CSV, a cache entry, a reference
table — goes through :func:`read_bounded`. It opens without blocking (a named pipe without
a writer answers at once), refuses anything that is not a regular file (``/dev/zero`` would
be read forever, a pipe waits for its writer, a terminal for its user) and reads at most the
limit of the file's kind (:data:`LIMITS`), so that a wrong path costs one line, never a hang
or the machine's memory. :func:`decode_text` makes text of a text file's bytes: UTF-8, with
or without the byte-order mark Windows editors write; a UTF-16 or UTF-32 file is named as such.
"""

from __future__ import annotations

import errno
import os
import stat

from passmd.runtime.validation import InputError

__all__ = ["LIMITS", "RefusedFile", "decode_text", "format_size", "read_bounded", "read_text"]

_MiB = 2**20
#: The largest file of each kind the package reads, in bytes (README, "Reliability"): far
#: above any real input of the kind, far below what would exhaust a machine's memory.
LIMITS: dict[str, int] = {
    "drive file": _MiB,  # a drive file is a few hundred bytes of TOML
    "measurement file": 100 * _MiB,  # about two million rows of measurements
    "reference table": 16 * _MiB,  # the reference curves, claims table and baselines are a few kB
    "benchmark record": 16 * _MiB,  # a benchmark's JSON: tens of kB
    "cache entry": 2**30,  # one sweep point's result, arrays included
    "cache marker": 4096,  # CACHEDIR.TAG: a few lines
}

#: What lies at a path that is not a regular file, by its type in ``st_mode``.
_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISFIFO, "a named pipe"),
          (stat.S_ISSOCK, "a socket"), (stat.S_ISLNK, "a symbolic link"))


class RefusedFile(InputError):
    """A file that is not read: not a regular file, not of its kind, or above its kind's limit.

    ``reason`` is ``"type"`` (``found`` says what lies there: ``"a named pipe"``), ``"start"``
    (the file does not begin with the bytes its kind begins with), ``"size"`` (``size``: its
    size in bytes, or a lower bound when it grew while read) or ``"encoding"`` (not UTF-8 text:
    :func:`decode_text`). ``name`` is ``"file"`` and
    ``value`` the path as given.
    """

    def __init__(self, message: str, *, path, reason: str, found: str = "", size: int | None = None):
        super().__init__(message, name="file", value=str(path))
        self.path, self.reason, self.found, self.size = path, reason, found, size

    def __reduce__(self):  # (survives a process pool, like the other input errors)
        return _rebuild, (str(self), self.path, self.reason, self.found, self.size)


def _rebuild(message, path, reason, found, size):
    return RefusedFile(message, path=path, reason=reason, found=found, size=size)


def format_size(size: int) -> str:
    """``1 MiB``, ``100 MiB``, ``1 GiB``, ``4096 bytes``: a limit or a size as a reader says it."""
    for unit, scale in (("GiB", 2**30), ("MiB", _MiB), ("KiB", 1024)):
        if size >= scale:
            value = size / scale
            return f"{value:.0f} {unit}" if value == int(value) else f"{value:.3g} {unit}"
    return f"{size} bytes"


def _found(mode: int) -> str:
    return next((text for test, text in _KINDS if test(mode)), "not a regular file")


def _refuse_type(path, label: str, kind: str, found: str) -> RefusedFile:
    return RefusedFile(f"{label}: {found}, not a regular file: a {kind} is read from a regular file of at "
                       f"most {format_size(LIMITS[kind])}", path=path, reason="type", found=found)


def _refuse_size(path, label: str, kind: str, size: int, more: bool = False) -> RefusedFile:
    shown = f"more than {format_size(LIMITS[kind])}" if more else format_size(size)
    return RefusedFile(f"{label}: {shown}, above the {format_size(LIMITS[kind])} limit of a {kind}",
                       path=path, reason="size", size=size)


def _check_type(path, label: str, kind: str, mode: int) -> None:
    if stat.S_ISDIR(mode):
        raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR), str(path))
    if not stat.S_ISREG(mode):
        raise _refuse_type(path, label, kind, _found(mode))


def _open(path, label: str, kind: str, follow_links: bool) -> int:
    """A descriptor on the regular file ``path``, opened for reading without blocking (and
    without following a final symbolic link unless ``follow_links``).

    What lies at the path is looked at before it is opened (opening a device can have effects
    of its own) and again on the descriptor (it may have been replaced in between).
    """
    _check_type(path, label, kind, (os.stat if follow_links else os.lstat)(path).st_mode)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    if not follow_links:
        flags |= getattr(os, "O_NOFOLLOW", 0)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        if exc.errno == errno.ELOOP and not follow_links:  # replaced by a link since the lstat
            raise _refuse_type(path, label, kind, "a symbolic link") from None
        raise
    try:
        _check_type(path, label, kind, os.fstat(fd).st_mode)
    except BaseException:
        os.close(fd)
        raise
    return fd


def read_bounded(path, kind: str, *, label: str | None = None, follow_links: bool = True,
                 starts_with: bytes = b"", read: bool = True) -> bytes:
    """The bytes of the regular file ``path``, at most :data:`LIMITS` ``[kind]`` of them.

    Parameters
    ----------
    path : path-like
        The file; a link to a regular file is followed unless ``follow_links`` is False.
    kind : str
        A key of :data:`LIMITS` (``"drive file"``, ``"measurement file"``, ...): the limit,
        and the words of the messages.
    label : str, optional
        How the messages name the file (default: the path as given).
    follow_links : bool
        False: a symbolic link is refused as ``"a symbolic link"`` (the cache's own files).
    starts_with : bytes
        The bytes a file of this kind begins with; a file that does not is refused (reason
        ``"start"``) before its size is looked at.
    read : bool
        False: only check the file (type, first bytes, size) and return ``starts_with``.

    Raises
    ------
    RefusedFile
        Not a regular file, not starting with ``starts_with``, or above the limit: one line
        naming the file, what it is and the limit.
    IsADirectoryError
        A directory (as ``open()`` raises it).
    OSError
        Missing, unreadable (as ``open()`` raises it).
    """
    label = str(path) if label is None else label
    limit = LIMITS[kind]
    fd = _open(path, label, kind, follow_links)
    with os.fdopen(fd, "rb", buffering=0) as fh:
        size = os.fstat(fd).st_size
        head = _read_up_to(fh, len(starts_with))
        if head != starts_with:
            raise RefusedFile(f"{label}: not a {kind} (it does not start with {starts_with!r})", path=path,
                              reason="start")
        if size > limit:
            raise _refuse_size(path, label, kind, size)
        if not read:
            return head
        data = head + _read_up_to(fh, limit + 1 - len(head))
    if len(data) > limit:  # it grew while read
        raise _refuse_size(path, label, kind, len(data), more=True)
    return data


def _read_up_to(fh, count: int) -> bytes:
    """Up to ``count`` bytes (fewer only at the end of the file)."""
    chunks, left = [], count
    while left > 0:
        chunk = fh.read(min(left, 16 * _MiB))
        if not chunk:
            break
        chunks.append(chunk)
        left -= len(chunk)
    return b"".join(chunks)


#: Byte-order marks of the encodings a text file may be saved in that passmd does not read.
_OTHER_ENCODINGS = ((b"\xff\xfe\x00\x00", "UTF-32"), (b"\x00\x00\xfe\xff", "UTF-32"),
                    (b"\xff\xfe", "UTF-16"), (b"\xfe\xff", "UTF-16"))


def decode_text(data: bytes, label: str, kind: str) -> str:
    """The text of a text file's bytes: UTF-8, a leading byte-order mark dropped.

    Raises :class:`RefusedFile` (reason ``"encoding"``) naming a UTF-16 or UTF-32 file (by its
    byte-order mark) or the first byte that is not UTF-8.
    """
    for mark, encoding in _OTHER_ENCODINGS:
        if data.startswith(mark):
            raise RefusedFile(f"{label}: saved as {encoding}: a {kind} must be UTF-8 text (save it as UTF-8)",
                              path=label, reason="encoding")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise RefusedFile(f"{label}: not UTF-8 text: byte 0x{data[exc.start]:02x} on line {line} (a {kind} "
                          "must be UTF-8 text)", path=label, reason="encoding") from None


def read_text(path, kind: str, *, label: str | None = None) -> str:
    """The text of the regular file ``path`` of ``kind``: :func:`read_bounded`, then :func:`decode_text`."""
    label = str(path) if label is None else label
    return decode_text(read_bounded(path, kind, label=label), label, kind)
