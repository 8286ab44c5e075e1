"""The cache deletes only its own files and survives any entry (passmd.runtime.cache, ``passmd cache``).

Contract (README, "Reliability"; rules in the :mod:`passmd.runtime.cache` docstring): a directory
without the cache's marker is never read, written or pruned; inside a cache only files at
an entry's path that start with the magic line (or links and special files there) and the
cache's own temporary files are removed, and counts are true; keys are checked before
they become paths; no entry (nested, large, a link, a device) stops a run or is read
without bound: it is reported once, removed and recomputed.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from passmd.runtime import cache, sweep
from passmd.runtime.cache import MAGIC, MARKER_NAME, Cache, CacheWarning, CorruptEntry, NotACache

FUZZ = int(os.environ.get("PASSMD_CACHE_FUZZ_EXAMPLES", "40"))
FUZZ_SETTINGS = settings(max_examples=FUZZ, deadline=None,
                         suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
KEY_A = "ab" + "0" * 62
KEY_B = "cd" + "1" * 62


def point_function(x):
    return {"y": x}


def cli(*argv, cwd=None, env=None):
    """``python -m passmd cache ...`` in a subprocess: (status, stdout, stderr)."""
    full_env = {**os.environ, **(env or {})}
    if env is None:
        full_env.pop("PASSMD_CACHE_DIR", None)
    done = subprocess.run([sys.executable, "-m", "passmd", "cache", *argv], capture_output=True, text=True,
                          cwd=cwd, env=full_env, timeout=120)
    return done.returncode, done.stdout, done.stderr


def craft(key: str, header: bytes, payload: bytes = b"") -> bytes:
    """Entry bytes around any header, with a correct checksum (the reader must not trust it)."""
    digest = hashlib.sha256(header + payload).hexdigest()
    return MAGIC + f"{digest} {len(header)}\n".encode() + header + payload


def deep_header(key: str, depth: int) -> bytes:
    return (b'{"format":1,"key":"' + key.encode() + b'","value":' + b"[" * depth + b"]" * depth + b"}")


def marked_cache(directory: Path) -> Cache:
    """A cache the package created: marker written, no entries, no subfolders (the entry's
    subfolder depends on the code's fingerprint, and would collide with a test's crafted key one
    code change in 256)."""
    store = Cache(directory)
    key = store.key(point_function, {"x": -1.0})
    assert store.put(key, {"y": -1.0}) and store.clear() == 1
    (directory / key[:2]).rmdir()  # empty after clear()
    return store


def user_files(root: Path) -> dict[Path, bytes]:
    """A mistyped --cache-dir's files: a user's *.pkl, *.tmp and *.pmc files in two-character subfolders."""
    files = {root / "ab" / "results.pkl": b"\x80\x04 a user's pickle",
             root / "xy" / "draft.tmp": b"half a thesis",
             root / "00" / "scan.pmc": b"a user's .pmc file",
             root / "ab" / (KEY_A + ".pmc"): b"named like an entry, but not one",
             root / "notes.txt": b"notes"}
    for path, data in files.items():
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    return files


def assert_intact(files: dict[Path, bytes]):
    for path, data in files.items():
        assert path.read_bytes() == data, path


def one_line(err: str) -> str:
    assert err.count("\n") == 1 and err.startswith("passmd cache: error: ") and "Traceback" not in err, err
    return err


# --------------------------------------------------------------------------------------
# A folder without the marker: refused by the commands, untouched by sweeps
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("json_flag", [[], ["--json"]])
@pytest.mark.parametrize("action", ["clear", "prune", "info"])
def test_commands_refuse_a_folder_without_the_marker(tmp_path, action, json_flag):
    """A mistyped --cache-dir: one line naming the option and directory, exit 2, nothing deleted."""
    folder = tmp_path / "thesis"
    files = user_files(folder)
    status, out, err = cli(action, "--cache-dir", str(folder), *json_flag)
    assert status == 2 and out == ""
    one_line(err)
    assert f"--cache-dir = '{folder}'" in err and "is not a passmd cache" in err and MARKER_NAME in err
    assert ("nothing was read" if action == "info" else "nothing was removed") in err
    assert_intact(files)
    assert not (folder / MARKER_NAME).exists()


def test_refusal_names_the_environment_variable_and_the_default(tmp_path):
    folder = tmp_path / "thesis"
    files = user_files(folder)
    status, _, err = cli("clear", env={"PASSMD_CACHE_DIR": str(folder)})
    assert status == 2 and f"PASSMD_CACHE_DIR = '{folder}' ({folder})" in one_line(err)
    default = tmp_path / "xdg" / "passmd" / "results"  # the user cache folder (platformdirs, Linux)
    files |= user_files(default)
    (tmp_path / "project").mkdir()
    status, _, err = cli("prune", "--json", cwd=tmp_path / "project",
                         env={"XDG_CACHE_HOME": str(tmp_path / "xdg"), "PASSMD_CACHE_DIR": ""})
    assert status == 2 and f"the default cache directory ({default})" in one_line(err)
    assert list((tmp_path / "project").iterdir()) == []
    status, _, err = cli("clear", "--cache-dir", ".", cwd=folder)  # a relative path, as typed
    assert status == 2 and f"--cache-dir = '.' ({folder})" in one_line(err)
    assert_intact(files)


def test_a_file_as_cache_dir_is_refused(tmp_path):
    path = tmp_path / "results.csv"
    path.write_text("a,b\n")
    status, _, err = cli("clear", "--cache-dir", str(path), "--json")
    assert status == 2 and "is not a directory" in one_line(err)
    assert path.read_text() == "a,b\n"


def test_a_missing_or_empty_folder_is_an_empty_cache(tmp_path):
    """Nothing to remove and nothing to misread: exit 0, zero counts; the commands create nothing."""
    missing, empty = tmp_path / "missing", tmp_path / "empty"
    empty.mkdir()
    for folder in (missing, empty):
        for action in ("info", "clear", "prune"):
            store = Cache(folder)
            result = getattr(store, action)()
            assert (result["entries"] if action == "info" else result) == 0
    status, out, err = cli("clear", "--cache-dir", str(missing), "--json")
    assert status == 0 and json.loads(out)["removed"] == 0 and err == ""
    assert not missing.exists() and list(empty.iterdir()) == []


def test_a_sweep_does_not_use_a_folder_without_the_marker(tmp_path):
    """One warning; every point computed; nothing written into or removed from the folder."""
    folder = tmp_path / "thesis"
    files = user_files(folder)
    before = sorted(folder.rglob("*"))
    with pytest.warns(CacheWarning, match="is not a passmd cache.*continuing without the cache") as record:
        frame = sweep.run(point_function, [{"x": 1.0}, {"x": 2.0}], executor="serial", cache=Cache(folder),
                          progress=False)
    assert len(record) == 1
    assert frame["y"].tolist() == [1.0, 2.0]
    assert sorted(folder.rglob("*")) == before
    assert_intact(files)


def test_the_package_marks_a_folder_it_creates_or_finds_empty(tmp_path):
    for folder in (tmp_path / "new" / "cache", tmp_path / "empty"):
        if folder.name == "empty":
            folder.mkdir()
        store = Cache(folder)
        assert store.put(store.key(point_function, {"x": 1.0}), {"y": 1.0})
        lines = (folder / MARKER_NAME).read_text().splitlines()
        assert lines[0] == "Signature: 8a477f597d28d172789f06886806bc55"  # a cache directory tag
        assert "# passmd cache format: PASSMD-CACHE 1" in lines
        assert {p.name for p in folder.iterdir()} == {MARKER_NAME, store.key(point_function, {"x": 1.0})[:2]}


def test_an_unmarked_cache_of_own_entries_is_adopted_by_a_run_not_by_the_commands(tmp_path):
    """A cache filled before markers (entries and temporary files of the cache's own layout)."""
    folder = tmp_path / ".passmd-cache"
    store = marked_cache(folder)
    points = [{"x": 1.0}, {"x": 2.0}]
    first = sweep.run(point_function, points, executor="serial", cache=store, progress=False)
    (folder / MARKER_NAME).unlink()  # as older versions left it
    status, _, err = cli("prune", "--cache-dir", str(folder))
    assert status == 2 and "holds only passmd cache entries" in one_line(err)
    again = sweep.run(point_function, points, executor="serial", cache=Cache(folder), progress=False)
    assert again.attrs["sweep"]["cached"] == 2 and again["y"].tolist() == first["y"].tolist()
    assert (folder / MARKER_NAME).is_file()
    status, out, _ = cli("info", "--cache-dir", str(folder), "--json")
    assert status == 0 and json.loads(out)["entries"] == 2


def test_a_cachedir_tag_of_another_program_is_not_a_marker(tmp_path):
    folder = tmp_path / "other-cache"
    folder.mkdir()
    tag = folder / MARKER_NAME
    tag.write_text("Signature: 8a477f597d28d172789f06886806bc55\n# some other program's cache\n")
    (folder / "ab").mkdir()
    victim = folder / "ab" / (KEY_A + ".pmc")
    victim.write_bytes(craft(KEY_A, b"{}"))  # even an entry-like file is not touched
    with pytest.raises(NotACache, match="not a passmd cache"):
        Cache(folder).clear()
    with pytest.warns(CacheWarning, match="not a passmd cache"):
        assert Cache(folder).put(KEY_B, {"y": 1}) is False
    assert victim.exists() and tag.read_text().endswith("some other program's cache\n")
    assert sorted(p.name for p in folder.iterdir()) == [MARKER_NAME, "ab"]


def test_a_cache_of_another_format_version_is_refused(tmp_path):
    folder = tmp_path / "cache"
    store = marked_cache(folder)
    store.put(KEY_A, {"y": 1})
    marker = folder / MARKER_NAME
    marker.write_text(marker.read_text().replace("PASSMD-CACHE 1", "PASSMD-CACHE 2"))
    status, _, err = cli("clear", "--cache-dir", str(folder))
    assert status == 2 and "format 'PASSMD-CACHE 2'" in one_line(err)
    with pytest.warns(CacheWarning, match="PASSMD-CACHE 2"):
        assert Cache(folder).get(KEY_A, "miss") == "miss"
    assert Cache(folder).path(KEY_A).exists()


# --------------------------------------------------------------------------------------
# Inside a cache: only its own files go, and the count is true
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("json_flag", [False, True])
def test_clear_removes_only_entries_and_counts_them(tmp_path, json_flag):
    folder = tmp_path / "cache"
    store = marked_cache(folder)
    files = user_files(folder)  # a user's files put into a real cache
    store.put(KEY_B, {"y": 2.0})
    store.put("ab" + "2" * 62, {"y": 3.0})
    temp = folder / "cd" / f".{KEY_B[:16]}-k1l2m3n4.tmp"  # one of the cache's own temporary files
    temp.write_bytes(b"PASSMD-CACHE 1\nhalf")
    status, out, err = cli("clear", "--cache-dir", str(folder), *(["--json"] if json_flag else []))
    assert status == 0 and err == ""
    if json_flag:
        assert json.loads(out)["removed"] == 3
    else:
        assert out == f"clear: removed 3 file(s) from {folder}\n"
    assert store.entries() == [] and not temp.exists()
    assert_intact(files)
    assert (folder / MARKER_NAME).exists()


@pytest.mark.parametrize("json_flag", [False, True])
def test_prune_removes_only_stale_or_unreadable_entries(tmp_path, json_flag):
    folder = tmp_path / "cache"
    store = marked_cache(folder)
    files = user_files(folder)
    keep = store.key(point_function, {"x": 5.0})
    store.put(keep, {"y": 5.0})
    old = Cache(folder, fingerprint="0" * 64)
    old.put(old.key(point_function, {"x": 5.0}), {"y": 5.0})  # another code version
    broken = store.path("ab" + "3" * 62)
    broken.write_bytes(MAGIC + b"garbage")
    fresh = folder / "cd" / f".{KEY_B[:16]}-fresh123.tmp"  # a write in progress: kept
    stale = folder / "cd" / f".{KEY_B[:16]}-stale123.tmp"  # left by a killed process: removed
    fresh.parent.mkdir(exist_ok=True)
    fresh.write_bytes(b"x")
    stale.write_bytes(b"x")
    past = time.time() - 2 * cache.STALE_TEMP_SECONDS
    os.utime(stale, (past, past))
    status, out, err = cli("prune", "--cache-dir", str(folder), *(["--json"] if json_flag else []))
    assert status == 0 and err == ""
    if json_flag:
        assert json.loads(out)["removed"] == 3
    else:
        assert out == f"prune: removed 3 file(s) from {folder}\n"
    assert store.get(keep) == {"y": 5.0} and fresh.exists() and not stale.exists() and not broken.exists()
    assert_intact(files)


def test_info_counts_foreign_files_and_leaves_them(tmp_path):
    folder = tmp_path / "cache"
    store = marked_cache(folder)
    files = user_files(folder)
    store.put(KEY_B, {"y": 2.0})
    status, out, _ = cli("info", "--cache-dir", str(folder), "--json")
    info = json.loads(out)
    assert status == 0 and (info["entries"], info["foreign"], info["unreadable"]) == (1, len(files), 0)
    status, out, _ = cli("info", "--cache-dir", str(folder))
    assert status == 0 and f"foreign (left alone)    {len(files)}" in out
    assert_intact(files)


def test_a_subfolder_that_is_a_link_is_never_followed(tmp_path):
    folder = tmp_path / "cache"
    store = marked_cache(folder)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    victim = elsewhere / (KEY_A + ".pmc")
    victim.write_bytes(craft(KEY_A, b'{"format":1,"value":{"t":"none"}}'))
    (folder / "ab").symlink_to(elsewhere, target_is_directory=True)
    with pytest.warns(CacheWarning, match="a link or a file where the cache keeps a subfolder"):
        assert store.get(KEY_A, "miss") == "miss"
        assert store.put(KEY_A, {"y": 1}) is False
    assert store.prune() == 0 and store.clear() == 0
    assert sorted(p.name for p in elsewhere.iterdir()) == [victim.name]
    assert store.info()["foreign"] == 1


# --------------------------------------------------------------------------------------
# Keys are checked before they become paths
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("key", ["..escape", "../" + "a" * 61, "/tmp/x" + "a" * 58, "A" * 64, "a" * 63,
                                 "a" * 65, "", "ab/" + "c" * 61, "a" * 63 + "\n", 12345, None])
def test_a_key_that_is_not_64_hex_digits_is_refused(tmp_path, key):
    folder = tmp_path / "inner" / "cache"
    store = Cache(folder)
    for call in (lambda: store.put(key, {"y": 1}), lambda: store.get(key), lambda: key in store,
                 lambda: store.path(key)):
        with pytest.raises(ValueError, match=r"key = .* is not a cache key: must be 64 lowercase hex"):
            call()
    assert not (tmp_path / "inner").exists()  # nothing written, inside or outside the folder
    assert sorted(p.name for p in tmp_path.iterdir()) == []


# --------------------------------------------------------------------------------------
# Entries that cannot be read: reported once, removed, recomputed; never a crash
# --------------------------------------------------------------------------------------


def test_a_header_nested_200000_levels_is_removed_and_recomputed(tmp_path):
    folder = tmp_path / "cache"
    store = marked_cache(folder)
    points = [{"x": 1.0}, {"x": 2.0}]
    key = store.key(point_function, points[0])
    store.path(key).parent.mkdir(parents=True, exist_ok=True)
    store.path(key).write_bytes(craft(key, deep_header(key, 200_000)))
    status, out, err = cli("info", "--cache-dir", str(folder), "--json")
    assert status == 0 and json.loads(out)["unreadable"] == 1 and err == ""
    with pytest.warns(CacheWarning, match="nested too deeply.*removed; recomputing") as record:
        frame = sweep.run(point_function, points, executor="serial", cache=store, progress=False)
    assert len(record) == 1 and frame["y"].tolist() == [1.0, 2.0] and frame.attrs["sweep"]["computed"] == 2
    assert store.get(key) == {"y": 1.0}  # written back
    store.path(key).write_bytes(craft(key, deep_header(key, 200_000)))
    status, out, err = cli("prune", "--cache-dir", str(folder))
    assert status == 0 and out == f"prune: removed 1 file(s) from {folder}\n" and err == ""
    assert not store.path(key).exists()


def test_a_value_nested_deeper_than_the_limit_is_refused_when_stored_and_removed_when_read(tmp_path):
    store = marked_cache(tmp_path / "cache")
    deep = value = []
    for _ in range(cache.MAX_DEPTH - 1):
        value = [value]
    assert store.put(KEY_A, value) and store.get(KEY_A) == value  # at the limit: stored and read
    with pytest.raises(TypeError, match="nests deeper than 64 levels"):
        store.put(KEY_B, [value])
    deep.append(deep)  # a list that contains itself: refused, not a RecursionError
    with pytest.raises(TypeError, match="nests deeper"):
        store.put(KEY_B, deep)
    node = {"t": "none"}
    for _ in range(cache.MAX_DEPTH + 5):  # deep in the value tree, shallow for JSON
        node = {"t": "list", "v": [node]}
    header = json.dumps({"format": 1, "key": KEY_B, "value": node}).encode()
    store.path(KEY_B).parent.mkdir(exist_ok=True)
    store.path(KEY_B).write_bytes(craft(KEY_B, header))
    with pytest.warns(CacheWarning, match="nests deeper than 64 levels.*removed"):
        assert store.get(KEY_B, "miss") == "miss"
    assert not store.path(KEY_B).exists()


def test_a_header_above_the_size_limit_is_removed_unparsed(tmp_path):
    """Valid JSON with a valid checksum, one byte above 16 MiB: refused by its announced size."""
    store = marked_cache(tmp_path / "cache")
    pad = cache.MAX_HEADER_BYTES - len(KEY_A) - 47
    big = b'{"format":1,"key":"' + KEY_A.encode() + b'","value":{"t":"str","v":"' + b"x" * pad + b'"}}'
    assert len(big) == cache.MAX_HEADER_BYTES + 1
    store.path(KEY_A).parent.mkdir(exist_ok=True)
    store.path(KEY_A).write_bytes(craft(KEY_A, big))
    assert store.info()["unreadable"] == 1
    with pytest.warns(CacheWarning, match="header of .* bytes, above the .*-byte limit.*removed"):
        assert store.get(KEY_A, "miss") == "miss"
    assert not store.path(KEY_A).exists()


def test_a_result_above_the_size_limits_is_kept_not_cached(tmp_path, monkeypatch):
    store = marked_cache(tmp_path / "cache")
    monkeypatch.setattr(cache.entry, "MAX_ENTRY_BYTES", 10_000)
    too_large = "is not cached: its .* bytes are above the 10000-byte limit"
    with pytest.warns(CacheWarning, match=too_large) as record:
        frame = sweep.run(point_function, [{"x": np.zeros(2000)}, {"x": np.ones(2000)}], executor="serial",
                          cache=store, progress=False)
    assert len(record) == 1 and len(frame) == 2 and store.entries() == []
    monkeypatch.setattr(cache.entry, "MAX_HEADER_BYTES", 100)
    with pytest.warns(CacheWarning, match="header of .* bytes is above the 100-byte limit"):
        assert store.put(KEY_A, {"y": list(range(50))}, function="other") is False


def test_an_entry_above_the_size_limit_is_removed_unread(tmp_path):
    """A 1 GiB + 1 byte (sparse) file with the magic line: removed without reading it."""
    store = marked_cache(tmp_path / "cache")
    path = store.path(KEY_A)
    path.parent.mkdir(exist_ok=True)
    with open(path, "wb") as fh:
        fh.write(MAGIC)
        fh.truncate(cache.MAX_ENTRY_BYTES + 1)
    assert store.info()["unreadable"] == 1
    with pytest.warns(CacheWarning, match="above the 1073741824-byte limit.*removed"):
        assert store.get(KEY_A, "miss") == "miss"
    assert not path.exists()


@pytest.mark.parametrize("target", ["/dev/zero", "user file", "dangling"])
def test_a_link_at_an_entry_path_is_removed_never_its_target(tmp_path, target):
    folder = tmp_path / "cache"
    store = marked_cache(folder)
    user = tmp_path / "user.dat"
    user.write_bytes(store.path(KEY_A).name.encode())
    link = store.path(KEY_A)
    link.parent.mkdir(exist_ok=True)
    destination = {"/dev/zero": Path("/dev/zero"), "user file": user, "dangling": tmp_path / "gone"}[target]
    link.symlink_to(destination)
    status, out, _ = cli("info", "--cache-dir", str(folder), "--json")
    assert status == 0 and json.loads(out)["unreadable"] == 1
    with pytest.warns(CacheWarning, match="symbolic link.*removed; recomputing") as record:
        assert store.get(KEY_A, "miss") == "miss"
    assert len(record) == 1 and not os.path.lexists(link)
    assert user.read_bytes() == link.name.encode() and Path("/dev/zero").exists()
    link.symlink_to(destination)  # prune and clear remove the link too
    status, out, _ = cli("prune", "--cache-dir", str(folder), "--json")
    assert status == 0 and json.loads(out)["removed"] == 1 and not os.path.lexists(link)
    link.symlink_to(destination)
    assert store.put(KEY_A, {"y": 1}) and store.get(KEY_A) == {"y": 1}  # replaces the link itself
    assert user.read_bytes() == link.name.encode()


def test_a_fifo_at_an_entry_path_neither_blocks_nor_stays(tmp_path):
    store = marked_cache(tmp_path / "cache")
    path = store.path(KEY_A)
    path.parent.mkdir(exist_ok=True)
    os.mkfifo(path)
    assert store.info()["unreadable"] == 1
    with pytest.warns(CacheWarning, match="not a regular file.*removed"):
        assert store.get(KEY_A, "miss") == "miss"
    assert not os.path.lexists(path)
    os.mkfifo(path)
    assert store.clear() == 1 and not os.path.lexists(path)


def test_a_directory_at_an_entry_path_is_left_alone(tmp_path):
    store = marked_cache(tmp_path / "cache")
    inside = store.path(KEY_A) / "keep.txt"
    inside.parent.mkdir(parents=True)
    inside.write_text("keep")
    with pytest.warns(CacheWarning, match="a directory: left in place"):
        assert store.get(KEY_A, "miss") == "miss"
        assert store.put(KEY_A, {"y": 1}) is False
    assert store.prune() == 0 and store.clear() == 0 and inside.read_text() == "keep"


# --------------------------------------------------------------------------------------
# Temporary files: removed on any exception, and by prune once stale
# --------------------------------------------------------------------------------------


class _Terminated(BaseException):
    """What a signal handler may raise in the middle of a write."""


@pytest.mark.parametrize("exception", [KeyboardInterrupt, SystemExit, _Terminated, MemoryError])
@pytest.mark.parametrize("where", ["fdopen", "replace"])
def test_put_removes_its_temporary_file_on_any_exception(tmp_path, monkeypatch, exception, where):
    store = marked_cache(tmp_path / "cache")

    def interrupted(*args, **kwargs):
        raise exception

    monkeypatch.setattr(cache.store.os, where, interrupted)
    with pytest.raises(exception):
        store.put(KEY_A, {"y": 1.0})
    monkeypatch.undo()
    assert [p.name for p in store.directory.rglob("*") if p.is_file()] == [MARKER_NAME]


SIGTERM_SCRIPT = """
import os, signal, sys, time
from passmd.runtime import sweep
from passmd.runtime.cache import Cache


def point(x):
    return {"y": x + 0.5}


if __name__ == "__main__":
    cache_dir, mode = sys.argv[1], sys.argv[2]
    if mode == "handled":  # as the command line handles SIGTERM: like Ctrl-C
        def terminated(signum, frame):
            raise KeyboardInterrupt
        signal.signal(signal.SIGTERM, terminated)
    store = Cache(cache_dir)
    store.put(store.key(point, {"x": -1.0}), {"y": 0.0})
    real_replace, calls = os.replace, []

    def slow_replace(source, target):  # the signal arrives while the first entry of the sweep is written
        calls.append(source)
        if len(calls) == 1:
            print("writing", flush=True)
            time.sleep(60)
        real_replace(source, target)

    os.replace = slow_replace
    try:
        sweep.run(point, [{"x": float(i)} for i in range(4)], executor="process", workers=2, cache=store,
                  progress=False)
    except KeyboardInterrupt:
        sys.exit(143)
"""


def _terminate_during_a_write(tmp_path, mode):
    script, folder = tmp_path / "sweep_script.py", tmp_path / "cache"
    script.write_text(SIGTERM_SCRIPT)
    proc = subprocess.Popen([sys.executable, str(script), str(folder), mode], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)
    assert proc.stdout.readline() == "writing\n", proc.stderr.read()
    assert list(folder.glob("??/.*.tmp"))  # the write is under way
    os.killpg(proc.pid, signal.SIGTERM)  # as `timeout` or a batch system sends it
    try:
        proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    return proc.returncode, folder


def test_sigterm_during_a_process_pool_sweep_leaves_no_temporary_file(tmp_path):
    status, folder = _terminate_during_a_write(tmp_path, "handled")
    assert status == 143
    assert not list(folder.glob("??/.*.tmp"))


def test_a_process_killed_during_a_write_leaves_a_temporary_file_that_prune_removes_once_stale(tmp_path):
    status, folder = _terminate_during_a_write(tmp_path, "killed")
    assert status == -signal.SIGTERM
    (leftover,) = folder.glob("??/.*.tmp")
    status, out, _ = cli("prune", "--cache-dir", str(folder), "--json")
    assert status == 0 and json.loads(out)["removed"] == 0 and leftover.exists()  # may be a write under way
    past = time.time() - 2 * cache.STALE_TEMP_SECONDS
    os.utime(leftover, (past, past))
    status, out, _ = cli("prune", "--cache-dir", str(folder), "--json")
    assert status == 0 and json.loads(out)["removed"] == 1 and not leftover.exists()
    assert len(Cache(folder).entries()) == 1  # the finished entry stays


# --------------------------------------------------------------------------------------
# Generated cache folders (hypothesis): only the cache's own files are ever removed
# --------------------------------------------------------------------------------------

HEX = "0123456789abcdef"
keys = st.text(HEX, min_size=64, max_size=64)
names = st.text("abcdefghijklmnopqrstuvwxyz0123456789_-", min_size=3, max_size=12)
LOCATIONS = ["entry", "entry-wrong-folder", "short-name", "upper-case", "user-pkl", "user-tmp", "user-pmc",
             "own-temp", "own-temp-stale", "own-temp-wrong-folder", "top-level", "nested"]
CONTENTS = ["random", "magic", "entry-current", "entry-other-code", "deep", "big-header", "foreign-key",
            "link-dev-zero", "link-user", "link-dangling", "fifo", "directory"]
REMOVABLE_AT_ENTRY = {"magic", "entry-current", "entry-other-code", "deep", "big-header", "foreign-key",
                      "link-dev-zero", "link-user", "link-dangling", "fifo"}
REGULAR = {"random", "magic", "entry-current", "entry-other-code", "deep", "big-header", "foreign-key"}


@st.composite
def cache_items(draw):
    """(relative path, location, content, key, depth) of one thing put into a cache folder."""
    key = draw(keys)
    other = draw(keys.filter(lambda k: k[:2] != key[:2]))
    location = draw(st.sampled_from(LOCATIONS))
    name = draw(names)
    upper = "A" + key[1:].upper()
    path = {
        "entry": f"{key[:2]}/{key}.pmc",
        "entry-wrong-folder": f"{other[:2]}/{key}.pmc",
        "short-name": f"{key[:2]}/{key[:63]}.pmc",
        "upper-case": f"{upper[:2]}/{upper}.pmc",
        "user-pkl": f"{key[:2]}/{name}.pkl",
        "user-tmp": f"{key[:2]}/{name}.tmp",
        "user-pmc": f"{key[:2]}/{name}.pmc",
        "own-temp": f"{key[:2]}/.{key[:16]}-{name[:8].replace('-', '_')}.tmp",
        "own-temp-stale": f"{key[:2]}/.{key[:16]}-{name[:8].replace('-', '_')}.tmp",
        "own-temp-wrong-folder": f"{other[:2]}/.{key[:16]}-abcdefgh.tmp",
        "top-level": f"{name}.{draw(st.sampled_from(['pkl', 'tmp', 'pmc', 'txt']))}",
        "nested": f"{key[:2]}/{name}/{key}.pmc",
    }[location]
    content = draw(st.sampled_from(CONTENTS))
    return path, location, content, key, draw(st.integers(1, 3000)), draw(st.binary(max_size=64))


def _content_bytes(content, key, depth, noise, current, user):
    if content == "random":
        return b"#" + noise  # never the magic line
    if content == "magic":
        return MAGIC + noise
    if content in ("entry-current", "entry-other-code"):
        fingerprint = current if content == "entry-current" else "0" * 64
        return cache.encode_entry(key, {"y": noise.hex()}, fingerprint=fingerprint)
    if content == "foreign-key":
        return cache.encode_entry("f" * 64, {"y": 1.0}, fingerprint=current)
    if content == "deep":
        return craft(key, deep_header(key, depth))
    if content == "big-header":
        return MAGIC + f"{'0' * 64} {cache.MAX_HEADER_BYTES + 1}\n".encode() + noise
    return None


def build(root: Path, items, store: Cache, user: Path) -> dict:
    """Make the items under ``root``; return {path: (location, content)} of those made."""
    made = {}
    for rel, location, content, key, depth, noise in items:
        path = root / rel
        if os.path.lexists(path) or any(os.path.lexists(p) and not p.is_dir() for p in path.parents):
            continue  # clashes with an earlier item
        path.parent.mkdir(parents=True, exist_ok=True)
        data = _content_bytes(content, key, depth, noise, store.fingerprint, user)
        if data is not None:
            path.write_bytes(data)
            if location == "own-temp-stale":
                past = time.time() - 2 * cache.STALE_TEMP_SECONDS
                os.utime(path, (past, past))
        elif content == "fifo":
            os.mkfifo(path)
        elif content == "directory":
            path.mkdir()
            (path / "inside.txt").write_bytes(noise)
        else:
            path.symlink_to({"link-dev-zero": Path("/dev/zero"), "link-user": user,
                             "link-dangling": root.parent / "gone"}[content])
        made[path] = (location, content, key, noise)
    return made


def snapshot(top: Path) -> dict:
    """Everything under ``top``, links not followed: kind and content of each path."""
    found = {}
    for here, dirs, files in os.walk(top, followlinks=False):
        for name in dirs + files:
            path = Path(here) / name
            info = os.lstat(path)
            if os.path.islink(path):
                found[path] = ("link", os.readlink(path))
            elif path.is_dir():
                found[path] = ("dir",)
            elif path.is_file():
                found[path] = ("file", hashlib.sha256(path.read_bytes()).hexdigest(), info.st_mtime_ns)
            else:
                found[path] = ("special", info.st_mode)
    return found


def removable(made: dict, action: str) -> set:
    """Independent statement of what each action may remove (the module docstring's rule)."""
    allowed = set()
    for path, (location, content, _, _) in made.items():
        if location == "entry" and content in REMOVABLE_AT_ENTRY:
            if action == "clear" or content != "entry-current":
                allowed.add(path)
        elif location in ("own-temp", "own-temp-stale") and content in REGULAR:
            if action == "clear" or location == "own-temp-stale":
                allowed.add(path)
    return allowed


def assert_only_removed(before: dict, after: dict, allowed: set):
    assert set(after) <= set(before), sorted(set(after) - set(before))  # nothing new
    for path, state in before.items():
        if path in after:
            assert after[path] == state, path  # never modified
        else:
            assert path in allowed, path  # removed: must be the cache's own


@contextlib.contextmanager
def scratch():
    with tempfile.TemporaryDirectory() as top, warnings.catch_warnings():
        warnings.simplefilter("ignore", CacheWarning)
        top = Path(top)
        user = top / "user.dat"
        user.write_bytes(b"the user's data")
        yield top, user


@FUZZ_SETTINGS
@given(items=st.lists(cache_items(), max_size=12))
def test_generated_cache_folders_lose_only_the_caches_own_files(items):
    with scratch() as (top, user):
        store = marked_cache(top / "cache")
        made = build(store.directory, items, store, user)
        before = snapshot(top)
        info = store.info()  # never changes anything
        assert snapshot(top) == before
        assert info["entries"] + info["unreadable"] == sum(
            loc == "entry" and content in REMOVABLE_AT_ENTRY for loc, content, _, _ in made.values())
        for path, (location, content, key, noise) in made.items():  # reads: the value or a miss
            if location != "entry":
                continue
            state = snapshot(top)
            value = store.get(key, "miss")
            stored = content in ("entry-current", "entry-other-code")
            assert value == ({"y": noise.hex()} if stored else "miss")
            assert_only_removed(state, snapshot(top), removable({path: made[path]}, "clear"))
        made = {p: v for p, v in made.items() if os.path.lexists(p)}
        state = snapshot(top)
        removed = store.prune()
        after = snapshot(top)
        assert_only_removed(state, after, removable(made, "prune"))
        assert removed == len(set(state) - set(after))
        state = after
        removed = store.clear()
        after = snapshot(top)
        assert_only_removed(state, after, removable(made, "clear"))
        assert removed == len(set(state) - set(after))
        assert not (removable(made, "clear") & set(after))  # clear is complete
        assert user.read_bytes() == b"the user's data" and (store.directory / MARKER_NAME).is_file()


@FUZZ_SETTINGS
@given(items=st.lists(cache_items(), min_size=1, max_size=8))
def test_generated_folders_without_the_marker_are_never_touched(items):
    with scratch() as (top, user):
        folder = top / "folder"
        folder.mkdir()
        build(folder, items, Cache(folder), user)
        before = snapshot(top)
        for action in ("info", "prune", "clear"):
            if not any(folder.iterdir()):
                break
            with pytest.raises(NotACache):
                getattr(Cache(folder), action)()
            assert snapshot(top) == before


@FUZZ_SETTINGS
@given(data=st.one_of(st.binary(max_size=200), st.binary(max_size=200).map(lambda b: MAGIC + b)))
def test_generated_bytes_decode_to_a_value_or_a_corrupt_entry(data):
    try:
        cache.decode_entry(data, KEY_A)
    except CorruptEntry:
        pass


json_values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=5),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.sampled_from(["t", "v", "dtype", "shape",
                                                                                  "offset", "nbytes", "x"]),
                                                                inner, max_size=4),
    max_leaves=20)
