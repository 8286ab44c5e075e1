"""On-disk cache (passmd.runtime.cache): keys, code fingerprint, atomic writes, corrupt entries."""

import os
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import passmd
from passmd.model.parameters import Drive
from passmd.runtime import cache
from passmd.runtime.cache import Cache, canonical, code_fingerprint, default_cache_dir
from passmd.runtime.config import RunConfig


def point_function(x):
    return {"y": x}


def other_function(x):
    return {"y": x}


@pytest.fixture
def store(tmp_path):
    return Cache(tmp_path / "cache")


@pytest.fixture
def marked(store):
    """An empty cache directory the cache created (and marked) itself."""
    key = store.key(other_function, {"x": -1})
    assert store.put(key, {"y": -1}) and store.clear() == 1
    return store


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


def test_put_get_roundtrip_is_bit_exact(store):
    key = store.key(point_function, {"x": 1})
    assert store.get(key) is None
    assert key not in store
    array = np.array([1.0, -0.0, np.nextafter(1.0, 2.0), 1e-308 / 3, np.inf, np.nan])
    value = {"array": array, "scalar": 0.1 + 0.2, "np_scalar": np.float64(2.0 / 3.0), "n": 7,
             "big": 2**70, "flag": True, "np_flag": np.bool_(False), "label": "µ", "none": None,
             "steps_m": [1e-9, 2e-9], "pair": (1, 2.5), "nested": {"ints": np.arange(3, dtype=np.int32)}}
    store.put(key, value)
    back = store.get(key)
    assert list(back) == list(value)
    assert back["array"].dtype == array.dtype and back["array"].tobytes() == array.tobytes()
    assert back["array"].flags.writeable
    assert float.hex(back["scalar"]) == float.hex(value["scalar"]) and type(back["scalar"]) is float
    assert type(back["np_scalar"]) is np.float64 and back["np_scalar"] == value["np_scalar"]
    assert back["n"] == 7 and type(back["n"]) is int and back["big"] == 2**70
    assert back["flag"] is True and type(back["np_flag"]) is np.bool_
    assert back["label"] == "µ" and back["none"] is None
    assert back["steps_m"] == [1e-9, 2e-9] and back["pair"] == (1, 2.5)
    assert back["nested"]["ints"].dtype == np.int32
    assert key in store
    assert store.entries() == [store.path(key)]
    assert store.clear() == 1
    assert key not in store


@pytest.mark.parametrize("value", [
    {"frame": pd.DataFrame({"u_m": [0.0, 1e-9]})},
    {"objects": np.array([object()], dtype=object)},
    {1: 2.0},
    {"thing": object()},
])
def test_values_the_format_cannot_store_are_refused(store, value):
    key = store.key(point_function, {"x": 1})
    with pytest.raises(TypeError, match="cannot cache"):
        store.put(key, value)
    assert not store.path(key).exists()


def test_no_entry_can_run_code_when_read(marked, tmp_path):
    """A pickle that runs a command when unpickled is never unpickled (nor removed: not ours)."""
    import pickle

    marker = tmp_path / "pwned"

    class Exploit:
        def __reduce__(self):
            return (os.system, (f"touch {marker}",))

    store = marked
    key = store.key(point_function, {"x": 9})
    store.path(key).parent.mkdir(parents=True, exist_ok=True)
    store.path(key).write_bytes(pickle.dumps({"key": key, "value": Exploit()}))
    with pytest.warns(cache.CacheWarning, match="not a passmd cache entry") as record:
        assert store.get(key, "miss") == "miss"
        assert store.put(key, {"y": 9}) is False  # the same path: reported once, not replaced
    assert len(record) == 1
    assert not marker.exists()
    assert store.path(key).read_bytes().startswith(b"\x80")  # left in place
    # the entry format itself is JSON + raw bytes: nothing in it is callable
    store.path(key).unlink()
    store.put(key, {"y": np.arange(3.0)})
    data = store.path(key).read_bytes()
    assert data.startswith(cache.MAGIC) and b"pickle" not in data


def test_flipped_byte_is_detected_removed_and_recomputed(store):
    key = store.key(point_function, {"x": 8})
    store.put(key, {"position_m": np.linspace(0, 1e-6, 50)})
    data = bytearray(store.path(key).read_bytes())
    data[-17] ^= 0x40  # one bit inside the stored array
    store.path(key).write_bytes(bytes(data))
    with pytest.warns(cache.CacheWarning, match="checksum mismatch") as record:
        assert store.get(key, "miss") == "miss"
    assert len(record) == 1  # reported once
    assert not store.path(key).exists()


