"""On-disk cache of computed results, keyed by the function, its parameters and the code.

A result is stored under a key that hashes

* the function's module and qualified name,
* every parameter, canonicalised (:func:`canonical`): dataclasses field by field
  (with their class name), floats by ``repr`` (exact), NumPy arrays by dtype, shape
  and bytes, mappings in sorted order,
* the *code fingerprint* (:func:`code_fingerprint`): a hash of every ``passmd/**/*.py``
  source file's path and bytes, so any edit of the package invalidates every entry and
  a code change never serves a stale result (a version number alone would not).

Entry format (data, never code)
-------------------------------
Each entry is one file ``<directory>/<key[:2]>/<key>.pmc``::

    PASSMD-CACHE 1\\n
    <sha256 hex of header+payload> <length of header in bytes>\\n
    <header: UTF-8 JSON>
    <payload: the raw bytes of the stored NumPy arrays, one after the other>

The JSON header holds the key, the function's name, the code fingerprint, the creation
time and the stored value as a tree of typed nodes: ``None``, booleans, integers,
strings, floats (as ``float.hex()``, exact to the bit), lists, tuples, dicts with
string keys, and NumPy arrays or NumPy scalars (dtype, shape and a slice of the
payload; numeric dtypes only). Reading parses JSON and copies bytes into arrays: no
entry can run code when it is read (pickles could). A value of any other type (a
DataFrame, an object array, an arbitrary class) is refused with a ``TypeError`` when
it is stored; convert it where it is produced.

An entry whose magic line, checksum, header, key or (when the caller names it, as
:func:`passmd.sweep.run` does) function does not check out (corrupt, truncated, foreign
or misplaced) is reported once with a :class:`CacheWarning`,
removed, and treated as a miss, so the caller recomputes it. Entries are written
atomically: to a temporary file in the same directory, flushed to disk, then moved into
place with :func:`os.replace`; an interrupted write leaves either no entry or the
complete one. A cache that cannot be written (read-only, not a directory, owned by
another user, disk full) is reported once per directory with a :class:`CacheWarning`
and the caller goes on without caching: the computed result is never lost.

The directory is ``.passmd-cache/`` in the current working directory unless the caller
names another (``Cache(directory)``; entry points take it from the run configuration,
:class:`passmd.config.RunConfig`, whose ``cache_dir`` comes from ``$PASSMD_CACHE_DIR`` or
``--cache-dir``; this module reads no environment variable).
``passmd cache info|clear|prune`` shows, empties or prunes it (prune: entries of other
code fingerprints, unreadable entries and leftovers of the former pickle format).
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import os
import tempfile
import time
import warnings
from collections.abc import Mapping
from enum import Enum
from pathlib import Path

import numpy as np

__all__ = [
    "DEFAULT_CACHE_DIR",
    "ENTRY_SUFFIX",
    "Cache",
    "CacheWarning",
    "CorruptEntry",
    "canonical",
    "code_fingerprint",
    "decode_entry",
    "default_cache_dir",
    "encode_entry",
    "function_name",
]

#: Cache directory (relative to the current working directory) when nothing overrides it.
DEFAULT_CACHE_DIR = ".passmd-cache"
#: File suffix of an entry.
ENTRY_SUFFIX = ".pmc"
#: First line of every entry (format name and version).
MAGIC = b"PASSMD-CACHE 1\n"
#: Suffix of entries of the former pickle format: never read, removed by ``prune``/``clear``.
LEGACY_SUFFIX = ".pkl"

_PACKAGE_DIR = Path(__file__).resolve().parent
_MISS = object()
#: Directories already reported as unwritable in this process (one warning each).
_REPORTED_UNWRITABLE: set[str] = set()


class CacheWarning(UserWarning):
    """A cache entry was unusable (removed, recomputed) or the cache cannot be written."""


class CorruptEntry(ValueError):
    """An entry's bytes do not decode to a checked value (see :func:`decode_entry`)."""


def default_cache_dir() -> Path:
    """``./.passmd-cache`` of the current working directory (absolute)."""
    return Path(DEFAULT_CACHE_DIR).resolve()


