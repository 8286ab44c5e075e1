"""On-disk cache of computed results, keyed by the function, its parameters and the code.

A result is stored under a key that hashes

* the function's module and qualified name,
* every parameter, canonicalised (:func:`canonical`): dataclasses field by field
  (with their class name), floats by ``repr`` (exact), NumPy arrays by dtype, shape
  and bytes, mappings in sorted order,
* the *code fingerprint* (:func:`code_fingerprint`): a hash of every ``passmd/**/*.py``
  source file's path and bytes, so any edit of the package invalidates every entry and
  a code change never serves a stale result (a version number alone would not),
* the *function's own code* (:func:`function_code`): for a function outside passmd (a
  user's own, in a script, notebook or module) its bytecode, defaults, closure values,
  the plain-valued globals it reads and, recursively, the user code it calls; a function
  whose code cannot be fingerprinted this way raises :class:`Unfingerprintable` and is
  not cached (:func:`passmd.runtime.sweep.run` says so in one line).

Entry format (data, never code)
-------------------------------
Each entry is one file ``<directory>/<key[:2]>/<key>.pmc`` (``key``: 64 lowercase hex
digits, checked before it becomes a path)::

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
DataFrame, an object array, an arbitrary class) or nested deeper than
:data:`MAX_DEPTH` levels is refused with a ``TypeError`` when it is stored; convert it
where it is produced. An entry larger than :data:`MAX_ENTRY_BYTES` or with a header
larger than :data:`MAX_HEADER_BYTES` is not stored (one :class:`CacheWarning`; the
caller keeps its result).

An entry whose size (at most :data:`MAX_ENTRY_BYTES`), checksum, header (also: above
its size limit, nested too deeply), key or (when the caller names it, as
:func:`passmd.runtime.sweep.run` does) function does not check out (corrupt, truncated,
foreign or misplaced), or whose path holds a link or a special file instead of a regular
file, is reported once with a
:class:`CacheWarning`, removed (a link itself, never its target), and treated as a miss,
so the caller recomputes it. Entries are written atomically: to a temporary file
``.<key[:16]>-<random>.tmp`` in the same directory, flushed to disk, then moved into
place with :func:`os.replace`; an interrupted write (any exception, also
``KeyboardInterrupt`` or the exception a signal handler raises) removes its temporary
file, and one killed outright leaves one that ``prune`` removes once it is stale
(:data:`STALE_TEMP_SECONDS`). A cache that cannot be written (read-only, not a
directory, owned by another user, disk full) is reported once per directory with a
:class:`CacheWarning` and the caller goes on without caching: the computed result is
never lost.

Ownership: the cache deletes only its own files
------------------------------------------------
A cache directory carries the marker ``CACHEDIR.TAG`` (a cache directory tag, which
backup tools skip, naming the format, ``PASSMD-CACHE 1``). :class:`Cache` writes it when
it creates the directory, or on its first use of an existing directory that is empty or
holds only files of the cache's own layout (two-hex-digit subfolders of entries that start
with the magic line, and its own temporary files): a cache filled before markers existed
is adopted. Any other directory without the marker (a mistyped path, a folder of the
user's) is never read from, written into or pruned: a sweep reports it once and goes on
without the cache, and :meth:`Cache.info`, :meth:`Cache.prune` and :meth:`Cache.clear`
raise :class:`NotACache` (``passmd cache`` refuses it with one line); the same holds for
a marker of another format version.

Even inside a marked cache, deletion touches only files at an entry's path
(``<key[:2]>/<key>.pmc``) that start with the magic line, or that are links or special
files there (the link itself is removed), and the cache's own temporary files. Any
other file (also a regular file at an entry's path that is not an entry: it is neither
removed nor replaced, and its point is not cached) is reported as foreign and left alone.

The directory is the user's cache folder for passmd (:func:`default_cache_dir`, e.g.
``~/.cache/passmd/results`` on Linux, via ``platformdirs``) unless the caller names another
(``Cache(directory)``; entry points take it from the run configuration,
:class:`passmd.runtime.config.RunConfig`, whose ``cache_dir`` comes from ``$PASSMD_CACHE_DIR`` or
``--cache-dir``; this module reads no environment variable). A run of the command line or the
API leaves nothing in the folder it runs in; the book and the tests (``noxfile.py``) set
``PASSMD_CACHE_DIR`` to the project's own ``.passmd-cache/`` (:data:`DEFAULT_CACHE_DIR`), which
they share.
``passmd cache info|clear|prune`` shows, empties or prunes it (prune: entries of other
code fingerprints, unreadable entries and stale temporary files).
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import inspect
import json
import os
import re
import stat
import sys
import sysconfig
import tempfile
import time
import types
import warnings
from collections.abc import Mapping
from enum import Enum
from pathlib import Path

import numpy as np
import platformdirs

__all__ = [
    "DEFAULT_CACHE_DIR",
    "ENTRY_SUFFIX",
    "FORMAT",
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

#: Name of the project-local cache folder the book and the tests use (``noxfile.py`` sets
#: ``PASSMD_CACHE_DIR`` to it at the repository's root); ignored by git.
DEFAULT_CACHE_DIR = ".passmd-cache"
#: File suffix of an entry.
ENTRY_SUFFIX = ".pmc"
#: Format name and version: the first line of every entry and the marker's format line.
FORMAT = "PASSMD-CACHE 1"
#: First line of every entry.
MAGIC = FORMAT.encode() + b"\n"
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
#: Largest marker file read (the tag is a few lines).
_MARKER_MAX_BYTES = 4096
#: Largest entry file read or written, in bytes (results are KiB to MiB; arrays live here).
MAX_ENTRY_BYTES = 2**30
#: Largest JSON header read or written, in bytes (the value tree without its array bytes).
MAX_HEADER_BYTES = 16 * 2**20
#: Deepest nesting of a stored value (a dict in a list in a dict ... counts one per level).
MAX_DEPTH = 64
#: Age after which ``prune`` removes one of the cache's temporary files (a write takes
#: milliseconds; an older one was left by a process killed outright).
STALE_TEMP_SECONDS = 600.0

#: Names the cache owns: subfolders, entries and temporary files (groups: the key's first
#: two digits, which must be the subfolder's name).
_KEY = re.compile(r"[0-9a-f]{64}")
_SUBDIR = re.compile(r"[0-9a-f]{2}")
_ENTRY_NAME = re.compile(r"([0-9a-f]{2})[0-9a-f]{62}" + re.escape(ENTRY_SUFFIX))
_TEMP_NAME = re.compile(r"\.([0-9a-f]{2})[0-9a-f]{14}-[a-z0-9_]{1,32}\.tmp")
_MARKER_TEMP_NAME = re.compile(r"\.CACHEDIR\.TAG-[a-z0-9_]{1,32}\.tmp")

#: The ``passmd`` package folder (this module is ``passmd/runtime/cache.py``).
_PACKAGE_DIR = Path(__file__).resolve().parents[1]
_MISS = object()
#: Directories already reported as unusable in this process (one warning each).
_REPORTED_UNWRITABLE: set[str] = set()


class CacheWarning(UserWarning):
    """A cache entry was unusable (removed, recomputed) or the cache cannot be written."""


class CorruptEntry(ValueError):
    """An entry's bytes do not decode to a checked value (see :func:`decode_entry`)."""


