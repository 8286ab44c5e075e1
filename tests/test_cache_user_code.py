"""The sweep cache and a user's own function: a changed function is never served from the cache.

A user's point function lives outside passmd, so the package's code fingerprint does not
cover it; the key holds the function's own code (passmd.runtime.cache.function_code). Each test
writes a user module to a temporary folder, sweeps it, edits the module and sweeps again
under the same module and function name: the values must be the edited code's.
"""

import importlib
import sys
import textwrap
import warnings

import numpy as np
import pytest

from passmd.runtime import sweep
from passmd.runtime.cache import Cache, CacheWarning, Unfingerprintable, function_code

POINTS = [{"x": 1.0}, {"x": 2.0}, {"x": 3.0}]


@pytest.fixture
def user_module(tmp_path, monkeypatch):
    """``load(source)`` writes ``usercode.py`` (and other files via ``files``) and imports it afresh."""
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(sys, "dont_write_bytecode", True)
    names = set()

    def load(source: str, name: str = "usercode", **files: str):
        for other, text in files.items():
            (tmp_path / f"{other}.py").write_text(textwrap.dedent(text))
            sys.modules.pop(other, None)
            names.add(other)
        (tmp_path / f"{name}.py").write_text(textwrap.dedent(source))
        sys.modules.pop(name, None)
        names.add(name)
        importlib.invalidate_caches()
        return importlib.import_module(name)

    yield load
    for name in names:
        sys.modules.pop(name, None)


def _sweep(func, store, points=POINTS):
    return sweep.run(func, points, executor="serial", cache=store, progress=False)


@pytest.mark.parametrize("before, after", [
    # a global constant the function reads (the preload of the report: 0.6 N -> 0.3 N)
    ("PRELOAD = 0.6\ndef point(x):\n    return {'y': PRELOAD * x}\n",
     "PRELOAD = 0.3\ndef point(x):\n    return {'y': PRELOAD * x}\n"),
    # the function's own body
    ("def point(x):\n    return {'y': 0.6 * x}\n",
     "def point(x):\n    return {'y': 0.3 * x}\n"),
    # a default argument
    ("def point(x, preload=0.6):\n    return {'y': preload * x}\n",
     "def point(x, preload=0.3):\n    return {'y': preload * x}\n"),
    # a helper in the same module, called by the swept function
    ("def helper(x):\n    return 0.6 * x\ndef point(x):\n    return {'y': helper(x)}\n",
     "def helper(x):\n    return 0.3 * x\ndef point(x):\n    return {'y': helper(x)}\n"),
    # a helper's helper, and a NumPy array the innermost one reads
    ("import numpy as np\nW = np.array([0.6])\ndef inner(x):\n    return float(W[0]) * x\n"
     "def outer(x):\n    return inner(x)\ndef point(x):\n    return {'y': outer(x)}\n",
     "import numpy as np\nW = np.array([0.3])\ndef inner(x):\n    return float(W[0]) * x\n"
     "def outer(x):\n    return inner(x)\ndef point(x):\n    return {'y': outer(x)}\n"),
    # a value captured in a closure (the module-level name is the same function factory's product)
    ("def make(p):\n    def point(x):\n        return {'y': p * x}\n    return point\npoint = make(0.6)\n",
     "def make(p):\n    def point(x):\n        return {'y': p * x}\n    return point\npoint = make(0.3)\n"),
], ids=["global", "body", "default", "helper", "nested-helper-array", "closure"])
def test_a_changed_user_function_is_recomputed(user_module, tmp_path, before, after):
    store = Cache(tmp_path / "cache")
    first = _sweep(user_module(before).point, store)
    assert first["y"].tolist() == pytest.approx([0.6, 1.2, 1.8], rel=1e-12)
    again = _sweep(user_module(before).point, store)  # unchanged code, re-imported: from the cache
    assert again.attrs["sweep"]["cached"] == 3
    edited = _sweep(user_module(after).point, store)
    assert edited.attrs["sweep"]["cached"] == 0 and edited.attrs["sweep"]["computed"] == 3
    assert edited["y"].tolist() == pytest.approx([0.3, 0.6, 0.9], rel=1e-12)