def code_fingerprint(package_dir: str | os.PathLike | None = None) -> str:
    """SHA-256 over the relative path and bytes of every ``*.py`` file of the package.

    Parameters
    ----------
    package_dir : path, optional
        Root to hash; default the installed ``passmd`` package. The default is
        computed once per process (the source does not change under a running sweep).
    """
    if package_dir is None:
        return _package_fingerprint()
    return _fingerprint(Path(package_dir))


@functools.lru_cache(maxsize=1)
def _package_fingerprint() -> str:
    return _fingerprint(_PACKAGE_DIR)


def _fingerprint(root: Path) -> str:
    root = root.resolve()
    if not root.is_dir():
        raise ValueError(f"package_dir = {str(root)!r} is not a directory")
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        if "__pycache__" in path.parts:
            continue
        rel = path.relative_to(root).as_posix().encode()
        data = path.read_bytes()
        digest.update(len(rel).to_bytes(8, "little") + rel)
        digest.update(len(data).to_bytes(8, "little") + data)
    return digest.hexdigest()


def function_name(func) -> str:
    """``module:qualname`` of a function (part of every cache key)."""
    module = getattr(func, "__module__", None)
    qualname = getattr(func, "__qualname__", None)
    if module is None or qualname is None:
        raise TypeError(f"func = {func!r} has no module/qualified name; pass a top-level function")
    return f"{module}:{qualname}"


def canonical(obj):
    """A JSON-serialisable, deterministic representation of a parameter value.

    Two values have the same canonical form exactly when they are the same
    parameter: ``0.1`` and ``0.1000000001`` differ (floats by ``repr``), ``1`` and
    ``1.0`` differ (int vs float), arrays compare by dtype, shape and bytes.

    Raises
    ------
    TypeError
        For a type it does not know how to canonicalise (rather than risk a key that
        ignores part of the parameter).
    """
    if obj is None or isinstance(obj, (bool, str)):
        return obj
    if isinstance(obj, Enum):
        return {"__enum__": f"{type(obj).__qualname__}.{obj.name}"}
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return {"__float__": repr(float(obj))}
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, np.ndarray):
        arr = np.ascontiguousarray(obj)
        if arr.dtype.hasobject:
            return {"__objarray__": [canonical(x) for x in arr.ravel().tolist()], "shape": arr.shape}
        return {
            "__ndarray__": hashlib.sha256(arr.tobytes()).hexdigest(),
            "dtype": arr.dtype.str,
            "shape": list(arr.shape),
        }
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        cls = type(obj)
        return {
            "__dataclass__": f"{cls.__module__}.{cls.__qualname__}",
            "fields": {f.name: canonical(getattr(obj, f.name)) for f in dataclasses.fields(obj)},
        }
    if isinstance(obj, Mapping):
        items = [(canonical(k), canonical(v)) for k, v in obj.items()]
        items.sort(key=lambda kv: json.dumps(kv[0], sort_keys=True))
        return {"__mapping__": items}
    if isinstance(obj, (list, tuple)):
        return {"__" + type(obj).__name__ + "__": [canonical(x) for x in obj]}
    if isinstance(obj, (set, frozenset)):
        return {"__set__": sorted((canonical(x) for x in obj), key=lambda c: json.dumps(c, sort_keys=True))}
    raise TypeError(f"cannot use a {type(obj).__name__} ({obj!r}) as a cached parameter")


# --------------------------------------------------------------------------------------
# Entry format: JSON header + raw array bytes, checksummed
# --------------------------------------------------------------------------------------


