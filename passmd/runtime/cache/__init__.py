"""On-disk cache of computed results, keyed by the function, its parameters and the code.

A result is stored under a key that hashes

* the function's module and qualified name,
* every parameter, canonicalised (:func:`~passmd.runtime.cache.keys.canonical`): dataclasses
  field by field (with their class name), floats by ``repr`` (exact), NumPy arrays by dtype,
  shape and bytes, mappings in sorted order,
* the *code fingerprint* (:func:`~passmd.runtime.cache.keys.code_fingerprint`): a hash of
  every ``passmd/**/*.py`` source file's path and bytes, so any edit of the package
  invalidates every entry and a code change never serves a stale result (a version number
  alone would not),
* the *function's own code* (:func:`~passmd.runtime.cache.keys.function_code`): for a
  function outside passmd (a user's own, in a script, notebook or module) its bytecode,
  defaults, closure values, the plain-valued globals it reads and, recursively, the user
  code it calls; a function whose code cannot be fingerprinted this way raises
  :class:`~passmd.runtime.cache.keys.Unfingerprintable` and is not cached
  (:func:`passmd.runtime.sweep.run` says so in one line).

Entry format (data, never code)
-------------------------------
Each entry is one file ``<directory>/<key[:2]>/<key>.pmc`` (``key``: 64 lowercase hex
digits, checked before it becomes a path)::

    PASSMD-CACHE 1\\n
    <sha256 hex of header+payload> <length of header in bytes>\\n
    <header: UTF-8 JSON>
    <payload: the raw bytes of the stored NumPy arrays, one after the other>

The JSON header holds the key, the function's name, the code fingerprint, the creation time
and the stored value as a tree of typed nodes: ``None``, booleans, integers, strings, floats
(as ``float.hex()``, exact to the bit), lists, tuples, dicts with string keys, and NumPy
arrays or NumPy scalars (dtype, shape and a slice of the payload; numeric dtypes only).
Reading parses JSON and copies bytes into arrays: no entry can run code when it is read
(pickles could). A value of any other type (a DataFrame, an object array, an arbitrary
class) or nested deeper than :data:`~passmd.runtime.cache.entry.MAX_DEPTH` levels is refused
with a ``TypeError`` when it is stored; convert it where it is produced. An entry larger
than :data:`~passmd.runtime.cache.entry.MAX_ENTRY_BYTES` or with a header larger than
:data:`~passmd.runtime.cache.entry.MAX_HEADER_BYTES` is not stored (one
:class:`~passmd.runtime.cache.store.CacheWarning`; the caller keeps its result).

An entry whose size (at most :data:`~passmd.runtime.cache.entry.MAX_ENTRY_BYTES`), checksum,
header (also: above its size limit, nested too deeply), key or (when the caller names it, as
:func:`passmd.runtime.sweep.run` does) function does not check out (corrupt, truncated,
foreign or misplaced), or whose path holds a link or a special file instead of a regular
file, is reported once with a :class:`~passmd.runtime.cache.store.CacheWarning`, removed (a
link itself, never its target), and treated as a miss, so the caller recomputes it. Entries
are written atomically: to a temporary file ``.<key[:16]>-<random>.tmp`` in the same
directory, flushed to disk, then moved into place with :func:`os.replace`; an interrupted
write (any exception, also ``KeyboardInterrupt`` or the exception a signal handler raises)
removes its temporary file, and one killed outright leaves one that ``prune`` removes once
it is stale (:data:`~passmd.runtime.cache.maintenance.STALE_TEMP_SECONDS`). A cache that
cannot be written (read-only, not a directory, owned by another user, disk full) is reported
once per directory with a :class:`~passmd.runtime.cache.store.CacheWarning` and the caller
goes on without caching: the computed result is never lost.

Ownership: the cache deletes only its own files
------------------------------------------------
A cache directory carries the marker ``CACHEDIR.TAG`` (a cache directory tag, which backup
tools skip, naming the format, ``PASSMD-CACHE 1``).
:class:`~passmd.runtime.cache.store.Cache` writes it when it creates the directory, or on
its first use of an existing directory that is empty or holds only files of the cache's own
layout (two-hex-digit subfolders of entries that start with the magic line, and its own
temporary files): a cache filled before markers existed is adopted. Any other directory
without the marker (a mistyped path, a folder of the user's) is never read from, written
into or pruned: a sweep reports it once and goes on without the cache, and the methods
``info``, ``prune`` and ``clear`` of :class:`~passmd.runtime.cache.store.Cache` raise
:class:`~passmd.runtime.cache.layout.NotACache` (``passmd cache`` refuses it with one line);
the same holds for a marker of another format version.

Even inside a marked cache, deletion touches only files at an entry's path
(``<key[:2]>/<key>.pmc``) that start with the magic line, or that are links or special files
there (the link itself is removed), and the cache's own temporary files. Any other file
(also a regular file at an entry's path that is not an entry: it is neither removed nor
replaced, and its point is not cached) is reported as foreign and left alone.

The directory is the user's cache folder for passmd
(:func:`~passmd.runtime.cache.store.default_cache_dir`, e.g. ``~/.cache/passmd/results`` on
Linux, via ``platformdirs``) unless the caller names another (``Cache(directory)``; entry
points take it from the run configuration, :class:`passmd.runtime.config.RunConfig`, whose
``cache_dir`` comes from ``$PASSMD_CACHE_DIR`` or ``--cache-dir``; this module reads no
environment variable). A run of the command line or the API leaves nothing in the folder it
runs in; the book and the tests (``noxfile.py``) set ``PASSMD_CACHE_DIR`` to the project's
own ``.passmd-cache/`` (:data:`~passmd.runtime.cache.store.DEFAULT_CACHE_DIR`), which they
share. ``passmd cache info|clear|prune`` shows, empties or prunes it (prune: entries of
other code fingerprints, unreadable entries and stale temporary files).

The code is split by concern: :mod:`~passmd.runtime.cache.keys` (what a key hashes),
:mod:`~passmd.runtime.cache.entry` (an entry's bytes), :mod:`~passmd.runtime.cache.layout`
(the directory's marker and names), :mod:`~passmd.runtime.cache.store`
(:class:`~passmd.runtime.cache.store.Cache`) and :mod:`~passmd.runtime.cache.maintenance`
(``info``, ``prune``, ``clear``); every public name is importable from
``passmd.runtime.cache``.
"""

