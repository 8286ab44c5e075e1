"""The cache itself: :class:`~passmd.runtime.cache.store.Cache` keys, reads and writes checked entries
in a directory it owns, and summarises, prunes or clears it (rules in :mod:`passmd.runtime.cache`).
"""

from __future__ import annotations

import errno
import hashlib
import json
import os
import stat
import time
import warnings
from collections.abc import Mapping
from pathlib import Path

import platformdirs

from passmd.runtime.cache.entry import CorruptEntry, _split_entry, _TooLarge, decode_entry, encode_entry
from passmd.runtime.cache.keys import canonical, code_fingerprint, function_code, function_name
from passmd.runtime.cache.layout import (
    ENTRY_SUFFIX,
    _check_key,
    _examine,
    _temporary,
    _unlink,
    _walk,
    _write_marker,
    inspect_directory,
    owned,
)

__all__ = ["DEFAULT_CACHE_DIR", "STALE_TEMP_SECONDS", "Cache", "CacheWarning", "default_cache_dir",
           "describe_default_cache_dir"]

#: Name of the project-local cache folder the book and the tests use (``noxfile.py`` sets
#: ``PASSMD_CACHE_DIR`` to it at the repository's root); ignored by git.
DEFAULT_CACHE_DIR = ".passmd-cache"
_MISS = object()
#: Age after which ``prune`` removes one of the cache's temporary files (a write takes
#: milliseconds; an older one was left by a process killed outright).
STALE_TEMP_SECONDS = 600.0
#: Directories already reported as unusable in this process (one warning each).
_REPORTED_UNWRITABLE: set[str] = set()


class CacheWarning(UserWarning):
    """A cache entry was unusable (removed, recomputed) or the cache cannot be written."""


def default_cache_dir() -> Path:
    """The user's cache folder for passmd's results (absolute): ``results`` in
    ``platformdirs.user_cache_dir`` of ``passmd`` (``$XDG_CACHE_HOME/passmd/results`` or
    ``~/.cache/passmd/results`` on Linux, ``~/Library/Caches/passmd/results`` on macOS,
    ``%LOCALAPPDATA%\\passmd\\Cache\\results`` on Windows)."""
    return (Path(platformdirs.user_cache_dir("passmd", appauthor=False)) / "results").resolve()


def describe_default_cache_dir() -> str:
    """The default directory for messages and help: ``the user cache folder <path>``."""
    return f"the user cache folder {default_cache_dir()}"