class NotACache(ValueError):
    """A directory is not a passmd cache (no marker of this format): nothing in it is touched.

    ``directory`` is the directory, ``reason`` says why (``str()`` joins both).
    """

    def __init__(self, directory: Path, reason: str):
        super().__init__(f"{directory} {reason}")
        self.directory, self.reason = directory, reason


class _TooLarge(ValueError):
    """An encoded entry above :data:`MAX_ENTRY_BYTES` or :data:`MAX_HEADER_BYTES`."""


def default_cache_dir() -> Path:
    """The user's cache folder for passmd's results (absolute): ``results`` in
    ``platformdirs.user_cache_dir`` of ``passmd`` (``$XDG_CACHE_HOME/passmd/results`` or
    ``~/.cache/passmd/results`` on Linux, ``~/Library/Caches/passmd/results`` on macOS,
    ``%LOCALAPPDATA%\\passmd\\Cache\\results`` on Windows)."""
    return (Path(platformdirs.user_cache_dir("passmd", appauthor=False)) / "results").resolve()


def describe_default_cache_dir() -> str:
    """The default directory for messages and help: ``the user cache folder <path>``."""
    return f"the user cache folder {default_cache_dir()}"


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


# --------------------------------------------------------------------------------------
# Fingerprint of the swept function's own code
# --------------------------------------------------------------------------------------


