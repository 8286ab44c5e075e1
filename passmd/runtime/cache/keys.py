"""What a cache key hashes: parameters (:func:`~passmd.runtime.cache.keys.canonical`), the package's
code (:func:`~passmd.runtime.cache.keys.code_fingerprint`) and the swept function's own code
(:func:`~passmd.runtime.cache.keys.function_code`).
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import inspect
import json
import os
import sys
import sysconfig
import types
from collections.abc import Mapping
from enum import Enum
from pathlib import Path

import numpy as np

__all__ = ["Unfingerprintable", "canonical", "code_fingerprint", "function_code", "function_name",
           "tree_fingerprint"]

#: The ``passmd`` package folder (this module is ``passmd/runtime/cache/keys.py``).
_PACKAGE_DIR = Path(__file__).resolve().parents[2]


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
    return tree_fingerprint(root, "*.py")


def tree_fingerprint(root: str | os.PathLike, pattern: str, skip: tuple[str, ...] = ()) -> str:
    """SHA-256 over the relative path and bytes of every file under ``root`` matching ``pattern``,
    leaving out ``__pycache__`` and any folder or file named in ``skip``."""
    root = Path(root).resolve()
    if not root.is_dir():
        raise ValueError(f"package_dir = {str(root)!r} is not a directory")
    left_out = {"__pycache__", *skip}
    digest = hashlib.sha256()
    for path in sorted(root.rglob(pattern)):
        parts = path.relative_to(root).parts
        if not path.is_file() or left_out.intersection(parts):
            continue
        rel = "/".join(parts).encode()
        data = path.read_bytes()
        digest.update(len(rel).to_bytes(8, "little") + rel)
        digest.update(len(data).to_bytes(8, "little") + data)
    return digest.hexdigest()


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

    A result that depends on the environment cannot be keyed: the cache cannot tell which
    variables a function reads (``os.environ`` is read through many names and mappings), so
    user code that names ``environ``, ``getenv`` (and their bytes forms) is refused rather than
    returned stale when a variable changes; pass the value as a point's parameter instead.

    Raises
    ------
    Unfingerprintable
        The function names something whose state cannot be fingerprinted (an arbitrary
        object, a class without source, a callable instance), or reads the environment; the
        message says what.
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
        _refuse_environment(set(_names(code)), f"{where} ({name})")
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
        _refuse_environment({n for n in _ENVIRONMENT if n in source}, f"{where} (the class {name})")
        methods = {k: _code_node(v, seen, f"{name}.{k}") for k, v in vars(obj).items()
                   if isinstance(v, types.FunctionType)}
        return {"class": name, "source": hashlib.sha256(source.encode()).hexdigest(), "methods": methods}
    inner = getattr(obj, "__wrapped__", None) or getattr(obj, "py_func", None)  # lru_cache, numba
    if inner is not None and inner is not obj:
        return {"wrapper": type(obj).__qualname__, "wrapped": _code_node(inner, seen, where)}
    raise Unfingerprintable(f"{where} is a {type(obj).__name__} object ({name}), not a function")


#: Names through which code reads the process environment (``os.environ``, ``os.getenv``, …).
_ENVIRONMENT = ("environ", "environb", "getenv", "getenvb")


def _refuse_environment(names: set, where: str) -> None:
    """Raise :class:`Unfingerprintable` if ``names`` include a way to read the environment."""
    used = sorted(set(_ENVIRONMENT) & names)
    if used:
        raise Unfingerprintable(f"{where} reads the environment ({', '.join(used)}): its result may change "
                                "with a variable the cache key cannot see (pass the value as a parameter "
                                "of the point instead)")


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
            source = Path(file).read_bytes()
        except (OSError, TypeError) as exc:
            raise Unfingerprintable(f"{where} is the module {value.__name__}, whose source cannot be "
                                    "read") from exc
        _refuse_environment({n for n in _ENVIRONMENT if n.encode() in source},
                            f"{where} (the module {value.__name__})")
        return {"module": value.__name__, "source": hashlib.sha256(source).hexdigest()}
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