class Cache:
    """Checked data entries on disk, keyed by function, parameters and code fingerprint.

    Parameters
    ----------
    directory : path, optional
        Where entries live; default :func:`default_cache_dir`. Created (with its marker)
        on first write; an existing directory is used only under the rules of the module
        docstring (marked, empty, or holding only the cache's own files).
    fingerprint : str, optional
        Code fingerprint mixed into every key; default
        :func:`~passmd.runtime.cache.keys.code_fingerprint`.

    Examples
    --------
    >>> cache = Cache("/tmp/passmd-doc-cache")
    >>> key = cache.key(divmod, {"a": 7, "b": 2})
    >>> cache.put(key, {"q": 3})
    True
    >>> cache.get(key)
    {'q': 3}
    """

    def __init__(self, directory: str | os.PathLike | None = None, *, fingerprint: str | None = None):
        self.directory = Path(directory).expanduser().resolve() if directory else default_cache_dir()
        self._default = not directory  # the user cache folder: a problem names the variable it comes from
        self.fingerprint = fingerprint if fingerprint is not None else code_fingerprint()
        self._usable: bool | None = None  # decided on first use (see _ready)
        self._reported: set = set()  # what _report_once reported

    def __repr__(self) -> str:
        return f"Cache({str(self.directory)!r}, fingerprint={self.fingerprint[:12]!r}...)"

    def key(self, func, params: Mapping, *, code: str | None = None) -> str:
        """Hex key of ``func(**params)`` under this cache's code fingerprint and ``func``'s own code.

        ``code``: :func:`~passmd.runtime.cache.keys.function_code` of ``func``, computed here if
        not given (a sweep computes it once for all its points).

        Raises
        ------
        Unfingerprintable
            ``func``'s code cannot be fingerprinted: its results must not be cached.
        """
        payload = {
            "function": function_name(func),
            "params": canonical(dict(params)),
            "code": self.fingerprint,
            "function_code": function_code(func) if code is None else code,
        }
        text = json.dumps(payload, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()

    def path(self, key: str) -> Path:
        """File of an entry: ``<directory>/<key[:2]>/<key>.pmc``.

        Raises
        ------
        ValueError
            If ``key`` is not 64 lowercase hexadecimal digits (what :meth:`key` returns).
        """
        _check_key(key)
        return self.directory / key[:2] / f"{key}{ENTRY_SUFFIX}"

    # ---- ownership of the directory ------------------------------------------------

    def _ready(self, create: bool) -> bool:
        """Whether entries may be read and written here; marks a new or adoptable directory.

        ``create``: make a missing directory (a write); else a missing one is a miss. A
        directory that is not usable is reported once (:class:`CacheWarning`).
        """
        if self._usable is not None:
            return self._usable
        try:
            state, reason = inspect_directory(self.directory)
            if state == "missing":
                if not create:
                    return False
                try:
                    self.directory.mkdir(parents=True)
                    state = "empty"
                except FileExistsError:  # made meanwhile, or a dangling link: look again
                    state, reason = inspect_directory(self.directory)
            if state in ("empty", "own-layout"):
                _write_marker(self.directory)
                state, reason = inspect_directory(self.directory)
        except OSError as exc:  # a readable folder that refuses its marker is read-only, not unreadable
            verb = "use" if exc.errno == errno.ENOTDIR else "write" if (
                create or exc.errno == errno.EROFS or os.access(self.directory, os.R_OK)) else "read"
            self._report_unusable(f"cannot {verb} the cache {self.directory}: {exc.strerror or exc}")
            self._usable = False
            return False
        self._usable = state == "marked"
        if state == "not-a-directory":
            self._report_unusable(f"cannot write the cache {self.directory}: it is not a directory")
        elif not self._usable:
            self._report_unusable(f"the cache directory {self.directory} {reason}")
        return self._usable
    def _subfolder(self, folder: Path, *, create: bool) -> bool:
        """Whether ``folder`` (``<directory>/<key[:2]>``) is a real directory; made on a write."""
        try:
            info = os.lstat(folder)
        except FileNotFoundError:
            if not create:
                return False
            try:
                os.mkdir(folder)
            except FileExistsError:
                pass
            info = os.lstat(folder)
        if stat.S_ISDIR(info.st_mode):
            return True
        self._report_path(folder, "a link or a file where the cache keeps a subfolder")
        return False

    # ---- reading and writing entries -----------------------------------------------

    def get(self, key: str, default=None, *, function: str | None = None):
        """The stored value, or ``default`` on a miss (absent or unusable entry).

        ``function`` given: an entry written for another function is unusable too.

        Raises
        ------
        ValueError
            If ``key`` is not a cache key (see :meth:`path`).
        """
        value = self._load(key, function)
        return default if value is _MISS else value

    def __contains__(self, key: str) -> bool:
        return self._load(key) is not _MISS

    def _load(self, key: str, function: str | None = None):
        path = self.path(key)
        if not self._ready(create=False):
            return _MISS
        try:
            if not self._subfolder(path.parent, create=False):
                return _MISS
            kind, found = _examine(path, read=True)
        except OSError as exc:  # unreadable (permissions): a miss
            verb = "use" if exc.errno == errno.ENOTDIR else "read"
            self._report_unusable(f"cannot {verb} the cache {self.directory}: {exc.strerror or exc}")
            return _MISS
        if kind == "missing":
            return _MISS
        if kind == "foreign":
            self._report_path(path, found)
            return _MISS
        if kind == "bad":
            self._discard(path, found)
            return _MISS
        try:
            header, value = decode_entry(found, key)
            if function is not None and header.get("function") not in (function, ""):
                raise CorruptEntry(f"written by {header.get('function')!r}, not {function!r}")
        except CorruptEntry as exc:
            self._discard(path, str(exc))
            return _MISS
        return value

    def _discard(self, path: Path, reason: str) -> None:
        """Report an unusable entry of the cache once and remove it (the caller recomputes it)."""
        try:
            _unlink(path)
            action = "removed; recomputing"
        except OSError:
            action = "could not remove it; recomputing"
        warnings.warn(f"cache entry {path} is unusable ({reason}); {action}", CacheWarning, stacklevel=4)

    def _report_path(self, path: Path, what: str) -> None:
        """Report once a path of the cache that holds something not the cache's (left alone)."""
        self._report_once(path, f"cache path {path} holds {what}: left in place, and this result is not "
                                "cached")

    def _report_once(self, token, message: str) -> None:
        if token not in self._reported:
            self._reported.add(token)
            warnings.warn(message, CacheWarning, stacklevel=5)

    def _report_unusable(self, message: str) -> None:
        marker = str(self.directory)
        if marker not in _REPORTED_UNWRITABLE:
            _REPORTED_UNWRITABLE.add(marker)
            hint = " (the user cache folder; PASSMD_CACHE_DIR or --cache-dir choose another)" \
                if self._default else ""
            warnings.warn(f"{message}{hint}; continuing without the cache", CacheWarning, stacklevel=4)

    def put(self, key: str, value, *, function: str = "") -> bool:
        """Store ``value`` atomically (temporary file in the same directory + ``os.replace``).

        Returns whether the entry was written. A cache that cannot be written or is not a
        passmd cache is reported once per directory (:class:`CacheWarning`), a file of
        someone else's at the entry's path once (it is never replaced), an entry above the
        size limits once; then ``False`` is returned: the caller keeps its result. The
        temporary file is removed on any exception, ``KeyboardInterrupt`` included.

        Raises
        ------
        ValueError
            If ``key`` is not a cache key (see :meth:`path`), checked first.
        TypeError
            If ``value`` holds a type the entry format does not store (checked before
            anything is written).
        """
        target = self.path(key)
        try:
            data = encode_entry(key, value, function=function, fingerprint=self.fingerprint)
        except _TooLarge as exc:
            self._report_once(("too large", function),
                              f"a result of {function or 'this function'} is not cached: {exc}")
            return False
        if not self._ready(create=True):
            return False
        try:
            if not self._subfolder(target.parent, create=True):
                return False
            kind, found = _examine(target, read=False)
            if kind == "foreign":
                self._report_path(target, found)
                return False
            # not flushed to disk first: an entry torn by a crash fails its checksum and is recomputed,
            # and a flush costs milliseconds per sweep point (more than a fit's row takes to compute)
            with _temporary(target.parent, f".{key[:16]}-", data, durable=False) as tmp:
                os.replace(tmp, target)
        except OSError as exc:
            self._report_unusable(f"cannot write the cache {self.directory}: {exc.strerror or exc}")
            return False
        return True

    # ---- the whole directory (passmd cache info|prune|clear) ---------------------

    def entries(self) -> list[Path]:
        """Paths of all complete entries: regular files at entries' paths with the magic line."""
        found = []
        for kind, path in _walk(self.directory):
            try:
                if kind == "candidate" and _examine(path, read=False)[0] == "entry":
                    found.append(path)
            except OSError:
                continue
        return found

    def info(self) -> dict:
        """Summary of the directory: entries, bytes, entries per code fingerprint and function.

        Unreadable entries, the cache's own temporary files (``leftovers``) and files that are
        not the cache's (``foreign``, never touched) are counted apart; nothing is removed.

        Raises
        ------
        NotACache
            The directory exists, is not empty and has no marker of this format.
        """
        summary = {"directory": str(self.directory), "entries": 0, "bytes": 0, "current_code": 0,
                   "other_code": 0, "unreadable": 0, "leftovers": 0, "foreign": 0, "functions": {}}
        if not owned(self.directory):
            return summary
        for kind, path in _walk(self.directory):
            try:
                size = os.lstat(path).st_size
                found, data = _examine(path, read=True) if kind == "candidate" else (kind, None)
                if found == "bad":
                    raise CorruptEntry(data)
                header = _split_entry(data)[0] if found == "entry" else None
            except FileNotFoundError:
                continue
            except (OSError, CorruptEntry):
                summary["unreadable"] += 1
                summary["bytes"] += 0 if kind == "foreign" else size
                continue
            if found in ("foreign", "missing"):
                summary["foreign"] += found == "foreign"
                continue
            summary["bytes"] += size
            if found == "temp":
                summary["leftovers"] += 1
                continue
            summary["entries"] += 1
            summary["current_code" if header.get("code") == self.fingerprint else "other_code"] += 1
            name = str(header.get("function") or "?")
            summary["functions"][name] = summary["functions"].get(name, 0) + 1
        return summary

    def prune(self) -> int:
        """Remove entries of other code fingerprints, unreadable entries, stale temporary files.

        Returns the number of files removed. Entries of the current code, temporary files
        younger than :data:`STALE_TEMP_SECONDS` (a write in progress) and files that are not
        the cache's stay.

        Raises
        ------
        NotACache
            The directory exists, is not empty and has no marker of this format.
        """
        now = time.time()

        def doomed(kind: str, path: Path) -> bool:
            if kind == "temp":
                return now - os.lstat(path).st_mtime > STALE_TEMP_SECONDS
            if kind != "candidate":
                return False
            found, data = _examine(path, read=True)
            if found != "entry":
                return found == "bad"
            try:
                return _split_entry(data)[0].get("code") != self.fingerprint
            except CorruptEntry:
                return True

        return self._remove(doomed)

    def clear(self) -> int:
        """Remove every entry (readable or not) and temporary file of the cache.

        Returns the number of files removed; files that are not the cache's stay. A write in
        progress meanwhile loses its entry (reported by that writer, which keeps its result).

        Raises
        ------
        NotACache
            The directory exists, is not empty and has no marker of this format.
        """
        return self._remove(lambda kind, path: kind == "temp" or (
            kind == "candidate" and _examine(path, read=False)[0] in ("entry", "bad")))

    def _remove(self, doomed) -> int:
        """Unlink each of the cache's own files for which ``doomed(kind, path)`` holds; the count
        (a folder that is not a cache is refused, a file gone meanwhile skipped)."""
        if not owned(self.directory):
            return 0
        removed = 0
        for kind, path in _walk(self.directory):
            try:
                if doomed(kind, path):
                    removed += _unlink(path)
            except FileNotFoundError:
                continue
        return removed
