"""On-disk cache of computed results, keyed by the function, its parameters and the code.

A result is stored under a key that hashes

* the function's module and qualified name,
* every parameter, canonicalised (:func:`canonical`): dataclasses field by field
  (with their class name), floats by ``repr`` (exact), NumPy arrays by dtype, shape
  and bytes, mappings in sorted order,
* the *code fingerprint* (:func:`code_fingerprint`): a hash of every ``passmd/**/*.py``
  source file's path and bytes, so any edit of the package invalidates every entry and
  a code change never serves a stale result (a version number alone would not).

Entries are pickles written atomically: to a temporary file in the same directory,
flushed to disk, then moved into place with :func:`os.replace`. An interrupted write
therefore leaves either no entry or the complete one, never a truncated entry. An
entry that cannot be read (corrupt, foreign, from another Python) counts as a miss and
is recomputed and overwritten.

The directory is ``.passmd-cache/`` in the current working directory unless the
environment variable ``PASSMD_CACHE_DIR`` (or an explicit ``directory``) says otherwise.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import os
import pickle
import tempfile
from collections.abc import Mapping
from enum import Enum
from pathlib import Path

import numpy as np

__all__ = [
    "CACHE_DIR_ENV",
    "DEFAULT_CACHE_DIR",
    "Cache",
    "canonical",
    "code_fingerprint",
    "default_cache_dir",
    "function_name",
]

#: Environment variable overriding the cache directory.
CACHE_DIR_ENV = "PASSMD_CACHE_DIR"
#: Cache directory (relative to the current working directory) when nothing overrides it.
DEFAULT_CACHE_DIR = ".passmd-cache"

_PACKAGE_DIR = Path(__file__).resolve().parent
_MISS = object()


def default_cache_dir() -> Path:
    """``$PASSMD_CACHE_DIR`` if set, else ``./.passmd-cache`` (absolute)."""
    env = os.environ.get(CACHE_DIR_ENV)
    return Path(env if env else DEFAULT_CACHE_DIR).expanduser().resolve()


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


class Cache:
    """Pickled results on disk, keyed by function, parameters and code fingerprint.

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
        """File of an entry: ``<directory>/<key[:2]>/<key>.pkl``."""
        return self.directory / key[:2] / f"{key}.pkl"

    def get(self, key: str, default=None):
        """The stored value, or ``default`` on a miss (absent or unreadable entry)."""
        value = self._load(key)
        return default if value is _MISS else value

    def __contains__(self, key: str) -> bool:
        return self._load(key) is not _MISS

    def _load(self, key: str):
        try:
            with open(self.path(key), "rb") as fh:
                entry = pickle.load(fh)
        except FileNotFoundError:
            return _MISS
        except Exception:  # corrupt, truncated or incompatible entry: a miss, recomputed
            return _MISS
        if not isinstance(entry, dict) or entry.get("key") != key or "value" not in entry:
            return _MISS
        return entry["value"]

    def put(self, key: str, value) -> None:
        """Store ``value`` atomically (temporary file in the same directory + ``os.replace``)."""
        target = self.path(key)
        target.parent.mkdir(parents=True, exist_ok=True)
        data = pickle.dumps({"key": key, "value": value}, protocol=pickle.HIGHEST_PROTOCOL)
        fd, tmp = tempfile.mkstemp(prefix=f".{key[:16]}-", suffix=".tmp", dir=target.parent)
        try:
            with os.fdopen(fd, "wb") as fh:
                fh.write(data)
                fh.flush()
                os.fsync(fh.fileno())
            os.replace(tmp, target)
        except BaseException:
            try:
                os.unlink(tmp)
            except OSError:
                pass
            raise

    def entries(self) -> list[Path]:
        """Paths of all complete entries (temporary files excluded)."""
        if not self.directory.is_dir():
            return []
        return sorted(p for p in self.directory.glob("??/*.pkl") if not p.name.startswith("."))

    def clear(self) -> int:
        """Delete every entry and leftover temporary file; return the number of entries removed."""
        removed = 0
        if not self.directory.is_dir():
            return 0
        for path in self.directory.glob("??/*"):
            if path.suffix in (".pkl", ".tmp") and path.is_file():
                removed += path.suffix == ".pkl"
                path.unlink(missing_ok=True)
        return removed
