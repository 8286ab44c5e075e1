"""The ledger's regression baselines: each claim's category on a profile, with the readings it was
computed at, its state at each of them, the reading its category was judged at (its held-out
reading) and its reading at the in-sample joint reading (``tests/ledger_baseline_<profile>.csv``).

:func:`write_baseline` (:func:`baseline_csv`, its text) records an evaluated ledger
(:func:`passmd.report.evaluation.evaluate`),
:func:`load_baseline`, :func:`load_baseline_readings` and :func:`load_baseline_states` read one back,
and :func:`check_categories` fails with a readable diff when any claim changed category.
"""

from __future__ import annotations

import io
from collections.abc import Mapping
from pathlib import Path

import pandas as pd

from passmd.ledger import readings
from passmd.runtime.inputs import read_text
from passmd.runtime.outputs import write_file

__all__ = ["READINGS_SEPARATOR", "STATE_LETTERS", "baseline_csv", "category_changes", "check_categories",
           "load_baseline", "load_baseline_readings", "load_baseline_states", "readings_of", "write_baseline"]

#: Separator of the readings in a baseline's ``readings`` column.
READINGS_SEPARATOR = " | "

#: One letter per reading in a baseline's ``states`` column, in the order of its ``readings``.
STATE_LETTERS = {"holds": "h", "fails": "f", "inconclusive": "?"}


def readings_of(depends: tuple[str, ...]) -> tuple[str, ...]:
    """The readings a claim depending on ``depends`` is evaluated at, in words."""
    return tuple(readings.describe(r) for r in readings.design(depends))


def _read(path) -> pd.DataFrame:
    """A baseline CSV, read from a regular file of at most ``LIMITS["reference table"]`` bytes."""
    text = read_text(path, "reference table")
    return pd.read_csv(io.StringIO(text), dtype=str, keep_default_na=False, comment="#")


def load_baseline(path) -> dict[str, str]:
    """``{claim id: category}`` from a baseline CSV written by :func:`write_baseline`."""
    table = _read(path)
    return dict(zip(table["claim"], table["status"], strict=True))


def load_baseline_readings(path) -> dict[str, tuple[str, ...]]:
    """``{claim id: readings}`` recorded in a baseline CSV (its ``readings`` column).

    Empty when the baseline records no readings: the readings its categories were computed at
    are then unknown, and no claim of it can be compared reading for reading.
    """
    table = _read(path)
    if "readings" not in table:
        return {}
    return {claim: tuple(text.split(READINGS_SEPARATOR))
            for claim, text in zip(table["claim"], table["readings"], strict=True)}


def load_baseline_states(path) -> dict[str, dict]:
    """``{claim id: {"states": {reading: state}, "held_out": reading, "joint": reading}}`` recorded in a
    baseline CSV: the claim's state (``holds``, ``fails``, ``inconclusive``) at each of its readings, the
    reading its category was judged at (held out) and its reading at the in-sample joint reading.
    Empty when the baseline records no states."""
    table = _read(path)
    if "states" not in table:
        return {}
    names = {letter: state for state, letter in STATE_LETTERS.items()}
    held = table["held_out"] if "held_out" in table else table["joint"]
    return {claim: {"states": dict(zip(text.split(READINGS_SEPARATOR), (names[c] for c in letters),
                                       strict=True)), "held_out": h, "joint": joint}
            for claim, text, letters, h, joint in zip(table["claim"], table["readings"], table["states"],
                                                      held,
                                                      table["joint"], strict=True)}


def baseline_csv(evaluated: pd.DataFrame, header: str = "") -> str:
    """The claims' categories as a baseline CSV (``claim,status,readings,states,held_out,joint``).

    ``readings`` lists the readings each category was computed at (from the row's
    ``depends_on``), so that two baselines are compared only where they evaluated the same
    readings; ``states`` the claim's state at each
    (:data:`passmd.ledger.baseline.STATE_LETTERS`, from the table's ``points``), ``held_out`` the
    reading of them its category was judged at (``defaults`` for a study) and ``joint`` its reading at
    the in-sample joint reading. ``header`` (e.g. the command and date that produced it) is written as
    ``#`` lines.
    """
    table = evaluated[["claim", "status"]].copy()
    depends = [tuple(d for d in text.split(";") if d) for text in evaluated["depends_on"]]
    table["readings"] = [READINGS_SEPARATOR.join(readings_of(d)) for d in depends]
    states = {(p["claim"], p["reading"]): p["state"] for p in evaluated.attrs.get("points", [])}
    table["states"] = ["".join(STATE_LETTERS[states.get((claim, r), "inconclusive")] for r in readings_of(d))
                       for claim, d in zip(evaluated["claim"], depends, strict=True)]
    table["held_out"] = [r if r != "—" else "defaults" for r in evaluated["held_out_reading"]]
    table["joint"] = [r if r != "—" else "defaults" for r in evaluated["joint_reading"]]
    comments = "".join(f"# {line}\n" for line in header.splitlines())
    return comments + table.to_csv(index=False, lineterminator="\n")


def write_baseline(evaluated: pd.DataFrame, path, header: str = "", *, overwrite: bool = False) -> None:
    """Write :func:`~passmd.ledger.baseline.baseline_csv` to ``path``, completely or not at all
    (:func:`passmd.runtime.outputs.write_file`).

    A regular file already at ``path`` is replaced only with ``overwrite`` (else
    :class:`~passmd.runtime.outputs.OutputExists`, a ``FileExistsError``, and the file is kept).
    """
    text = baseline_csv(evaluated, header)
    write_file(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8", newline=""),
               overwrite=overwrite)


def category_changes(evaluated: pd.DataFrame, baseline: Mapping[str, str]) -> pd.DataFrame:
    """Every claim whose category differs from ``baseline`` (or that appeared or disappeared).

    Columns ``claim``, ``baseline``, ``now`` (``"missing"`` where absent) and ``verdict``.
    """
    current = dict(zip(evaluated["claim"], evaluated["status"], strict=True))
    verdicts = dict(zip(evaluated["claim"], evaluated["verdict"], strict=True))
    rows = []
    for claim in list(baseline) + [c for c in current if c not in baseline]:
        before, now = baseline.get(claim, "missing"), current.get(claim, "missing")
        if before != now:
            rows.append({"claim": claim, "baseline": before, "now": now,
                         "verdict": verdicts.get(claim, "claim no longer in the ledger")})
    return pd.DataFrame(rows, columns=["claim", "baseline", "now", "verdict"])


def check_categories(evaluated: pd.DataFrame, baseline: Mapping[str, str]) -> None:
    """Raise ``AssertionError`` with a readable diff when any claim changed category."""
    changed = category_changes(evaluated, baseline)
    if len(changed):
        lines = [f"{r.claim}: {r.baseline} -> {r.now} ({r.verdict})" for r in changed.itertuples()]
        raise AssertionError(f"{len(lines)} claim(s) changed category against the baseline:\n  "
                             + "\n  ".join(lines))
