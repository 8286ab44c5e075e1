"""``passmd sweep --out PREFIX``: PREFIX.csv, PREFIX.json and (one or two axes) PREFIX.png.

Checked before any work (:func:`check_prefix`) and written together at the end (:func:`write`),
never over a file unless ``--overwrite`` (:mod:`passmd.runtime.outputs`).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from passmd.cli.errors import UsageError
from passmd.cli.output import check_output_file, plain
from passmd.cli.streams import check_new_outputs, check_outputs, create_outputs

__all__ = ["check_prefix", "outputs", "write"]


def outputs(prefix: str, axes: int) -> dict[str, str]:
    """PREFIX.csv, PREFIX.json and, for one or two axes, PREFIX.png."""
    files = {"csv": prefix + ".csv", "json": prefix + ".json"}
    if axes <= 2:
        files["png"] = prefix + ".png"
    return files


def _named(prefix: str, files: dict[str, str]) -> dict[str, str]:
    return {path: f"--out {prefix}" for path in files.values()}


def check_prefix(prefix: str, overwrite: bool) -> None:
    """--out PREFIX before any work: a file stem (not a folder, not ending in a separator), its
    files not there already (unless ``overwrite``) and creatable in an existing folder (exit 2)."""
    stem = os.path.basename(prefix)
    if not stem or stem in (".", "..") or prefix.endswith(os.sep) or Path(prefix).is_dir():
        raise UsageError(f"--out = {prefix!r} names a directory, not a PREFIX: give the files' stem, e.g. "
                         f"{os.path.join(prefix.rstrip(os.sep) or '.', 'map')!r}")
    files = outputs(prefix, 2)
    for suffix in (".csv", ".json", ".png"):
        check_output_file("--out", prefix + suffix)
    check_outputs({f"{path} (--out {prefix})": path for path in files.values()})
    check_new_outputs(_named(prefix, files), overwrite=overwrite)


def write(args, record: dict, table, figure) -> dict[str, str]:
    """PREFIX.csv (``table``, with ``record``'s provenance as ``#`` lines), PREFIX.json (``record``)
    and, given a ``figure``, PREFIX.png, written together or not at all, never over a file unless
    --overwrite (:func:`passmd.cli.streams.create_outputs`). Returns the files, by kind."""
    prefix = args.out
    files = outputs(prefix, 2 if figure is not None else 3)
    header = "".join(f"# {k}: {v}\n" for k, v in record["provenance"].items())
    header += f"# quantity: {args.quantity} ({record['column']})\n"

    def write_csv(tmp):
        with open(tmp, "w", encoding="utf-8", newline="") as fh:
            fh.write(header)
            table.to_csv(fh, index=False, lineterminator="\n")

    text = json.dumps(plain({**record, "files": files}), indent=2, allow_nan=False) + "\n"
    writers = {files["csv"]: write_csv,
               files["json"]: lambda tmp: Path(tmp).write_text(text, encoding="utf-8")}
    if figure is not None:
        facts = record["provenance"]
        summary = f"passmd {facts['passmd_version']}, commit {facts['git_commit']}"
        writers[files["png"]] = lambda tmp: figure.savefig(tmp, dpi=150, format="png",
                                                           metadata={"Description": summary})
    create_outputs(writers, _named(prefix, files), overwrite=args.overwrite)
    return files
