"""The paper's claims: ``claims.csv``, its schema and its loader.

``passmd/data/reference/claims.csv`` holds one row per checkable statement of the paper; its
columns are documented in ``passmd/data/reference/README.md``. :func:`load_claims` reads it and
checks every row against the schema (ids, configuration values, check kinds and relations,
tolerances with their kind and reason, reference curves, sources), naming each error with its
row. The constants here are the schema's vocabulary, shared by :mod:`passmd.ledger.checks` (the check
kinds and relations) and :mod:`passmd.report.evaluation` (the categories).
"""

from __future__ import annotations

import io
import math
import re
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from passmd.ledger import reference
from passmd.runtime.inputs import read_text

__all__ = [
    "CHECK_KINDS",
    "CLAIMS_PATH",
    "CLAIM_COLUMNS",
    "CLAIM_ID",
    "CONFIGURATION_COLUMNS",
    "RELATIONS",
    "REPRODUCED",
    "STATUSES",
    "TOLERANCE_KINDS",
    "is_number",
    "is_study",
    "family_of",
    "load_claims",
    "required_keys",
    "tolerance_text",
]

#: The claims file, package data: ``passmd/data/reference/claims.csv``.
CLAIMS_PATH = reference.REFERENCE_DIR / "claims.csv"

#: Columns claims.csv must have (passmd/data/reference/README.md documents each).
CLAIM_COLUMNS = (
    "id", "figure", "requires", "quantity", "ours_definition",
    "contacts", "actuator_model", "radius_mm", "preload_N", "friction_coefficient",
    "amplitude_nm", "frequency_Hz", "waveform", "assumed",
    "paper_value", "unit", "reference", "check", "relation", "tolerance", "tolerance_kind",
    "tolerance_reason", "source_section", "source_quote", "study_of", "notes", "reason", "implied_by",
    "compares",
)
#: The columns that state the configuration a claim is about.
CONFIGURATION_COLUMNS = (
    "contacts", "actuator_model", "radius_mm", "preload_N", "friction_coefficient",
    "amplitude_nm", "frequency_Hz", "waveform",
)
_NUMERIC_CONFIGURATION = ("contacts", "radius_mm", "preload_N", "friction_coefficient", "amplitude_nm",
                          "frequency_Hz")
#: The four kinds of check (``check`` column); :mod:`passmd.ledger.checks` implements each.
CHECK_KINDS = ("value", "ordering", "threshold", "trend")
#: The relations each check kind accepts (``relation`` column).
RELATIONS = {
    "value": ("",),
    "ordering": ("<", ">", "approx"),
    "threshold": ("holds_below", "holds_above", "switch_below", "switch_above"),
    "trend": ("increasing", "decreasing"),
}
#: A tolerance is relative (a fraction) or absolute (in the claim's unit).
TOLERANCE_KINDS = ("rel", "abs")
#: Verdict classes, in the order the summary lists them (``passmd.ledger.verdicts.category`` says when
#: each applies): the first two are the reproduced ones; a row whose check cannot fail on any result the model
#: can produce holds *by construction* and is never counted as reproduced.
STATUSES = ("reproduced", "reproduced under the joint reading", "holds by construction", "not reproduced",
            "inconclusive")
#: The categories that count as reproduced.
REPRODUCED = STATUSES[:2]
#: A claim id: a slug of lower-case letters, digits, '.', '_' and '-'.
CLAIM_ID = re.compile(r"^[a-z0-9][a-z0-9._-]*$")

_FIGURE_KEY = re.compile(r"^(fig\d+[a-z_]*|mdr_[a-z_]+|closed_forms)$")
_NUMBER = r"[-+]?(\d+(\.\d*)?|\.\d+)([eE][-+]?\d+)?"
_CONFIG_VALUE = re.compile(rf"^({_NUMBER}(;{_NUMBER})*|{_NUMBER}:{_NUMBER}(:{_NUMBER})?|grid)$")
_WORDS = {"actuator_model": ("rigid", "flexible"), "waveform": ("sawtooth", "optimized")}