class Unfingerprintable(TypeError):
    """A function whose code the cache cannot fingerprint (its results are not cached)."""


#: Folders of the Python installation (standard library, site-packages): modules there are
#: libraries, named by module and version in a fingerprint, not hashed.
def _library_roots() -> tuple[Path, ...]:
    roots = set()
    for name in ("stdlib", "platstdlib", "purelib", "platlib"):
        try:
            roots.add(Path(sysconfig.get_path(name)).resolve())
        except (KeyError, TypeError, OSError):
            continue
    return tuple(sorted(roots))


_LIBRARY_ROOTS = _library_roots()


def _origin(module_name: str | None) -> str:
    """``"passmd"`` (covered by the package fingerprint), ``"library"`` or ``"user"``."""
    module = sys.modules.get(module_name or "")
    if module is None:
        return "library" if module_name in sys.builtin_module_names else "user"
    file = getattr(module, "__file__", None)
    if file is None:  # built into the interpreter or frozen; else a notebook's or an exec'd namespace
        origin = getattr(getattr(module, "__spec__", None), "origin", None)
        builtin = module_name in sys.builtin_module_names or origin in ("built-in", "frozen")
        return "library" if builtin else "user"
    path = Path(file).resolve()
    if path.is_relative_to(_PACKAGE_DIR) and (module_name == "passmd" or module_name.startswith("passmd.")):
        return "passmd"
    if any(path.is_relative_to(root) for root in _LIBRARY_ROOTS):
        return "library"
    return "user"


def _library_version(module_name: str) -> str:
    top = sys.modules.get(module_name.partition(".")[0])
    return str(getattr(top, "__version__", "")) if top is not None else ""


def function_code(func) -> str:
    """Fingerprint of the code a swept function runs beyond passmd itself.

    A function of the ``passmd`` package is covered by :func:`code_fingerprint` and gives
    ``"passmd"``. Any other function (a user's, defined in a script, a notebook or a module
    of their own) is hashed from what decides its results: its bytecode, constants and
    names (not its line numbers), its defaults, the values of its closure, the globals it
    names that are plain values (numbers, strings, arrays, dataclasses: as
    :func:`canonical`), and, recursively, the functions and classes of user code it names
    (a user module it names: the bytes of its source file). Library functions and modules
    (the standard library, site-packages) count by name and version, ``functools.partial``
    by its function and arguments.

    Raises
    ------
    Unfingerprintable
        The function names something whose state cannot be fingerprinted (an arbitrary
        object, a class without source, a callable instance); the message says what.
    """
    digest = hashlib.sha256()
    digest.update(json.dumps(_code_node(func, set(), "func"), sort_keys=True,
                             separators=(",", ":")).encode())
    return digest.hexdigest()


