"""The cache directory on disk (rules in :mod:`passmd.runtime.cache`): its marker, the names it owns,
what lies at an entry's path (never following a link or blocking on a device) and the state of a
directory (:func:`~passmd.runtime.cache.layout.inspect_directory`;
:func:`~passmd.runtime.cache.layout.owned` refuses a foreign one).
"""

from __future__ import annotations

import contextlib
import os
import re
import stat
import tempfile
from pathlib import Path

from passmd.runtime.cache.entry import FORMAT, MAGIC, MAX_ENTRY_BYTES
from passmd.runtime.inputs import RefusedFile, read_bounded

__all__ = ["ENTRY_SUFFIX", "MARKER_NAME", "NotACache", "inspect_directory", "owned"]

#: File suffix of an entry.
ENTRY_SUFFIX = ".pmc"
#: The marker file of a cache directory (a cache directory tag, https://bford.info/cachedir/).
MARKER_NAME = "CACHEDIR.TAG"
_MARKER_SIGNATURE = "Signature: 8a477f597d28d172789f06886806bc55"
_MARKER_FORMAT_LINE = "# passmd cache format: "
_MARKER_TEXT = (
    f"{_MARKER_SIGNATURE}\n"
    "# This directory is a passmd simulation cache: passmd deletes only its own entries in it.\n"
    f"{_MARKER_FORMAT_LINE}{FORMAT}\n"
    "# For information about cache directory tags see https://bford.info/cachedir/\n"
).encode()

#: Names the cache owns: subfolders, entries and temporary files (groups: the key's first
#: two digits, which must be the subfolder's name).
_KEY = re.compile(r"[0-9a-f]{64}")
_SUBDIR = re.compile(r"[0-9a-f]{2}")
_ENTRY_NAME = re.compile(r"([0-9a-f]{2})[0-9a-f]{62}" + re.escape(ENTRY_SUFFIX))
_TEMP_NAME = re.compile(r"\.([0-9a-f]{2})[0-9a-f]{14}-[a-z0-9_]{1,32}\.tmp")
_MARKER_TEMP_NAME = re.compile(r"\.CACHEDIR\.TAG-[a-z0-9_]{1,32}\.tmp")


class NotACache(ValueError):
    """A directory is not a passmd cache (no marker of this format): nothing in it is touched.

    ``directory`` is the directory, ``reason`` says why (``str()`` joins both).
    """

    def __init__(self, directory: Path, reason: str):
        super().__init__(f"{directory} {reason}")
        self.directory, self.reason = directory, reason


def _check_key(key) -> str:
    if not isinstance(key, str) or not _KEY.fullmatch(key):
        shown = repr(key) if len(repr(key)) <= 80 else repr(key)[:76] + "...'"
        raise ValueError(f"key = {shown} is not a cache key: must be 64 lowercase hexadecimal digits "
                         "(as Cache.key returns)")
    return key


def _examine(path: Path, *, read: bool) -> tuple[str, object]:
    """What lies at an entry's path, never following a link or blocking on a device.

    ``("missing", None)``; ``("foreign", what)``: not the cache's (a directory, or a regular
    file without the magic line): never removed or replaced; ``("bad", why)``: unreadable
    as an entry and removable (a link, which is removed itself, a special file, an entry
    above :data:`~passmd.runtime.cache.entry.MAX_ENTRY_BYTES`); ``("entry", data)``: a
    regular file that starts with the magic line, with its bytes when ``read``. Other
    ``OSError`` (permissions) propagate. Read by :func:`passmd.runtime.inputs.read_bounded`.
    """
    try:
        data = read_bounded(path, "cache entry", follow_links=False, starts_with=MAGIC, read=read)
    except FileNotFoundError:
        return "missing", None
    except IsADirectoryError:
        return "foreign", "a directory"
    except RefusedFile as exc:
        if exc.reason == "start":
            return "foreign", "a file that is not a passmd cache entry (no PASSMD-CACHE first line)"
        if exc.reason == "size":
            return "bad", f"{exc.size} bytes, above the {MAX_ENTRY_BYTES}-byte limit"
        if exc.found == "a symbolic link":
            return "bad", "a symbolic link, not an entry"
        return "bad", "not a regular file"
    return "entry", data if read else None


def _read_marker(directory: Path) -> str | None:
    """The format a passmd marker in ``directory`` names, None if there is none."""
    try:
        text = read_bounded(directory / MARKER_NAME, "cache marker", follow_links=False)
    except (OSError, RefusedFile):
        return None
    lines = text.decode("utf-8", "replace").splitlines()
    if not lines or lines[0].strip() != _MARKER_SIGNATURE:
        return None
    for line in lines[1:]:
        if line.startswith(_MARKER_FORMAT_LINE) and line[len(_MARKER_FORMAT_LINE):].strip():
            return line[len(_MARKER_FORMAT_LINE):].strip()
    return None