def test_scalar_in_the_header_is_covered_by_the_checksum(store):
    key = store.key(point_function, {"x": 8})
    store.put(key, {"full_time_s": 0.25})
    data = store.path(key).read_bytes()
    hexed = float.hex(0.25).encode()
    store.path(key).write_bytes(data.replace(hexed, float.hex(0.5).encode()))
    with pytest.warns(cache.CacheWarning, match="checksum"):
        assert key not in store


def test_a_sweep_recomputes_a_corrupt_entry_with_one_warning(store):
    from passmd.runtime import sweep

    points = [{"x": 1.0}, {"x": 2.0}]
    first = sweep.run(point_function, points, executor="serial", cache=store, progress=False)
    victim = store.path(store.key(point_function, points[0]))
    victim.write_bytes(victim.read_bytes()[:-3])  # truncated
    with pytest.warns(cache.CacheWarning) as record:
        again = sweep.run(point_function, points, executor="serial", cache=store, progress=False)
    assert len(record) == 1 and "unusable" in str(record[0].message)
    assert again.attrs["sweep"]["computed"] == 1
    pd.testing.assert_frame_equal(first, again)
    third = sweep.run(point_function, points, executor="serial", cache=store, progress=False)
    assert third.attrs["sweep"]["cached"] == 2  # the recomputed entry was written back


@pytest.mark.parametrize("how", ["read-only", "a file", "disk full", "no permission"])
def test_unwritable_cache_warns_once_and_keeps_the_result(tmp_path, monkeypatch, how):
    from passmd.runtime import sweep

    monkeypatch.setattr(cache.store, "_REPORTED_UNWRITABLE", set())
    directory = tmp_path / "cache"
    if how == "read-only":
        if os.geteuid() == 0:
            pytest.skip("root writes into read-only directories")
        directory.mkdir()
        directory.chmod(0o500)
    elif how == "a file":
        directory.write_text("I am a file")
    elif how == "disk full":
        def full(*args, **kwargs):
            raise OSError(28, "No space left on device")

        monkeypatch.setattr(cache.store.os, "replace", full)
    else:  # another user's directory, also when the tests run as root
        def denied(*args, **kwargs):
            raise PermissionError(13, "Permission denied")

        monkeypatch.setattr(cache.layout.tempfile, "mkstemp", denied)
    store = Cache(directory)
    points = [{"x": float(x)} for x in range(4)]
    try:
        with pytest.warns(cache.CacheWarning, match="continuing without the cache") as record:
            frame = sweep.run(point_function, points, executor="serial", cache=store, progress=False)
    finally:
        if how == "read-only":
            directory.chmod(0o700)
    assert len(record) == 1
    assert frame["y"].tolist() == [0.0, 1.0, 2.0, 3.0]
    if directory.is_dir():
        assert not list(directory.glob("??/*"))  # no entry, no temporary file left behind


def test_prune_and_info(store, tmp_path):
    old = Cache(store.directory, fingerprint="0" * 64)
    old.put(old.key(point_function, {"x": 1}), {"y": 1}, function="tests:point_function")
    store.put(store.key(point_function, {"x": 2}), {"y": 2}, function="tests:point_function")
    legacy = store.directory / "ab" / ("ab" + "0" * 62 + ".pkl")  # not an entry: never removed
    legacy.parent.mkdir(parents=True, exist_ok=True)
    legacy.write_bytes(b"\x80\x05old pickle")
    info = store.info()
    assert (info["entries"], info["current_code"], info["other_code"], info["foreign"]) == (2, 1, 1, 1)
    assert info["functions"] == {"tests:point_function": 2}
    assert store.prune() == 1  # the other fingerprint's entry
    assert store.info()["entries"] == 1 and legacy.exists()
    assert store.get(store.key(point_function, {"x": 2})) == {"y": 2}


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


@pytest.mark.parametrize("content", [b"PASSMD-CACHE 1\n", b"PASSMD-CACHE 1\nabc 5\n{}",
                                     b"PASSMD-CACHE 1\n" + b"\x00" * 100])