def _code_node(obj, seen: set, where: str):
    """A JSON-serialisable node standing for what ``obj`` contributes to a result."""
    if isinstance(obj, functools.partial):
        return {"partial": _code_node(obj.func, seen, where),
                "args": [_value_node(a, seen, f"{where} argument") for a in obj.args],
                "keywords": {k: _value_node(v, seen, f"{where} argument {k}")
                             for k, v in obj.keywords.items()}}
    if isinstance(obj, types.MethodType):
        return {"method": _code_node(obj.__func__, seen, where),
                "self": _value_node(obj.__self__, seen, f"{where}.__self__")}
    module = getattr(obj, "__module__", None)
    name = f"{module}:{getattr(obj, '__qualname__', getattr(obj, '__name__', '?'))}"
    origin = _origin(module)
    if origin == "passmd":
        return {"passmd": name}
    if origin == "library" or isinstance(obj, (types.BuiltinFunctionType, types.BuiltinMethodType)):
        return {"library": name, "version": _library_version(module or "")}
    if id(obj) in seen:
        return {"seen": name}
    seen.add(id(obj))
    if isinstance(obj, types.FunctionType):
        code = obj.__code__
        closure = {}
        for var, cell in zip(code.co_freevars, obj.__closure__ or (), strict=True):
            try:
                closure[var] = _value_node(cell.cell_contents, seen, f"{name} closure variable {var!r}")
            except ValueError:  # an empty cell (a variable assigned later)
                closure[var] = None
        return {
            "function": name,
            "code": _bytecode(code),
            "defaults": _value_node(obj.__defaults__, seen, f"{name} defaults"),
            "kwdefaults": _value_node(obj.__kwdefaults__, seen, f"{name} defaults"),
            "closure": closure,
            "globals": _globals_node(code, obj.__globals__, seen, name),
        }
    if isinstance(obj, type):
        try:
            source = inspect.getsource(obj)
        except (OSError, TypeError) as exc:
            raise Unfingerprintable(f"{where} is the class {name}, whose source cannot be read") from exc
        methods = {k: _code_node(v, seen, f"{name}.{k}") for k, v in vars(obj).items()
                   if isinstance(v, types.FunctionType)}
        return {"class": name, "source": hashlib.sha256(source.encode()).hexdigest(), "methods": methods}
    inner = getattr(obj, "__wrapped__", None) or getattr(obj, "py_func", None)  # lru_cache, numba
    if inner is not None and inner is not obj:
        return {"wrapper": type(obj).__qualname__, "wrapped": _code_node(inner, seen, where)}
    raise Unfingerprintable(f"{where} is a {type(obj).__name__} object ({name}), not a function")


def _bytecode(code: types.CodeType):
    """The parts of a code object that decide what it computes (no file name or line numbers)."""
    consts = [_bytecode(c) if isinstance(c, types.CodeType) else _constant(c) for c in code.co_consts]
    return {"bytes": code.co_code.hex(), "consts": consts, "names": list(code.co_names),
            "varnames": list(code.co_varnames), "freevars": list(code.co_freevars),
            "cellvars": list(code.co_cellvars), "args": [code.co_argcount, code.co_posonlyargcount,
                                                         code.co_kwonlyargcount], "flags": code.co_flags}


def _constant(value):
    """A code constant's canonical form (constants are numbers, strings, bytes, tuples, frozensets)."""
    if isinstance(value, bytes):
        return {"__bytes__": value.hex()}
    if isinstance(value, (tuple, frozenset)):
        return {f"__{type(value).__name__}__": [_constant(x) for x in value]}
    if value is Ellipsis:
        return {"__ellipsis__": True}
    if isinstance(value, complex):
        return {"__complex__": [repr(value.real), repr(value.imag)]}
    return canonical(value)


def _names(code: types.CodeType):
    """Every name the code (and the code nested in it) loads: globals and attributes alike."""
    yield from code.co_names
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            yield from _names(const)


def _globals_node(code: types.CodeType, namespace: dict, seen: set, name: str) -> dict:
    """The globals a function's code names, each by what it contributes (missing: a builtin)."""
    found = {}
    for var in sorted(set(_names(code))):
        if var not in namespace:
            continue  # a builtin or an attribute name: its name is in the bytecode already
        found[var] = _value_node(namespace[var], seen, f"{name} global {var!r}")
    return found