def test_a_user_module_the_function_calls_into_is_covered(user_module, tmp_path):
    """``import helpers; helpers.scale(x)``: the other user module's source is part of the key."""
    store = Cache(tmp_path / "cache")
    source = "import helpers\ndef point(x):\n    return {'y': helpers.scale(x)}\n"
    first = _sweep(user_module(source, helpers="def scale(x):\n    return 0.6 * x\n").point, store)
    edited = _sweep(user_module(source, helpers="def scale(x):\n    return 0.3 * x\n").point, store)
    assert edited.attrs["sweep"]["cached"] == 0
    assert edited["y"].tolist() == pytest.approx([v / 2 for v in first["y"]], rel=1e-12)


def test_edits_that_cannot_change_a_result_keep_the_cache(user_module, tmp_path):
    """Comments, blank lines and code moved down a file do not change the fingerprint."""
    store = Cache(tmp_path / "cache")
    _sweep(user_module("def point(x):\n    return {'y': 2 * x}\n").point, store)
    moved = user_module("# a comment\n\n\ndef point(x):\n    # why\n    return {'y': 2 * x}\n")
    assert _sweep(moved.point, store).attrs["sweep"]["cached"] == 3


def test_a_function_that_cannot_be_fingerprinted_is_not_cached(user_module, tmp_path):
    """A global holding an arbitrary object: one warning, the results computed and not stored."""
    module = user_module("class Box:\n    def __init__(self):\n        self.p = 0.6\n"
                         "BOX = Box()\ndef point(x):\n    return {'y': BOX.p * x}\n")
    with pytest.raises(Unfingerprintable, match="global 'BOX' is a Box"):
        function_code(module.point)
    store = Cache(tmp_path / "cache")
    with pytest.warns(CacheWarning, match=r"is not cached: .*global 'BOX' is a Box") as caught:
        frame = _sweep(module.point, store)
    assert len([w for w in caught if issubclass(w.category, CacheWarning)]) == 1
    assert frame["y"].tolist() == pytest.approx([0.6, 1.2, 1.8], rel=1e-12)
    assert store.entries() == []
    module.BOX.p = 0.3  # the state changed: a cache would have served 0.6
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CacheWarning)
        assert _sweep(module.point, store)["y"].tolist() == pytest.approx([0.3, 0.6, 0.9], rel=1e-12)


def test_passmd_and_library_functions_have_fixed_fingerprints():
    """passmd's own functions are covered by the package fingerprint; libraries by name and version."""
    from sweep_points import drive_theory_point

    from passmd.model.theory import drive_theory

    assert function_code(drive_theory) == function_code(drive_theory)
    assert function_code(np.sum) != function_code(np.mean)
    assert function_code(drive_theory_point) != function_code(drive_theory)  # test code is user code


def test_a_notebook_function_is_recomputed_when_its_cell_changes(tmp_path, monkeypatch):
    """A function defined in a namespace without a source file (a notebook's ``__main__``)."""
    import types

    store = Cache(tmp_path / "cache")
    values = []
    for preload in (0.6, 0.3):
        namespace = types.ModuleType("notebook_session")  # no __file__, as a Jupyter kernel's __main__
        monkeypatch.setitem(sys.modules, "notebook_session", namespace)
        exec(f"PRELOAD = {preload}\ndef point(x):\n    return {{'y': PRELOAD * x}}\n", namespace.__dict__)
        frame = _sweep(namespace.point, store)
        values.append((frame["y"].tolist(), frame.attrs["sweep"]["cached"]))
    assert values[0] == (pytest.approx([0.6, 1.2, 1.8], rel=1e-12), 0)
    assert values[1] == (pytest.approx([0.3, 0.6, 0.9], rel=1e-12), 0)


def test_decorated_helpers_are_fingerprinted_through_what_they_wrap(user_module, tmp_path):
    """A helper behind functools.lru_cache is hashed by the function it wraps."""
    store = Cache(tmp_path / "cache")
    source = ("import functools\n@functools.lru_cache\ndef scale():\n    return {p}\n"
              "def point(x):\n    return {{'y': scale() * x}}\n")
    _sweep(user_module(source.format(p=0.6)).point, store)
    assert _sweep(user_module(source.format(p=0.6)).point, store).attrs["sweep"]["cached"] == 3  # cached
    edited = _sweep(user_module(source.format(p=0.3)).point, store)
    assert edited.attrs["sweep"]["cached"] == 0
    assert edited["y"].tolist() == pytest.approx([0.3, 0.6, 0.9], rel=1e-12)