@contextlib.contextmanager
def _temporary(folder: Path, prefix: str, data: bytes, durable: bool = True):
    """A new file ``<prefix><random>.tmp`` in ``folder`` holding ``data`` (with ``durable``, flushed
    to disk), for the block to move into place; removed on leaving it (also on
    ``KeyboardInterrupt`` or what a SIGTERM handler raises) unless moved."""
    fd, tmp = tempfile.mkstemp(prefix=prefix, suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            if durable:
                os.fsync(fh.fileno())
        yield tmp
    finally:
        try:
            os.unlink(tmp)
        except OSError:
            pass


def _write_marker(directory: Path) -> None:
    """Write the marker atomically without replacing a file already there."""
    marker = directory / MARKER_NAME
    with _temporary(directory, f".{MARKER_NAME}-", _MARKER_TEXT) as tmp:
        os.chmod(tmp, 0o644)
        try:
            os.link(tmp, marker)  # atomic, and fails where a marker (or any file) is already
        except FileExistsError:
            pass
        except OSError:  # a file system without hard links
            if not os.path.lexists(marker):
                os.replace(tmp, marker)


def _unlink(path: Path) -> bool:
    """Remove one file (a link itself); False if it was gone already."""
    try:
        os.unlink(path)
    except FileNotFoundError:
        return False
    return True


def _is_regular(path: Path) -> bool:
    try:
        return stat.S_ISREG(os.lstat(path).st_mode)
    except OSError:
        return False


def _walk(directory: Path):
    """``(kind, path)`` of every name in a cache directory (subfolders: their names).

    ``kind``: ``"candidate"`` (at an entry's path: :func:`_examine` tells what it is),
    ``"temp"`` (one of the cache's own temporary files), ``"foreign"`` (anything else: not
    the cache's). The marker itself is not listed. Names that vanish meanwhile are skipped.
    """
    try:
        top = sorted(os.listdir(directory))
    except FileNotFoundError:
        return
    for name in top:
        path = directory / name
        if name == MARKER_NAME:
            continue
        if _MARKER_TEMP_NAME.fullmatch(name) and _is_regular(path):
            yield "temp", path
            continue
        try:
            is_subdir = _SUBDIR.fullmatch(name) is not None and stat.S_ISDIR(os.lstat(path).st_mode)
        except FileNotFoundError:
            continue
        if not is_subdir:
            yield "foreign", path
            continue
        try:
            names = sorted(os.listdir(path))
        except FileNotFoundError:
            continue
        for child in names:
            file = path / child
            entry = _ENTRY_NAME.fullmatch(child)
            if entry and entry[1] == name:
                yield "candidate", file
                continue
            temp = _TEMP_NAME.fullmatch(child)
            if temp and temp[1] == name and _is_regular(file):
                yield "temp", file
                continue
            yield "foreign", file


def _first_stray(directory: Path) -> str | None:
    """The first name in an unmarked directory that is not of the cache's own layout."""
    for kind, path in _walk(directory):
        if kind == "candidate" and _examine(path, read=False)[0] in ("entry", "missing"):
            continue
        if kind != "temp":
            return path.relative_to(directory).as_posix()
    if (directory / MARKER_NAME).exists() or os.path.islink(directory / MARKER_NAME):
        return MARKER_NAME  # a tag of another program
    return None


def inspect_directory(directory: Path) -> tuple[str, str]:
    """State of the directory and, for one that is not a usable cache, why.

    ``missing``, ``empty``, ``marked`` (marker of this format), ``own-layout`` (no
    marker, only the cache's own files), ``foreign``, ``other-format``,
    ``not-a-directory``. ``OSError`` (permissions) propagates.
    """
    try:
        info = os.stat(directory)
    except FileNotFoundError:
        return "missing", "does not exist"
    if not stat.S_ISDIR(info.st_mode):
        return "not-a-directory", "is not a directory"
    found = _read_marker(directory)
    if found == FORMAT:
        return "marked", ""
    if found is not None:
        return "other-format", (f"is a passmd cache of format {found!r}; this passmd reads {FORMAT!r} "
                                "(use the passmd that wrote it, or remove the directory by hand)")
    if not os.listdir(directory):
        return "empty", ""
    stray = _first_stray(directory)
    if stray is None:
        return "own-layout", (f"has no {MARKER_NAME} marker, though it holds only passmd cache entries "
                              "(a cache from before markers): the next run that caches results in it "
                              "marks it")
    return "foreign", (f"is not a passmd cache: it has no {MARKER_NAME} marker written by passmd and "
                       f"holds {stray!r}, which is not a passmd cache file")


def owned(directory: Path) -> bool:
    """For info/clear/prune: True for a marked cache, False for a missing or empty directory.

    Raises
    ------
    NotACache
        Any other directory (its files are never read or removed).
    """
    state, reason = inspect_directory(directory)
    if state == "marked":
        return True
    if state in ("missing", "empty"):
        return False
    raise NotACache(directory, reason)