def _value_node(value, seen: set, where: str):
    """A value a function reads: plain values canonically, code recursively, modules by file."""
    if isinstance(value, types.ModuleType):
        origin = _origin(value.__name__)
        if origin != "user":
            return {"module": value.__name__, "origin": origin, "version": _library_version(value.__name__)}
        file = getattr(value, "__file__", None)
        try:
            return {"module": value.__name__, "source": hashlib.sha256(Path(file).read_bytes()).hexdigest()}
        except (OSError, TypeError) as exc:
            raise Unfingerprintable(f"{where} is the module {value.__name__}, whose source cannot be "
                                    "read") from exc
    if isinstance(value, (types.FunctionType, types.BuiltinFunctionType, types.MethodType, functools.partial,
                          type)) or hasattr(value, "__wrapped__") or hasattr(value, "py_func"):
        return _code_node(value, seen, where)
    if isinstance(value, tuple) and not hasattr(value, "_fields"):
        return {"__tuple__": [_value_node(x, seen, where) for x in value]}
    try:
        node = canonical(value)
    except TypeError:
        pass
    else:  # an instance of a class of user code: its methods may run too
        cls = type(value)
        if _origin(cls.__module__) == "user":
            return {"value": node, "class": _code_node(cls, seen, where)}
        return node
    if callable(value) and _origin(getattr(value, "__module__", None)) in ("passmd", "library"):
        return {"callable": f"{getattr(value, '__module__', '?')}:{type(value).__qualname__}",
                "version": _library_version(getattr(value, "__module__", "") or "")}
    raise Unfingerprintable(f"{where} is a {type(value).__name__}, whose state cannot be fingerprinted")


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


def _encode_node(value, chunks: list[bytes], offset: list[int], where: str, depth: int = 1):
    """JSON node of one value; array bytes are appended to ``chunks``."""
    if depth > MAX_DEPTH:
        raise TypeError(f"cannot cache {where}: the value nests deeper than {MAX_DEPTH} levels")
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
        items = [_encode_node(x, chunks, offset, f"{where}[{i}]", depth + 1) for i, x in enumerate(value)]
        return {"t": type(value).__name__, "v": items}
    if isinstance(value, dict):
        if not all(isinstance(k, str) for k in value):
            raise TypeError(f"cannot cache {where}: a dict with non-string keys")
        return {"t": "dict", "v": [[k, _encode_node(v, chunks, offset, f"{where}[{k!r}]", depth + 1)]
                                   for k, v in value.items()]}
    raise TypeError(
        f"cannot cache {where}: a {type(value).__name__} (the cache stores None, bool, int, float, "
        "str, lists, tuples, dicts and numeric NumPy arrays; convert it where it is produced)"
    )


