"""The book's one evaluation of the whole ledger, written once per build and read by every chapter.

Every chapter shows its ledger rows judged in the whole ledger (the joint reading needs every
claim), so without this each chapter would evaluate all the claims again from the same cached
results. ``nox -s book`` runs ``python -m passmd.report.stored_evaluation --profile P --out FILE``
after ``passmd ledger`` and points ``$PASSMD_BOOK_LEDGER`` at the file;
:func:`passmd.report.publish.book_evaluation` reads it.

The file is a checksummed data entry in the result cache's format (no pickle:
:mod:`passmd.runtime.cache.entry`) whose key is the profile, the package's code and its data files
(claims, reference values): a file written for another profile, or by other code or data, is not
read, and the chapter evaluates the ledger itself. A dict whose keys are not strings (a reading,
keyed by its axes' values) is stored as its list of items.
"""

from __future__ import annotations

import argparse
import hashlib
import sys
from pathlib import Path

import pandas as pd

from passmd.runtime.cache.entry import CorruptEntry, decode_entry, encode_entry
from passmd.runtime.cache.keys import code_fingerprint, tree_fingerprint
from passmd.runtime.outputs import write_file

__all__ = ["decode_table", "encode_table", "key", "read", "write"]

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


def write(path, table: pd.DataFrame, profile: str) -> None:
    """Write the evaluated ledger of ``profile`` to ``path`` (replacing the build's earlier one)."""
    data = encode_entry(key(profile), encode_table(table), function=_FUNCTION, fingerprint=code_fingerprint())
    write_file(path, lambda tmp: Path(tmp).write_bytes(data), overwrite=True)


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


def main(argv=None) -> int:
    """``python -m passmd.report.stored_evaluation --profile P --out FILE``: evaluate the whole ledger
    of profile P (its results from the cache ``passmd ledger`` filled) and write it to FILE."""
    from passmd.report import evaluation
    from passmd.runtime.config import PROFILES, RunConfig

    parser = argparse.ArgumentParser(description=main.__doc__.splitlines()[0])
    parser.add_argument("--profile", required=True, choices=PROFILES)
    parser.add_argument("--out", required=True, help="the file the book's chapters read")
    args = parser.parse_args(argv)
    config = RunConfig.from_environment(profile=args.profile)
    write(args.out, evaluation.evaluate(config=config), config.profile)
    return 0


if __name__ == "__main__":
    sys.exit(main())