def _encode_node(value, chunks: list[bytes], offset: list[int], where: str):
    """JSON node of one value; array bytes are appended to ``chunks``."""
    if value is None:
        return {"t": "none"}
    if isinstance(value, bool):
        return {"t": "bool", "v": value}
    if isinstance(value, (np.ndarray, np.generic)):
        arr = np.asarray(value)
        if arr.dtype.hasobject or arr.dtype.fields is not None or arr.dtype.kind not in "biufc":
            raise TypeError(f"cannot cache {where}: a NumPy {arr.dtype} value (numeric dtypes only)")
        data = np.ascontiguousarray(arr).tobytes()
        node = {"t": "array", "dtype": arr.dtype.str, "shape": list(arr.shape),
                "offset": offset[0], "nbytes": len(data), "scalar": isinstance(value, np.generic)}
        chunks.append(data)
        offset[0] += len(data)
        return node
    if isinstance(value, int):
        return {"t": "int", "v": int(value)}
    if isinstance(value, float):
        return {"t": "float", "v": float.hex(value)}
    if isinstance(value, str):
        return {"t": "str", "v": value}
    if isinstance(value, (list, tuple)):
        return {"t": type(value).__name__,
                "v": [_encode_node(x, chunks, offset, f"{where}[{i}]") for i, x in enumerate(value)]}
    if isinstance(value, dict):
        if not all(isinstance(k, str) for k in value):
            raise TypeError(f"cannot cache {where}: a dict with non-string keys")
        return {"t": "dict", "v": [[k, _encode_node(v, chunks, offset, f"{where}[{k!r}]")]
                                   for k, v in value.items()]}
    raise TypeError(
        f"cannot cache {where}: a {type(value).__name__} (the cache stores None, bool, int, float, "
        "str, lists, tuples, dicts and numeric NumPy arrays; convert it where it is produced)"
    )


def _decode_node(node, payload: memoryview):
    kind = node["t"]
    if kind == "none":
        return None
    if kind == "bool":
        return bool(node["v"])
    if kind == "int":
        if not isinstance(node["v"], int):
            raise CorruptEntry("int node without an integer")
        return node["v"]
    if kind == "float":
        return float.fromhex(node["v"])
    if kind == "str":
        if not isinstance(node["v"], str):
            raise CorruptEntry("str node without a string")
        return node["v"]
    if kind in ("list", "tuple"):
        items = [_decode_node(x, payload) for x in node["v"]]
        return items if kind == "list" else tuple(items)
    if kind == "dict":
        return {str(k): _decode_node(v, payload) for k, v in node["v"]}
    if kind == "array":
        dtype = np.dtype(node["dtype"])
        if dtype.hasobject or dtype.kind not in "biufc":
            raise CorruptEntry(f"array of dtype {dtype}")
        shape = tuple(int(n) for n in node["shape"])
        start, nbytes = int(node["offset"]), int(node["nbytes"])
        count = int(np.prod(shape, dtype=np.int64))
        if start < 0 or start + nbytes > len(payload) or nbytes != count * dtype.itemsize:
            raise CorruptEntry("array outside the payload")
        arr = np.frombuffer(payload[start:start + nbytes], dtype=dtype, count=count).reshape(shape).copy()
        return arr[()] if node.get("scalar") else arr
    raise CorruptEntry(f"unknown node type {kind!r}")