def _decode_node(node, payload: memoryview, depth: int = 1):
    if depth > MAX_DEPTH:
        raise CorruptEntry(f"the value nests deeper than {MAX_DEPTH} levels")
    if not isinstance(node, dict):
        raise CorruptEntry("a value node that is not an object")
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
        items = [_decode_node(x, payload, depth + 1) for x in node["v"]]
        return items if kind == "list" else tuple(items)
    if kind == "dict":
        return {str(k): _decode_node(v, payload, depth + 1) for k, v in node["v"]}
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
        If ``value`` holds a type the format does not store, or nests deeper than
        :data:`MAX_DEPTH` levels.
    ValueError
        If the entry would exceed :data:`MAX_ENTRY_BYTES` or its header
        :data:`MAX_HEADER_BYTES` (it could not be read back).
    """
    chunks: list[bytes] = []
    tree = _encode_node(value, chunks, [0], "the value")
    header = json.dumps(
        {"format": 1, "key": key, "function": function, "code": fingerprint,
         "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), "value": tree},
        separators=(",", ":"), allow_nan=False,
    ).encode()
    if len(header) > MAX_HEADER_BYTES:
        raise _TooLarge(f"its header of {len(header)} bytes is above the {MAX_HEADER_BYTES}-byte limit")
    payload = b"".join(chunks)
    digest = hashlib.sha256(header + payload).hexdigest()
    data = MAGIC + f"{digest} {len(header)}\n".encode() + header + payload
    if len(data) > MAX_ENTRY_BYTES:
        raise _TooLarge(f"its {len(data)} bytes are above the {MAX_ENTRY_BYTES}-byte limit")
    return data


def _split_entry(data: bytes) -> tuple[dict, memoryview]:
    """Header (checked against the checksum and the limits) and payload of an entry's bytes."""
    if not data.startswith(MAGIC):
        raise CorruptEntry("not a passmd cache entry (bad first line)")
    if len(data) > MAX_ENTRY_BYTES:
        raise CorruptEntry(f"{len(data)} bytes, above the {MAX_ENTRY_BYTES}-byte limit")
    end = data.find(b"\n", len(MAGIC), len(MAGIC) + 128)
    if end < 0:
        raise CorruptEntry("truncated (no checksum line)")
    try:
        digest, length = data[len(MAGIC):end].decode("ascii").split(" ")
        length = int(length)
    except (UnicodeDecodeError, ValueError) as exc:
        raise CorruptEntry("unreadable checksum line") from exc
    body = data[end + 1:]
    if length > MAX_HEADER_BYTES:
        raise CorruptEntry(f"a header of {length} bytes, above the {MAX_HEADER_BYTES}-byte limit")
    if length < 0 or length > len(body):
        raise CorruptEntry("truncated (header shorter than announced)")
    if hashlib.sha256(body).hexdigest() != digest:
        raise CorruptEntry("checksum mismatch (the bytes changed after they were written)")
    try:
        header = json.loads(body[:length].decode())
    except RecursionError as exc:
        raise CorruptEntry("a header nested too deeply to read") from exc
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
        Bad magic line, checksum, header or node, a header or value above the limits
        (:data:`MAX_HEADER_BYTES`, :data:`MAX_DEPTH`), or another key than ``key``.
    """
    header, payload = _split_entry(data)
    if key is not None and header.get("key") != key:
        raise CorruptEntry(f"written for another key ({str(header.get('key'))[:12]}...)")
    try:
        value = _decode_node(header["value"], payload)
    except CorruptEntry:
        raise
    except (KeyError, TypeError, ValueError, OverflowError, IndexError, RecursionError) as exc:
        raise CorruptEntry(f"malformed value ({type(exc).__name__})") from exc
    return header, value


# --------------------------------------------------------------------------------------
# Files: what lies at a path, and which of the cache's files are its own
# --------------------------------------------------------------------------------------


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
    above :data:`MAX_ENTRY_BYTES`); ``("entry", data)``: a regular file that starts with
    the magic line, with its bytes when ``read``. Other ``OSError`` (permissions) propagate.
    """
    try:
        info = os.lstat(path)
    except FileNotFoundError:
        return "missing", None
    if stat.S_ISLNK(info.st_mode):
        return "bad", "a symbolic link, not an entry"
    if stat.S_ISDIR(info.st_mode):
        return "foreign", "a directory"
    if not stat.S_ISREG(info.st_mode):
        return "bad", "not a regular file"
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        return "missing", None
    except OSError as exc:
        if os.path.islink(path):  # replaced by a link since the lstat
            return "bad", "a symbolic link, not an entry"
        raise exc
    with os.fdopen(fd, "rb") as fh:
        info = os.fstat(fh.fileno())
        if not stat.S_ISREG(info.st_mode):
            return "bad", "not a regular file"
        head = fh.read(len(MAGIC))
        if head != MAGIC:
            return "foreign", "a file that is not a passmd cache entry (no PASSMD-CACHE first line)"
        if info.st_size > MAX_ENTRY_BYTES:
            return "bad", f"{info.st_size} bytes, above the {MAX_ENTRY_BYTES}-byte limit"
        if not read:
            return "entry", None
        data = head + fh.read(MAX_ENTRY_BYTES + 1 - len(head))
    if len(data) > MAX_ENTRY_BYTES:
        return "bad", f"more than the {MAX_ENTRY_BYTES}-byte limit"
    return "entry", data


