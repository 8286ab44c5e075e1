"""On-disk cache (passmd.cache): keys, code fingerprint, atomic writes, corrupt entries."""

import os
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import passmd
from passmd import cache as cache_module
from passmd.cache import Cache, canonical, code_fingerprint, default_cache_dir
from passmd.parameters import Drive


def point_function(x):
    return {"y": x}


def other_function(x):
    return {"y": x}


@pytest.fixture
def store(tmp_path):
    return Cache(tmp_path / "cache")


def test_key_depends_on_every_parameter_and_function(store):
    base = store.key(point_function, {"x": 0.1, "drive": Drive()})
    assert base == Cache(store.directory).key(point_function, {"drive": Drive(), "x": 0.1})  # order-free
    different = [
        store.key(point_function, {"x": 0.1000000000000001, "drive": Drive()}),  # next float
        store.key(point_function, {"x": 0.1, "drive": Drive(preload=0.5)}),  # nested dataclass field
        store.key(point_function, {"x": 0.1, "drive": Drive(runner_mass=3.0000001e-3)}),
        store.key(point_function, {"x": 0.1, "drive": Drive(contacts=1)}),
        store.key(other_function, {"x": 0.1, "drive": Drive()}),
        store.key(point_function, {"x": 0.1}),
    ]
    assert len({base, *different}) == len(different) + 1


def test_canonical_types():
    assert canonical(1) != canonical(1.0)  # int and float are different parameters
    assert canonical(np.float64(0.1)) == canonical(0.1)
    a = np.arange(4.0)
    assert canonical(a) == canonical(a.copy())
    assert canonical(a) != canonical(a.reshape(2, 2))
    b = a.copy()
    b[3] = np.nextafter(3.0, 4.0)
    assert canonical(a) != canonical(b)
    assert canonical({"b": 1, "a": 2}) == canonical({"a": 2, "b": 1})
    assert canonical([1, 2]) != canonical((1, 2))
    with pytest.raises(TypeError, match="cannot use a object"):
        canonical(object())


def test_put_get_roundtrip(store):
    key = store.key(point_function, {"x": 1})
    assert store.get(key) is None
    assert key not in store
    frame = pd.DataFrame({"u_m": [0.0, 1e-9]})
    store.put(key, {"frame": frame, "array": np.array([1.0, 2.0]), "scalar": 3.5})
    value = store.get(key)
    pd.testing.assert_frame_equal(value["frame"], frame)
    np.testing.assert_array_equal(value["array"], [1.0, 2.0])
    assert value["scalar"] == 3.5
    assert key in store
    assert store.entries() == [store.path(key)]
    assert store.clear() == 1
    assert key not in store


def test_interrupted_write_leaves_no_entry(store, monkeypatch):
    """A crash between writing the temporary file and the rename leaves no (corrupt) entry."""
    key = store.key(point_function, {"x": 2})

    def crash(src, dst):
        raise KeyboardInterrupt  # the process dies exactly here

    monkeypatch.setattr(cache_module.os, "replace", crash)
    with pytest.raises(KeyboardInterrupt):
        store.put(key, {"y": 2})
    monkeypatch.undo()
    assert key not in store
    assert not store.path(key).exists()
    assert list(store.path(key).parent.iterdir()) == []  # the temporary file is cleaned up
    store.put(key, {"y": 2})
    assert store.get(key) == {"y": 2}


def test_killed_write_leftover_is_ignored(store):
    """A hard kill can leave a temporary file; it is never read as an entry."""
    key = store.key(point_function, {"x": 3})
    store.path(key).parent.mkdir(parents=True)
    leftover = store.path(key).parent / f".{key[:16]}-abc.tmp"
    leftover.write_bytes(b"\x80\x05half a pickle")
    assert key not in store
    assert store.entries() == []
    store.put(key, {"y": 3})
    assert store.get(key) == {"y": 3}


@pytest.mark.parametrize("content", [b"", b"\x80\x05garbage", b"not a pickle at all"])
def test_corrupt_entry_is_a_miss(store, content):
    key = store.key(point_function, {"x": 4})
    store.path(key).parent.mkdir(parents=True)
    store.path(key).write_bytes(content)
    assert store.get(key, "miss") == "miss"
    store.put(key, {"y": 4})  # recomputed value overwrites it
    assert store.get(key) == {"y": 4}


def test_entry_under_wrong_key_is_a_miss(store):
    key_a = store.key(point_function, {"x": 5})
    key_b = store.key(point_function, {"x": 6})
    store.put(key_a, {"y": 5})
    store.path(key_b).parent.mkdir(parents=True, exist_ok=True)
    shutil.copy(store.path(key_a), store.path(key_b))  # a misplaced file is not trusted
    assert key_b not in store


def test_source_change_changes_fingerprint(tmp_path):
    package = tmp_path / "passmd"
    shutil.copytree(Path(passmd.__file__).parent, package, ignore=shutil.ignore_patterns("__pycache__"))
    before = code_fingerprint(package)
    assert before == code_fingerprint(package)  # deterministic
    assert code_fingerprint() == code_fingerprint(Path(passmd.__file__).parent)
    theory = package / "theory.py"
    theory.write_bytes(theory.read_bytes() + b"\n# an edit\n")
    edited = code_fingerprint(package)
    assert edited != before
    (package / "new_module.py").write_text("X = 1\n")
    assert code_fingerprint(package) not in (before, edited)
    # and a different fingerprint means different keys: stale results are never served
    a = Cache(tmp_path / "c", fingerprint=before).key(point_function, {"x": 1})
    b = Cache(tmp_path / "c", fingerprint=edited).key(point_function, {"x": 1})
    assert a != b


def test_default_directory(tmp_path, monkeypatch):
    monkeypatch.delenv("PASSMD_CACHE_DIR", raising=False)
    monkeypatch.chdir(tmp_path)
    assert default_cache_dir() == tmp_path.resolve() / ".passmd-cache"
    assert Cache().directory == tmp_path.resolve() / ".passmd-cache"
    monkeypatch.setenv("PASSMD_CACHE_DIR", os.fspath(tmp_path / "elsewhere"))
    assert Cache().directory == (tmp_path / "elsewhere").resolve()
    with pytest.raises(ValueError, match="is not a directory"):
        code_fingerprint(tmp_path / "missing")
