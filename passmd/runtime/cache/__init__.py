"""On-disk cache of computed results, keyed by the function, its parameters and the code.

A key hashes the function's module and qualified name; every parameter, canonicalised
(:func:`~passmd.runtime.cache.keys.canonical`: dataclasses field by field, floats by ``repr``,
arrays by dtype, shape and bytes, mappings sorted); the *code fingerprint*
(:func:`~passmd.runtime.cache.keys.code_fingerprint`, a hash of every ``passmd/**/*.py``
file's path and bytes: any edit of the package invalidates every entry); and the *function's
own code* (:func:`~passmd.runtime.cache.keys.function_code`: for a function outside passmd its
bytecode, defaults, closure, plain-valued globals and, recursively, the user code it calls;
one that cannot be fingerprinted raises :class:`~passmd.runtime.cache.keys.Unfingerprintable`
and is not cached).

Entry format (data, never code)
-------------------------------
One file ``<directory>/<key[:2]>/<key>.pmc`` per entry (``key``: 64 lowercase hex digits,
checked before it becomes a path)::

    PASSMD-CACHE 1\\n
    <sha256 hex of header+payload> <length of header in bytes>\\n
    <header: UTF-8 JSON>
    <payload: the raw bytes of the stored NumPy arrays, one after the other>

The header holds the key, the function's name, the code fingerprint, the creation time and
the value as a tree of typed nodes (``None``, booleans, integers, strings, floats as
``float.hex()``, lists, tuples, string-keyed dicts, numeric NumPy arrays and scalars as a
slice of the payload). Reading parses JSON and copies bytes: no entry can run code (a pickle
could). Any other type, or nesting deeper than
:data:`~passmd.runtime.cache.entry.MAX_DEPTH`, is refused with a ``TypeError`` when stored;
an entry above :data:`~passmd.runtime.cache.entry.MAX_ENTRY_BYTES` (header above
:data:`~passmd.runtime.cache.entry.MAX_HEADER_BYTES`) is not stored (one
:class:`~passmd.runtime.cache.store.CacheWarning`; the caller keeps its result).

An entry whose size, checksum, header, key or (when the caller names it) function does not
check out, or whose path holds a link or a special file, is reported once
(:class:`~passmd.runtime.cache.store.CacheWarning`), removed (a link itself, never its target)
and recomputed. Writes are atomic: a temporary file ``.<key[:16]>-<random>.tmp`` in the same
folder, moved into place with :func:`os.replace` (not flushed to disk first: an entry a crash
tore fails its checksum, is reported and recomputed); any exception (also
``KeyboardInterrupt``) removes it, and one left by a killed process is removed by ``prune``
once stale (:data:`~passmd.runtime.cache.store.STALE_TEMP_SECONDS`). A cache that cannot be
written is reported once per directory and the caller goes on without it.

Ownership: the cache deletes only its own files
------------------------------------------------
A cache directory carries the marker ``CACHEDIR.TAG`` (a cache directory tag naming the
format), written when :class:`~passmd.runtime.cache.store.Cache` creates the directory or
first uses one that is empty or holds only files of the cache's own layout (a cache from
before markers is adopted). Any other directory (a mistyped path, a folder of the user's, a
marker of another format) is never read, written or pruned: a sweep reports it once and goes
on without the cache, and ``info``, ``prune`` and ``clear`` raise
:class:`~passmd.runtime.cache.layout.NotACache`. Inside a marked cache, deletion touches only
files at an entry's path that start with the magic line, links or special files there, and
the cache's own temporary files; anything else is reported as foreign and left alone.

The directory is :func:`~passmd.runtime.cache.store.default_cache_dir` (the user's cache
folder, via ``platformdirs``) unless the caller names another; entry points take it from
:class:`passmd.runtime.config.RunConfig` (``$PASSMD_CACHE_DIR`` or ``--cache-dir``; this
module reads no environment variable). The book and the tests share the project's
``.passmd-cache/`` (:data:`~passmd.runtime.cache.store.DEFAULT_CACHE_DIR`). Modules:
:mod:`~passmd.runtime.cache.keys` (what a key hashes), :mod:`~passmd.runtime.cache.entry`
(an entry's bytes), :mod:`~passmd.runtime.cache.layout` (the directory's marker and names),
:mod:`~passmd.runtime.cache.store` (:class:`~passmd.runtime.cache.store.Cache`, with ``info``,
``prune`` and ``clear``); every public name is importable from ``passmd.runtime.cache``.
"""

from passmd.runtime.cache.entry import (
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
from passmd.runtime.cache.layout import MARKER_NAME, NotACache
from passmd.runtime.cache.store import (
    DEFAULT_CACHE_DIR,
    STALE_TEMP_SECONDS,
    Cache,
    CacheWarning,
    default_cache_dir,
    describe_default_cache_dir,
)

__all__ = [
    "DEFAULT_CACHE_DIR",
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