def _read_marker(directory: Path) -> str | None:
    """The format a passmd marker in ``directory`` names, None if there is none."""
    marker = directory / MARKER_NAME
    try:
        if not stat.S_ISREG(os.lstat(marker).st_mode):
            return None
        fd = os.open(marker, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
        with os.fdopen(fd, "rb") as fh:
            if not stat.S_ISREG(os.fstat(fh.fileno()).st_mode):
                return None
            text = fh.read(_MARKER_MAX_BYTES + 1)
    except OSError:
        return None
    if len(text) > _MARKER_MAX_BYTES:
        return None
    lines = text.decode("utf-8", "replace").splitlines()
    if not lines or lines[0].strip() != _MARKER_SIGNATURE:
        return None
    for line in lines[1:]:
        if line.startswith(_MARKER_FORMAT_LINE) and line[len(_MARKER_FORMAT_LINE):].strip():
            return line[len(_MARKER_FORMAT_LINE):].strip()
    return None


def _write_marker(directory: Path) -> None:
    """Write the marker atomically without replacing a file already there."""
    marker = directory / MARKER_NAME
    fd, tmp = tempfile.mkstemp(prefix=f".{MARKER_NAME}-", suffix=".tmp", dir=directory)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(_MARKER_TEXT)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o644)
        try:
            os.link(tmp, marker)  # atomic, and fails where a marker (or any file) is already
        except FileExistsError:
            pass
        except OSError:  # a file system without hard links
            if not os.path.lexists(marker):
                os.replace(tmp, marker)
    finally:
        try:
            os.unlink(tmp)
        except OSError:
            pass


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


