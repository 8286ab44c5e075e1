"""The ledger's regression baselines: each claim's category on a profile, with the readings it was
computed at (``tests/ledger_baseline_<profile>.csv``).

:func:`write_baseline` records an evaluated ledger (:func:`passmd.ledger.evaluation.evaluate`),
:func:`load_baseline` and :func:`load_baseline_readings` read one back, and
:func:`check_categories` fails with a readable diff when any claim changed category.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import pandas as pd

from passmd.ledger import readings

__all__ = ["READINGS_SEPARATOR", "category_changes", "check_categories", "load_baseline",
           "load_baseline_readings", "readings_of", "write_baseline"]

#: Separator of the readings in a baseline's ``readings`` column.
READINGS_SEPARATOR = " | "


def readings_of(depends: tuple[str, ...]) -> tuple[str, ...]:
    """The readings a claim depending on ``depends`` is evaluated at, in words."""
    return tuple(readings.describe(r) for r in readings.design(depends))


def load_baseline(path) -> dict[str, str]:
    """``{claim id: category}`` from a baseline CSV written by :func:`write_baseline`."""
    table = pd.read_csv(path, dtype=str, keep_default_na=False, comment="#")
    return dict(zip(table["claim"], table["status"], strict=True))


def load_baseline_readings(path) -> dict[str, tuple[str, ...]]:
    """``{claim id: readings}`` recorded in a baseline CSV (its ``readings`` column).

    Empty when the baseline records no readings: the readings its categories were computed at
    are then unknown, and no claim of it can be compared reading for reading.
    """
    table = pd.read_csv(path, dtype=str, keep_default_na=False, comment="#")
    if "readings" not in table:
        return {}
    return {claim: tuple(text.split(READINGS_SEPARATOR))
            for claim, text in zip(table["claim"], table["readings"], strict=True)}


def write_baseline(evaluated: pd.DataFrame, path, header: str = "") -> None:
    """Write the claims' categories as a baseline CSV (``claim,status,readings``), atomically.

    ``readings`` lists the readings each category was computed at (from the row's
    ``depends_on``), so that two baselines are compared only where they evaluated the same
    readings. ``header`` (e.g. the command and date that produced it) is written as ``#`` lines.
    """
    path = Path(path)
    table = evaluated[["claim", "status"]].copy()
    table["readings"] = [READINGS_SEPARATOR.join(readings_of(tuple(d for d in depends.split(";") if d)))
                         for depends in evaluated["depends_on"]]
    tmp = path.with_name(f".{path.name}.tmp")
    with open(tmp, "w", encoding="utf-8", newline="") as fh:
        for line in header.splitlines():
            fh.write(f"# {line}\n")
        table.to_csv(fh, index=False, lineterminator="\n")
    tmp.replace(path)


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