def encode_entry(key: str, value, *, function: str = "", fingerprint: str = "") -> bytes:
    """The bytes of one entry (format in the module docstring).

    Raises
    ------
    TypeError
        If ``value`` holds a type the format does not store.
    """
    chunks: list[bytes] = []
    tree = _encode_node(value, chunks, [0], "the value")
    header = json.dumps(
        {"format": 1, "key": key, "function": function, "code": fingerprint,
         "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), "value": tree},
        separators=(",", ":"), allow_nan=False,
    ).encode()
    payload = b"".join(chunks)
    digest = hashlib.sha256(header + payload).hexdigest()
    return MAGIC + f"{digest} {len(header)}\n".encode() + header + payload


def _split_entry(data: bytes) -> tuple[dict, memoryview]:
    """Header (checked against the checksum) and payload of an entry's bytes."""
    if not data.startswith(MAGIC):
        raise CorruptEntry("not a passmd cache entry (bad first line)")
    end = data.find(b"\n", len(MAGIC))
    if end < 0:
        raise CorruptEntry("truncated (no checksum line)")
    try:
        digest, length = data[len(MAGIC):end].decode("ascii").split(" ")
        length = int(length)
    except (UnicodeDecodeError, ValueError) as exc:
        raise CorruptEntry("unreadable checksum line") from exc
    body = data[end + 1:]
    if length < 0 or length > len(body):
        raise CorruptEntry("truncated (header shorter than announced)")
    if hashlib.sha256(body).hexdigest() != digest:
        raise CorruptEntry("checksum mismatch (the bytes changed after they were written)")
    try:
        header = json.loads(body[:length].decode())
    except (UnicodeDecodeError, ValueError) as exc:
        raise CorruptEntry("unreadable header") from exc
    if not isinstance(header, dict) or header.get("format") != 1 or "value" not in header:
        raise CorruptEntry("foreign header")
    return header, memoryview(body)[length:]


def decode_entry(data: bytes, key: str | None = None):
    """``(header, value)`` of an entry's bytes; ``key`` given: it must be the entry's key.

    Raises
    ------
    CorruptEntry
        Bad magic line, checksum, header or node, or another key than ``key``.
    """
    header, payload = _split_entry(data)
    if key is not None and header.get("key") != key:
        raise CorruptEntry(f"written for another key ({str(header.get('key'))[:12]}...)")
    try:
        value = _decode_node(header["value"], payload)
    except CorruptEntry:
        raise
    except (KeyError, TypeError, ValueError, OverflowError) as exc:
        raise CorruptEntry(f"malformed value ({type(exc).__name__})") from exc
    return header, value


class Cache:
    """Checked data entries on disk, keyed by function, parameters and code fingerprint.

    Parameters
    ----------
    directory : path, optional
        Where entries live; default :func:`default_cache_dir`. Created on first write.
    fingerprint : str, optional
        Code fingerprint mixed into every key; default :func:`code_fingerprint`.

    Examples
    --------
    >>> cache = Cache("/tmp/passmd-doc-cache")
    >>> key = cache.key(divmod, {"a": 7, "b": 2})
    >>> cache.put(key, {"q": 3})
    >>> cache.get(key)
    {'q': 3}
    """

    def __init__(self, directory: str | os.PathLike | None = None, *, fingerprint: str | None = None):
        self.directory = Path(directory).expanduser().resolve() if directory else default_cache_dir()
        self.fingerprint = fingerprint if fingerprint is not None else code_fingerprint()

    def __repr__(self) -> str:
        return f"Cache({str(self.directory)!r}, fingerprint={self.fingerprint[:12]!r}...)"

    def key(self, func, params: Mapping) -> str:
        """Hex key of ``func(**params)`` under this cache's code fingerprint."""
        payload = {
            "function": function_name(func),
            "params": canonical(dict(params)),
            "code": self.fingerprint,
        }
        text = json.dumps(payload, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()

    def path(self, key: str) -> Path:
        """File of an entry: ``<directory>/<key[:2]>/<key>.pmc``."""
        return self.directory / key[:2] / f"{key}{ENTRY_SUFFIX}"

    def get(self, key: str, default=None, *, function: str | None = None):
        """The stored value, or ``default`` on a miss (absent or unusable entry).

        ``function`` given: an entry written for another function is unusable too.
        """
        value = self._load(key, function)
        return default if value is _MISS else value

    def __contains__(self, key: str) -> bool:
        return self._load(key) is not _MISS

    def _load(self, key: str, function: str | None = None):
        path = self.path(key)
        try:
            data = path.read_bytes()
        except FileNotFoundError:
            return _MISS
        except OSError as exc:  # unreadable (permissions, a directory in the way): a miss
            self._report_unusable(f"cannot read the cache {self.directory}: {exc.strerror or exc}")
            return _MISS
        try:
            header, value = decode_entry(data, key)
            if function is not None and header.get("function") not in (function, ""):
                raise CorruptEntry(f"written by {header.get('function')!r}, not {function!r}")
        except CorruptEntry as exc:
            self._discard(path, str(exc))
            return _MISS
        return value

    def _discard(self, path: Path, reason: str) -> None:
        """Report an unusable entry once and remove it (the caller recomputes it)."""
        try:
            path.unlink()
            action = "removed; recomputing"
        except OSError:
            action = "could not remove it; recomputing"
        warnings.warn(f"cache entry {path} is unusable ({reason}); {action}", CacheWarning, stacklevel=4)

    def _report_unusable(self, message: str) -> None:
        marker = str(self.directory)
        if marker not in _REPORTED_UNWRITABLE:
            _REPORTED_UNWRITABLE.add(marker)
            warnings.warn(f"{message}; continuing without the cache", CacheWarning, stacklevel=4)

    def put(self, key: str, value, *, function: str = "") -> bool:
        """Store ``value`` atomically (temporary file in the same directory + ``os.replace``).

        Returns whether the entry was written. A cache that cannot be written is reported
        once per directory (:class:`CacheWarning`) and ``False`` is returned: the caller
        keeps its result.

        Raises
        ------
        TypeError
            If ``value`` holds a type the entry format does not store (checked before
            anything is written).
        """
        data = encode_entry(key, value, function=function, fingerprint=self.fingerprint)
        target = self.path(key)
        tmp = None
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(prefix=f".{key[:16]}-", suffix=".tmp", dir=target.parent)
            with os.fdopen(fd, "wb") as fh:
                fh.write(data)
                fh.flush()
                os.fsync(fh.fileno())
            os.replace(tmp, target)
            tmp = None
        except OSError as exc:
            self._report_unusable(f"cannot write the cache {self.directory}: {exc.strerror or exc}")
            return False
        finally:
            if tmp is not None:
                try:
                    os.unlink(tmp)
                except OSError:
                    pass
        return True

    def entries(self) -> list[Path]:
        """Paths of all complete entries (temporary files excluded)."""
        if not self.directory.is_dir():
            return []
        return sorted(p for p in self.directory.glob(f"??/*{ENTRY_SUFFIX}") if not p.name.startswith("."))

    def info(self) -> dict:
        """Summary of the directory: entries, bytes, entries per code fingerprint and function.

        Unreadable entries and leftovers (temporary files, former pickle entries) are counted
        apart; nothing is removed.
        """
        summary = {"directory": str(self.directory), "entries": 0, "bytes": 0, "current_code": 0,
                   "other_code": 0, "unreadable": 0, "leftovers": 0, "functions": {}}
        for path in self._files():
            size = path.stat().st_size
            summary["bytes"] += size
            if path.suffix != ENTRY_SUFFIX or path.name.startswith("."):
                summary["leftovers"] += 1
                continue
            try:
                header, _ = _split_entry(path.read_bytes())
            except (CorruptEntry, OSError):
                summary["unreadable"] += 1
                continue
            summary["entries"] += 1
            current = header.get("code") == self.fingerprint
            summary["current_code" if current else "other_code"] += 1
            name = str(header.get("function") or "?")
            summary["functions"][name] = summary["functions"].get(name, 0) + 1
        return summary

    def _files(self) -> list[Path]:
        if not self.directory.is_dir():
            return []
        return sorted(p for p in self.directory.glob("??/*") if p.is_file())

    def prune(self) -> int:
        """Remove entries of other code fingerprints, unreadable entries and leftovers.

        Returns the number of files removed. Entries of the current code stay.
        """
        removed = 0
        for path in self._files():
            if path.suffix == ENTRY_SUFFIX and not path.name.startswith("."):
                try:
                    header, _ = _split_entry(path.read_bytes())
                    if header.get("code") == self.fingerprint:
                        continue
                except (CorruptEntry, OSError):
                    pass
            elif path.suffix not in (".tmp", LEGACY_SUFFIX):
                continue  # not ours
            path.unlink(missing_ok=True)
            removed += 1
        return removed

    def clear(self) -> int:
        """Delete every entry and leftover file; return the number of entries removed."""
        removed = 0
        for path in self._files():
            if path.suffix in (ENTRY_SUFFIX, ".tmp", LEGACY_SUFFIX):
                removed += path.suffix == ENTRY_SUFFIX and not path.name.startswith(".")
                path.unlink(missing_ok=True)
        return removed