nodes = st.recursive(
    st.fixed_dictionaries({"t": st.sampled_from(["none", "bool", "int", "float", "str", "array", "?"]),
                           "v": json_values}),
    lambda inner: st.fixed_dictionaries({"t": st.sampled_from(["list", "tuple", "dict"]),
                                         "v": st.lists(inner | st.lists(inner, max_size=3), max_size=3)}),
    max_leaves=10)
arrays = st.fixed_dictionaries({"t": st.just("array"),
                                "dtype": st.sampled_from(["<f8", "|u1", "O", "V8", "<c16", "x"]),
                                "shape": st.lists(st.integers(-2, 2**62), max_size=3),
                                "offset": st.integers(-5, 100), "nbytes": st.integers(-5, 100)})


@FUZZ_SETTINGS
@given(value=st.one_of(nodes, arrays, json_values), payload=st.binary(max_size=64))
def test_generated_headers_with_a_valid_checksum_decode_to_a_value_or_a_corrupt_entry(value, payload):
    header = json.dumps({"format": 1, "key": KEY_A, "value": value}).encode()
    try:
        cache.decode_entry(craft(KEY_A, header, payload), KEY_A)
    except CorruptEntry:
        pass


@FUZZ_SETTINGS
@given(key=st.one_of(st.text(max_size=70), keys, st.text(HEX + "./", min_size=60, max_size=68)))
def test_generated_keys_are_refused_or_stay_inside_the_cache(key):
    with scratch() as (top, _user):
        store = Cache(top / "a" / "cache")
        try:
            written = store.put(key, {"y": 1})
        except ValueError as exc:
            assert "is not a cache key" in str(exc)
            assert sorted(p.name for p in top.iterdir()) == ["user.dat"]
            return
        assert written and store.get(key) == {"y": 1}
        assert {p for p in top.rglob("*") if p.is_file()} == {
            top / "user.dat", store.directory / MARKER_NAME, store.directory / key[:2] / f"{key}.pmc"}