def is_number(text: str) -> bool:
    """Whether ``text`` reads as a finite number."""
    try:
        return math.isfinite(float(text))
    except ValueError:
        return False


def _row_errors(row: Mapping[str, str], reference_dir: Path) -> list[str]:
    """Schema errors of one claims.csv row (empty list when the row is valid)."""
    errors = []

    def bad(column, allowed):
        errors.append(f"{column} = {row[column]!r} is not allowed: must be {allowed}")

    if not CLAIM_ID.match(row["id"]):
        bad("id", "a slug of lower-case letters, digits, '.', '_', '-'")
    for column in ("figure", "quantity", "ours_definition", "check", "source_section", "source_quote",
                   "tolerance_reason"):
        if column == "source_quote" and row["study_of"]:
            continue  # a study states no sentence of the paper (passmd.ledger.rules)
        if not row[column].strip():
            errors.append(f"{column} is empty: it is required")
    keys = required_keys(row)
    if not keys or any(not _FIGURE_KEY.match(k) for k in keys):
        bad("requires", "';'-separated result keys such as 'fig5a' or 'closed_forms'")
    for column in CONFIGURATION_COLUMNS:
        value = row[column]
        if not value:
            continue
        if column in _WORDS:
            if any(part not in _WORDS[column] for part in value.split(";")):
                bad(column, "';'-separated words from " + ", ".join(_WORDS[column]))
        elif column in _NUMERIC_CONFIGURATION and not _CONFIG_VALUE.match(value):
            bad(column, "a number, a ';' list, 'start:stop[:step]' or 'grid'")
    unknown = [c for c in row["assumed"].split(";") if c and c not in CONFIGURATION_COLUMNS]
    if unknown:
        bad("assumed", "';'-separated configuration column names")
    kind = row["check"]
    if kind not in CHECK_KINDS:
        bad("check", "one of " + ", ".join(CHECK_KINDS))
        return errors
    if row["relation"] not in RELATIONS[kind]:
        bad("relation", f"one of {RELATIONS[kind]} for check {kind!r}")
    has_tolerance = bool(row["tolerance"])
    if has_tolerance and not (is_number(row["tolerance"]) and float(row["tolerance"]) >= 0):
        bad("tolerance", "a finite number >= 0")
    if has_tolerance and row["tolerance_kind"] not in TOLERANCE_KINDS:
        bad("tolerance_kind", "'rel' or 'abs' when a tolerance is given")
    if not has_tolerance and row["tolerance_kind"]:
        bad("tolerance_kind", "empty when no tolerance is given")
    needs_tolerance = kind in ("value", "threshold", "trend") or row["relation"] == "approx"
    if needs_tolerance and not has_tolerance:
        errors.append(f"tolerance is empty: check {kind!r} {row['relation']!r} needs one")
    if row["paper_value"] and not is_number(row["paper_value"]):
        bad("paper_value", "a finite number")
    if kind == "value":
        if bool(row["paper_value"]) == bool(row["reference"]):
            errors.append("a value claim needs exactly one of paper_value and reference")
        if row["reference"]:
            errors.extend(_reference_errors(row["reference"], reference_dir))
    elif row["reference"]:
        bad("reference", "empty for a non-value claim")
    if kind == "threshold" and not row["paper_value"]:
        errors.append("paper_value is empty: a threshold claim needs the threshold x")
    if kind in ("ordering", "trend") and row["paper_value"]:
        bad("paper_value", f"empty for a {kind} claim")
    compares = [p.strip() for p in row["compares"].split("|")] if row["compares"] else []
    if compares and (kind != "ordering" or len(compares) != 2 or not all(compares)):
        bad("compares", "'<lhs> | <rhs>' (what the two sides are) for an ordering claim, else empty")
    return errors


def required_keys(row: Mapping) -> list[str]:
    """The result keys a claims.csv row reads: its ``requires``, ``;``-separated."""
    return [key for key in str(row["requires"]).split(";") if key]