def test_corrupt_entry_is_a_miss(marked, content):
    store = marked
    key = store.key(point_function, {"x": 4})
    store.path(key).parent.mkdir(parents=True, exist_ok=True)
    store.path(key).write_bytes(content)
    with pytest.warns(cache.CacheWarning, match="unusable.*removed; recomputing"):
        assert store.get(key, "miss") == "miss"
    assert not store.path(key).exists()
    store.put(key, {"y": 4})  # the recomputed value takes its place
    assert store.get(key) == {"y": 4}


@pytest.mark.parametrize("content", [b"", b"\x80\x05garbage", b"not a pickle at all", b"PASSMD-CACHE 2\n"])
def test_a_file_at_an_entry_path_without_the_magic_line_is_left_alone(marked, content):
    """Not the cache's (the magic line is missing): a miss, reported, neither removed nor replaced."""
    store = marked
    key = store.key(point_function, {"x": 4})
    store.path(key).parent.mkdir(parents=True, exist_ok=True)
    store.path(key).write_bytes(content)
    with pytest.warns(cache.CacheWarning, match="not a passmd cache entry.*left in place"):
        assert store.get(key, "miss") == "miss"
    assert store.put(key, {"y": 4}) is False
    assert store.path(key).read_bytes() == content
    assert store.prune() == 0 and store.clear() == 0
    assert store.path(key).read_bytes() == content
    assert store.info()["foreign"] == 1


def test_entry_under_wrong_key_is_a_miss(store):
    key_a = store.key(point_function, {"x": 5})
    key_b = store.key(point_function, {"x": 6})
    store.put(key_a, {"y": 5})
    store.path(key_b).parent.mkdir(parents=True, exist_ok=True)
    shutil.copy(store.path(key_a), store.path(key_b))  # a misplaced file is not trusted
    with pytest.warns(cache.CacheWarning, match="another key"):
        assert key_b not in store
    assert not store.path(key_b).exists() and store.get(key_a) == {"y": 5}


def test_source_change_changes_fingerprint(tmp_path):
    package = tmp_path / "passmd"
    shutil.copytree(Path(passmd.__file__).parent, package, ignore=shutil.ignore_patterns("__pycache__"))
    before = code_fingerprint(package)
    assert before == code_fingerprint(package)  # deterministic
    assert code_fingerprint() == code_fingerprint(Path(passmd.__file__).parent)
    theory = package / "model" / "theory.py"
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
    """The user's cache folder (platformdirs; $XDG_CACHE_HOME on Linux), never the working folder."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("XDG_CACHE_HOME", os.fspath(tmp_path / "xdg"))
    monkeypatch.setenv("PASSMD_CACHE_DIR", os.fspath(tmp_path / "elsewhere"))  # read by entry points only
    assert default_cache_dir() == (tmp_path / "xdg" / "passmd" / "results").resolve()
    assert Cache().directory == default_cache_dir()
    # an entry point's run configuration names the directory; the cache takes it from there
    config = RunConfig.from_environment()
    assert Cache(config.cache_dir).directory == (tmp_path / "elsewhere").resolve()
    with pytest.raises(ValueError, match="is not a directory"):
        code_fingerprint(tmp_path / "missing")


def test_cached_rerun_is_bit_identical(store):
    """A sweep served from the cache returns exactly the computed values (floats by bits)."""
    from sweep_points import drive_theory_point

    from passmd.runtime import sweep

    points = sweep.grid(preload=[0.1, 0.37, 1.0], contacts=[1, 6])
    cold = sweep.run(drive_theory_point, points, executor="serial", cache=store, progress=False)
    warm = sweep.run(drive_theory_point, points, executor="serial", cache=store, progress=False)
    assert warm.attrs["sweep"]["cached"] == len(points)
    pd.testing.assert_frame_equal(cold, warm, check_exact=True)
    for column in cold.columns:
        for a, b in zip(cold[column], warm[column], strict=True):
            assert repr(a) == repr(b) and type(a) is type(b), column


def test_entry_of_another_function_is_recomputed(store):
    """Right key, well-formed, but written by another function: foreign content is not served."""
    from passmd.runtime import sweep

    key = store.key(point_function, {"x": 1.0})
    store.put(key, {"full_time_s": 1.0}, function="somewhere:else")
    with pytest.warns(cache.CacheWarning, match="written by 'somewhere:else'"):
        frame = sweep.run(point_function, [{"x": 1.0}], executor="serial", cache=store, progress=False)
    assert frame["y"].tolist() == [1.0] and frame.attrs["sweep"]["computed"] == 1
