"""Maintenance of a whole cache directory: listing, summarising, pruning and clearing it.

What ``passmd cache info|prune|clear`` and :class:`~passmd.runtime.cache.store.Cache`'s methods of
the same names run. Each refuses a directory that is not a passmd cache
(:class:`~passmd.runtime.cache.layout.NotACache`) and removes only the cache's own files: entries,
unreadable entries at an entry's path, and its temporary files once they are older than
:data:`STALE_TEMP_SECONDS`.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

from passmd.runtime.cache.entry import CorruptEntry, _split_entry
from passmd.runtime.cache.layout import _examine, _unlink, _walk, owned

__all__ = ["STALE_TEMP_SECONDS", "clear", "entries", "info", "prune"]

#: Age after which ``prune`` removes one of the cache's temporary files (a write takes
#: milliseconds; an older one was left by a process killed outright).
STALE_TEMP_SECONDS = 600.0


def entries(directory: Path) -> list[Path]:
    """Paths of all complete entries: regular files at entries' paths with the magic line."""
    found = []
    for kind, path in _walk(directory):
        try:
            if kind == "candidate" and _examine(path, read=False)[0] == "entry":
                found.append(path)
        except OSError:
            continue
    return found

def info(directory: Path, fingerprint: str) -> dict:
    """Summary of the directory: entries, bytes, entries per code fingerprint and function.

    Unreadable entries, the cache's own temporary files (``leftovers``) and files that
    are not the cache's (``foreign``, never touched) are counted apart; nothing is removed.

    Raises
    ------
    NotACache
        The directory exists, is not empty and has no marker of this format.
    """
    summary = {"directory": str(directory), "entries": 0, "bytes": 0, "current_code": 0,
               "other_code": 0, "unreadable": 0, "leftovers": 0, "foreign": 0, "functions": {}}
    if not owned(directory):
        return summary
    for kind, path in _walk(directory):
        if kind == "foreign":
            summary["foreign"] += 1
            continue
        try:
            size = os.lstat(path).st_size
            found = _examine(path, read=True) if kind == "candidate" else ("temp", None)
        except FileNotFoundError:
            continue
        except OSError:
            summary["unreadable"] += 1
            continue
        if found[0] == "missing":
            continue
        if found[0] == "foreign":
            summary["foreign"] += 1
            continue
        summary["bytes"] += size
        if found[0] == "temp":
            summary["leftovers"] += 1
            continue
        try:
            if found[0] == "bad":
                raise CorruptEntry(found[1])
            header, _ = _split_entry(found[1])
        except CorruptEntry:
            summary["unreadable"] += 1
            continue
        summary["entries"] += 1
        current = header.get("code") == fingerprint
        summary["current_code" if current else "other_code"] += 1
        name = str(header.get("function") or "?")
        summary["functions"][name] = summary["functions"].get(name, 0) + 1
    return summary

def prune(directory: Path, fingerprint: str) -> int:
    """Remove entries of other code fingerprints, unreadable entries, stale temporary files.

    Returns the number of files removed. Entries of the current code, temporary files
    younger than :data:`STALE_TEMP_SECONDS` (a write in progress) and files that are
    not the cache's stay.

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
            return _split_entry(data)[0].get("code") != fingerprint
        except CorruptEntry:
            return True

    return _remove(directory, doomed)

def clear(directory: Path) -> int:
    """Remove every entry (readable or not) and temporary file of the cache.

    Returns the number of files removed; files that are not the cache's stay. A write
    in progress meanwhile loses its entry (reported by that writer, which keeps its
    result).

    Raises
    ------
    NotACache
        The directory exists, is not empty and has no marker of this format.
    """
    return _remove(directory, lambda kind, path: kind == "temp" or (
        kind == "candidate" and _examine(path, read=False)[0] in ("entry", "bad")))

def _remove(directory: Path, doomed) -> int:
    """Unlink each of the cache's own files for which ``doomed(kind, path)`` holds; the count.

    Refuses a folder that is not a cache (:func:`~passmd.runtime.cache.layout.owned`); a file gone
    meanwhile is skipped.
    """
    if not owned(directory):
        return 0
    removed = 0
    for kind, path in _walk(directory):
        try:
            if doomed(kind, path):
                removed += _unlink(path)
        except FileNotFoundError:
            continue
    return removed