def family_of(row: Mapping[str, str]) -> str:
    """The claim whose family a claims.csv row belongs to: its ``implied_by``, else its own id (a row
    implied by another is counted with it, once)."""
    return str(row.get("implied_by", "") or "") or str(row["id"])


def is_study(row: Mapping[str, str]) -> bool:
    """Whether a claims.csv row is a study (no sentence of the paper; :mod:`passmd.ledger.rules`)."""
    return bool(row["study_of"])


def _reference_errors(spec: str, reference_dir: Path) -> list[str]:
    filename, _, column = spec.partition(":")
    if not column:
        return [f"reference = {spec!r} is not allowed: must be '<file>:<column>'"]
    path = reference_dir / filename
    if not path.is_file():
        return [f"reference file {path} does not exist"]
    columns = pd.read_csv(io.StringIO(read_text(path, "reference table")), comment="#", nrows=0).columns
    if column not in columns:
        return [f"reference column {column!r} is not in {filename} (columns: {', '.join(columns)})"]
    return []


def load_claims(path=None) -> pd.DataFrame:
    """Read and validate ``claims.csv``.

    Parameters
    ----------
    path : path-like, optional
        Default :data:`CLAIMS_PATH` (``passmd/data/reference/claims.csv``). Reference curves
        named in the ``reference`` column are looked up next to it.

    Returns
    -------
    pandas.DataFrame
        One row per claim, every column as text (empty string where empty), plus
        ``paper_value_num`` and ``tolerance_num`` as floats (NaN where empty).

    Raises
    ------
    ValueError
        Listing every schema error with its row id: missing columns, duplicate ids,
        unknown check kinds or relations, tolerances without a kind or reason,
        value claims without a paper value or reference curve, missing sources.
    """
    path = Path(path) if path is not None else CLAIMS_PATH
    if not path.is_file():
        raise FileNotFoundError(f"claims file {path} does not exist")
    claims = pd.read_csv(io.StringIO(read_text(path, "reference table")), dtype=str, keep_default_na=False)
    missing = [c for c in CLAIM_COLUMNS if c not in claims.columns]
    if missing:
        raise ValueError(f"{path.name} is missing required columns: {', '.join(missing)}")
    claims = claims.apply(lambda column: column.str.strip())
    errors = []
    duplicated = claims["id"][claims["id"].duplicated()].unique()
    errors.extend(f"id {claim!r} appears more than once" for claim in duplicated)
    for _, row in claims.iterrows():
        errors.extend(f"row {row['id']!r}: {message}" for message in _row_errors(row, path.parent))
        target = row["study_of"]
        claims_of_the_paper = set(claims.loc[claims["study_of"] == "", "id"])
        if target and (target not in claims_of_the_paper or row["source_quote"]):
            errors.append(f"row {row['id']!r}: study_of = {target!r} is not allowed: must name a claim of "
                          "this file that is not a study, and a study quotes no sentence (source_quote "
                          "empty)")
        lead = row["implied_by"]
        leads = set(claims.loc[(claims["study_of"] == "") & (claims["implied_by"] == ""), "id"])
        if lead and (target or lead == row["id"] or lead not in leads):
            errors.append(f"row {row['id']!r}: implied_by = {lead!r} is not allowed: must name another claim "
                          "of this file that is neither a study nor implied by a third, and a study is "
                          "implied by none")
    if errors:
        raise ValueError(f"{path.name} has {len(errors)} schema error(s):\n  " + "\n  ".join(errors))
    claims["paper_value_num"] = pd.to_numeric(claims["paper_value"].replace("", np.nan))
    claims["tolerance_num"] = pd.to_numeric(claims["tolerance"].replace("", np.nan))
    return claims.reset_index(drop=True)


def tolerance_text(claim: Mapping) -> str:
    """A claim's tolerance as shown in the ledger: ``"5 %"``, ``"5 nm"`` or ``"—"`` without one."""
    if not claim["tolerance"]:
        return "—"
    if claim["tolerance_kind"] == "rel":
        return f"{claim['tolerance_num'] * 100:g} %"
    return f"{claim['tolerance_num']:g} {claim['unit']}".strip()