from passmd.runtime.cache.entry import (
    FORMAT,
    MAGIC,
    MAX_DEPTH,
    MAX_ENTRY_BYTES,
    MAX_HEADER_BYTES,
    CorruptEntry,
    decode_entry,
    encode_entry,
)
from passmd.runtime.cache.keys import (
    Unfingerprintable,
    canonical,
    code_fingerprint,
    function_code,
    function_name,
)
from passmd.runtime.cache.layout import ENTRY_SUFFIX, MARKER_NAME, NotACache
from passmd.runtime.cache.maintenance import STALE_TEMP_SECONDS
from passmd.runtime.cache.store import (
    DEFAULT_CACHE_DIR,
    Cache,
    CacheWarning,
    default_cache_dir,
    describe_default_cache_dir,
)

__all__ = [
    "DEFAULT_CACHE_DIR",
    "ENTRY_SUFFIX",
    "FORMAT",
    "MAGIC",
    "MARKER_NAME",
    "MAX_DEPTH",
    "MAX_ENTRY_BYTES",
    "MAX_HEADER_BYTES",
    "STALE_TEMP_SECONDS",
    "Cache",
    "CacheWarning",
    "CorruptEntry",
    "NotACache",
    "Unfingerprintable",
    "canonical",
    "code_fingerprint",
    "decode_entry",
    "default_cache_dir",
    "describe_default_cache_dir",
    "encode_entry",
    "function_code",
    "function_name",
]