class Cache:
    """Checked data entries on disk, keyed by function, parameters and code fingerprint.

    Parameters
    ----------
    directory : path, optional
        Where entries live; default :func:`default_cache_dir`. Created (with its marker)
        on first write; an existing directory is used only under the rules of the module
        docstring (marked, empty, or holding only the cache's own files).
    fingerprint : str, optional
        Code fingerprint mixed into every key; default :func:`code_fingerprint`.

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
        self.fingerprint = fingerprint if fingerprint is not None else code_fingerprint()
        self._usable: bool | None = None  # decided on first use (see _ready)
        self._reported: set = set()  # what _report_once reported

    def __repr__(self) -> str:
        return f"Cache({str(self.directory)!r}, fingerprint={self.fingerprint[:12]!r}...)"

    def key(self, func, params: Mapping, *, code: str | None = None) -> str:
        """Hex key of ``func(**params)`` under this cache's code fingerprint and ``func``'s own code.

        ``code``: :func:`function_code` of ``func``, computed here if not given (a sweep
        computes it once for all its points).

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

    def _inspect(self) -> tuple[str, str]:
        """State of the directory and, for one that is not a usable cache, why.

        ``missing``, ``empty``, ``marked`` (marker of this format), ``own-layout`` (no
        marker, only the cache's own files), ``foreign``, ``other-format``,
        ``not-a-directory``. ``OSError`` (permissions) propagates.
        """
        try:
            info = os.stat(self.directory)
        except FileNotFoundError:
            return "missing", "does not exist"
        if not stat.S_ISDIR(info.st_mode):
            return "not-a-directory", "is not a directory"
        found = _read_marker(self.directory)
        if found == FORMAT:
            return "marked", ""
        if found is not None:
            return "other-format", (f"is a passmd cache of format {found!r}; this passmd reads {FORMAT!r} "
                                    "(use the passmd that wrote it, or remove the directory by hand)")
        if not os.listdir(self.directory):
            return "empty", ""
        stray = _first_stray(self.directory)
        if stray is None:
            return "own-layout", (f"has no {MARKER_NAME} marker, though it holds only passmd cache entries "
                                  "(a cache from before markers): the next run that caches results in it "
                                  "marks it")
        return "foreign", (f"is not a passmd cache: it has no {MARKER_NAME} marker written by passmd and "
                           f"holds {stray!r}, which is not a passmd cache file")

    def _ready(self, create: bool) -> bool:
        """Whether entries may be read and written here; marks a new or adoptable directory.

        ``create``: make a missing directory (a write); else a missing one is a miss. A
        directory that is not usable is reported once (:class:`CacheWarning`).
        """
        if self._usable is not None:
            return self._usable
        try:
            state, reason = self._inspect()
            if state == "missing":
                if not create:
                    return False
                try:
                    self.directory.mkdir(parents=True)
                    state = "empty"
                except FileExistsError:  # made meanwhile, or a dangling link: look again
                    state, reason = self._inspect()
            if state in ("empty", "own-layout"):
                _write_marker(self.directory)
                state, reason = self._inspect()
        except OSError as exc:
            verb = "write" if create else "read"
            self._report_unusable(f"cannot {verb} the cache {self.directory}: {exc.strerror or exc}")
            self._usable = False
            return False
        self._usable = state == "marked"
        if state == "not-a-directory":
            self._report_unusable(f"cannot write the cache {self.directory}: it is not a directory")
        elif not self._usable:
            self._report_unusable(f"the cache directory {self.directory} {reason}")
        return self._usable

    def _owned(self) -> bool:
        """For info/clear/prune: True for a marked cache, False for a missing or empty directory.

        Raises
        ------
        NotACache
            Any other directory (its files are never read or removed).
        """
        state, reason = self._inspect()
        if state == "marked":
            return True
        if state in ("missing", "empty"):
            return False
        raise NotACache(self.directory, reason)

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
            self._report_unusable(f"cannot read the cache {self.directory}: {exc.strerror or exc}")
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
            warnings.warn(f"{message}; continuing without the cache", CacheWarning, stacklevel=4)

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
        tmp = None
        try:
            if not self._subfolder(target.parent, create=True):
                return False
            kind, found = _examine(target, read=False)
            if kind == "foreign":
                self._report_path(target, found)
                return False
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
        finally:  # also on KeyboardInterrupt and what a SIGTERM handler raises
            if tmp is not None:
                try:
                    os.unlink(tmp)
                except OSError:
                    pass
        return True

    # ---- the whole directory -------------------------------------------------------

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

        Unreadable entries, the cache's own temporary files (``leftovers``) and files that
        are not the cache's (``foreign``, never touched) are counted apart; nothing is removed.

        Raises
        ------
        NotACache
            The directory exists, is not empty and has no marker of this format.
        """
        summary = {"directory": str(self.directory), "entries": 0, "bytes": 0, "current_code": 0,
                   "other_code": 0, "unreadable": 0, "leftovers": 0, "foreign": 0, "functions": {}}
        if not self._owned():
            return summary
        for kind, path in _walk(self.directory):
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
            current = header.get("code") == self.fingerprint
            summary["current_code" if current else "other_code"] += 1
            name = str(header.get("function") or "?")
            summary["functions"][name] = summary["functions"].get(name, 0) + 1
        return summary

    def prune(self) -> int:
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
                return _split_entry(data)[0].get("code") != self.fingerprint
            except CorruptEntry:
                return True

        return self._remove(doomed)

    def clear(self) -> int:
        """Remove every entry (readable or not) and temporary file of the cache.

        Returns the number of files removed; files that are not the cache's stay. A write
        in progress meanwhile loses its entry (reported by that writer, which keeps its
        result).

        Raises
        ------
        NotACache
            The directory exists, is not empty and has no marker of this format.
        """
        return self._remove(lambda kind, path: kind == "temp" or (
            kind == "candidate" and _examine(path, read=False)[0] in ("entry", "bad")))

    def _remove(self, doomed) -> int:
        """Unlink each of the cache's own files for which ``doomed(kind, path)`` holds; the count.

        Refuses a folder that is not a cache (:meth:`_owned`); a file gone meanwhile is skipped.
        """
        if not self._owned():
            return 0
        removed = 0
        for kind, path in _walk(self.directory):
            try:
                if doomed(kind, path):
                    removed += _unlink(path)
            except FileNotFoundError:
                continue
        return removed
