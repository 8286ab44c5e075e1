"""The book's one evaluation of the whole ledger, written once per build and read by every chapter.

Every chapter shows its ledger rows judged in the whole ledger (the joint reading needs every
claim), so without this each chapter would evaluate all the claims again from the same cached
results. ``nox -s book`` runs ``passmd ledger --profile P --write-evaluation FILE``, which writes the
evaluation it has just made (:func:`encode`), and points ``$PASSMD_BOOK_LEDGER`` at the file;
:func:`passmd.report.publish.book_evaluation` reads it.

The file is a checksummed data entry in the result cache's format (no pickle:
:mod:`passmd.runtime.cache.entry`) whose key is the profile, the package's code and its data files
(claims, reference values): a file written for another profile, or by other code or data, is not
read, and the chapter evaluates the ledger itself. A dict whose keys are not strings (a reading,
keyed by its axes' values) is stored as its list of items.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import pandas as pd

from passmd.runtime.cache.entry import CorruptEntry, decode_entry, encode_entry
from passmd.runtime.cache.keys import code_fingerprint, tree_fingerprint

__all__ = ["decode_table", "encode", "encode_table", "key", "read"]

_ITEMS = "__items__"  # marks a dict stored as its list of (key, value) pairs
_DATA_DIR = Path(__file__).resolve().parents[1] / "data"  # passmd/data
_FUNCTION = "passmd.report.evaluation.evaluate"


def _data_fingerprint() -> str:
    """The package's data files other than benchmark records: the evaluation reads them (claims,
    reference values), and the code fingerprint covers the Python files only."""
    return tree_fingerprint(_DATA_DIR, "*", skip=("benchmarks",))


def key(profile: str) -> str:
    """The key of the evaluation of ``profile`` by this package: its profile, code and data files."""
    text = "\0".join(("ledger evaluation", profile, code_fingerprint(), _data_fingerprint()))
    return hashlib.sha256(text.encode()).hexdigest()


def _encode(value):
    if isinstance(value, dict):
        if all(isinstance(k, str) for k in value) and _ITEMS not in value:
            return {k: _encode(v) for k, v in value.items()}
        return {_ITEMS: [(_encode(k), _encode(v)) for k, v in value.items()]}
    if isinstance(value, (list, tuple)):
        return type(value)(_encode(v) for v in value)
    return value


def _decode(value):
    if isinstance(value, dict):
        if set(value) == {_ITEMS}:
            return {_decode(k): _decode(v) for k, v in value[_ITEMS]}
        return {k: _decode(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return type(value)(_decode(v) for v in value)
    return value


def encode_table(table: pd.DataFrame) -> dict:
    """The table as a tree of the cache's data types: its columns in order, their values, its ``attrs``."""
    return {"columns": list(table.columns),
            "values": {c: [v.item() if hasattr(v, "item") else v for v in table[c]] for c in table.columns},
            "attrs": _encode(dict(table.attrs))}


def decode_table(value: dict) -> pd.DataFrame:
    """The table :func:`encode_table` wrote."""
    table = pd.DataFrame({c: value["values"][c] for c in value["columns"]}, columns=value["columns"])
    table.attrs = _decode(value["attrs"])
    return table


def encode(table: pd.DataFrame, profile: str) -> bytes:
    """The file's bytes: the evaluated ledger of ``profile`` in a checksummed entry under :func:`key`."""
    return encode_entry(key(profile), encode_table(table), function=_FUNCTION, fingerprint=code_fingerprint())


def read(path, profile: str) -> pd.DataFrame | None:
    """The evaluated ledger at ``path`` if it was written for ``profile`` by this package's code and
    data; None if there is no such file or it was written for another (the caller evaluates)."""
    try:
        data = Path(path).read_bytes()
    except FileNotFoundError:
        return None
    try:
        _, value = decode_entry(data, key=key(profile))
    except CorruptEntry:
        return None
    return decode_table(value)
