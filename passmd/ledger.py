"""The replication ledger: the paper's claims, checked against our computed results.

Three pieces, kept apart so that figure chapters can add to them without editing this file:

* **claims**: ``passmd/data/reference/claims.csv``, one row per checkable statement of the paper
  (schema in ``passmd/data/reference/README.md``), read and validated by :func:`load_claims`;
* **figures**: the panels registered in :mod:`passmd.experiments` (``fig5a`` … ``fig10c``,
  shared with the book and the CLI) plus the ledger's own ``closed_forms`` table;
  :func:`collect_results` computes every available one, so a chapter never lists them;
* **extractors**: functions ``(results) -> ours`` registered with
  :func:`register_extractor` under a claim id; they turn the result tables into the number,
  pair, curve or series that the claim's check kind needs.

:func:`evaluate` runs the checks and computes every verdict (``reproduced``,
``reproduced within X %``, ``not reproduced: …``, ``expected to differ: …``,
``not evaluated``); :func:`summary` and :func:`styled` present them in the book, and
:func:`regressions` compares them with a committed baseline in the tests.

What ``ours`` must be for each check kind
-----------------------------------------
``value``
    A finite number in the claim's unit; for a claim with a ``reference`` curve,
    ``{'x': array, 'y': array}`` (x inside the curve's range, y in the curve's unit).
``ordering``
    ``{'lhs': a, 'rhs': b}``, numbers or equal-length arrays; the relation (``<``, ``>``,
    ``approx``) must hold at every element.
``threshold``
    ``{'x': array, 'holds': bool array}``: where the claim's condition holds.
``trend``
    ``{'x': array, 'y': array}`` or ``{label: {'x': array, 'y': array}, ...}``.

An extractor raises :class:`NotEvaluable` when the results cannot decide the claim
(e.g. the quick profile's grid has no point where the claim speaks).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from passmd import experiments, reference
from passmd._validation import check_choice
from passmd.parameters import all_assumptions

__all__ = [
    "CHECK_KINDS",
    "ExtractorError",
    "CLAIMS_PATH",
    "CLAIM_COLUMNS",
    "LEDGER_COLUMNS",
    "PROFILES",
    "RELATIONS",
    "STATUSES",
    "NotEvaluable",
    "Outcome",
    "assumptions_table",
    "check_no_regressions",
    "check_ordering",
    "check_threshold",
    "check_trend",
    "check_value",
    "claims_for",
    "collect_results",
    "curve_deviation",
    "evaluate",
    "extractors",
    "result_sources",
    "sources_markdown",
    "load_baseline",
    "load_claims",
    "orphan_extractors",
    "register_extractor",
    "regressions",
    "styled",
    "summary",
    "write_baseline",
]

#: The claims file, package data: ``passmd/data/reference/claims.csv``.
CLAIMS_PATH = reference.REFERENCE_DIR / "claims.csv"

#: Columns claims.csv must have (passmd/data/reference/README.md documents each).
CLAIM_COLUMNS = (
    "id", "figure", "requires", "quantity", "ours_definition",
    "contacts", "actuator_model", "radius_mm", "preload_N", "friction_coefficient",
    "amplitude_nm", "frequency_Hz", "waveform", "assumed",
    "paper_value", "unit", "reference", "check", "relation", "tolerance", "tolerance_kind",
    "tolerance_reason", "source_section", "source_quote", "notes",
    "expected_to_differ", "expected_difference_reason",
)
CONFIGURATION_COLUMNS = (
    "contacts", "actuator_model", "radius_mm", "preload_N", "friction_coefficient",
    "amplitude_nm", "frequency_Hz", "waveform",
)
_NUMERIC_CONFIGURATION = ("contacts", "radius_mm", "preload_N", "friction_coefficient", "amplitude_nm",
                          "frequency_Hz")
CHECK_KINDS = ("value", "ordering", "threshold", "trend")
RELATIONS = {
    "value": ("",),
    "ordering": ("<", ">", "approx"),
    "threshold": ("holds_below", "holds_above", "switch_below", "switch_above"),
    "trend": ("increasing", "decreasing"),
}
TOLERANCE_KINDS = ("rel", "abs")
#: Verdict classes, in the order the summary lists them.
STATUSES = ("reproduced", "not reproduced", "expected to differ", "not evaluated")
#: Columns of :func:`evaluate`'s result.
LEDGER_COLUMNS = ("claim", "figure", "quantity", "paper", "ours", "unit", "abs_deviation", "rel_deviation",
                  "tolerance", "verdict", "note", "status", "check")
#: Build profiles passed to figure functions (those of :mod:`passmd.experiments`).
PROFILES = experiments.PROFILES

_ID = re.compile(r"^[a-z0-9][a-z0-9._-]*$")
_FIGURE_KEY = re.compile(r"^(fig\d+[a-z]?|closed_forms)$")
_NUMBER = r"[-+]?(\d+(\.\d*)?|\.\d+)([eE][-+]?\d+)?"
_CONFIG_VALUE = re.compile(rf"^({_NUMBER}(;{_NUMBER})*|{_NUMBER}:{_NUMBER}(:{_NUMBER})?|grid)$")
_WORDS = {"actuator_model": ("rigid", "flexible"), "waveform": ("sawtooth", "optimized")}


class NotEvaluable(Exception):
    """Raised by an extractor or a check when the results cannot decide a claim."""


class ExtractorError(ValueError):
    """An extractor failed, or returned something its claim's check cannot use."""


# ======================================================================================
# Claims
# ======================================================================================


def _is_number(text: str) -> bool:
    try:
        return math.isfinite(float(text))
    except ValueError:
        return False


def _row_errors(row: Mapping[str, str], reference_dir: Path) -> list[str]:
    """Schema errors of one claims.csv row (empty list when the row is valid)."""
    errors = []

    def bad(column, allowed):
        errors.append(f"{column} = {row[column]!r} is not allowed: must be {allowed}")

    if not _ID.match(row["id"]):
        bad("id", "a slug of lower-case letters, digits, '.', '_', '-'")
    for column in ("figure", "quantity", "ours_definition", "check", "source_section", "source_quote",
                   "tolerance_reason"):
        if not row[column].strip():
            errors.append(f"{column} is empty: it is required")
    keys = [k for k in row["requires"].split(";") if k]
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
    if has_tolerance and not (_is_number(row["tolerance"]) and float(row["tolerance"]) >= 0):
        bad("tolerance", "a finite number >= 0")
    if has_tolerance and row["tolerance_kind"] not in TOLERANCE_KINDS:
        bad("tolerance_kind", "'rel' or 'abs' when a tolerance is given")
    if not has_tolerance and row["tolerance_kind"]:
        bad("tolerance_kind", "empty when no tolerance is given")
    needs_tolerance = kind in ("value", "threshold", "trend") or row["relation"] == "approx"
    if needs_tolerance and not has_tolerance:
        errors.append(f"tolerance is empty: check {kind!r} {row['relation']!r} needs one")
    if row["paper_value"] and not _is_number(row["paper_value"]):
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
    if row["expected_to_differ"] not in ("", "yes"):
        bad("expected_to_differ", "'yes' or empty")
    if row["expected_to_differ"] == "yes" and not row["expected_difference_reason"].strip():
        errors.append("expected_difference_reason is empty: required when expected_to_differ is 'yes'")
    return errors


def _reference_errors(spec: str, reference_dir: Path) -> list[str]:
    filename, _, column = spec.partition(":")
    if not column:
        return [f"reference = {spec!r} is not allowed: must be '<file>:<column>'"]
    path = reference_dir / filename
    if not path.is_file():
        return [f"reference file {path} does not exist"]
    columns = pd.read_csv(path, comment="#", nrows=0).columns
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
    claims = pd.read_csv(path, dtype=str, keep_default_na=False, encoding="utf-8")
    missing = [c for c in CLAIM_COLUMNS if c not in claims.columns]
    if missing:
        raise ValueError(f"{path.name} is missing required columns: {', '.join(missing)}")
    claims = claims.apply(lambda column: column.str.strip())
    errors = []
    duplicated = claims["id"][claims["id"].duplicated()].unique()
    errors.extend(f"id {claim!r} appears more than once" for claim in duplicated)
    for _, row in claims.iterrows():
        errors.extend(f"row {row['id']!r}: {message}" for message in _row_errors(row, path.parent))
    if errors:
        raise ValueError(f"{path.name} has {len(errors)} schema error(s):\n  " + "\n  ".join(errors))
    claims["paper_value_num"] = pd.to_numeric(claims["paper_value"].replace("", np.nan))
    claims["tolerance_num"] = pd.to_numeric(claims["tolerance"].replace("", np.nan))
    return claims.reset_index(drop=True)


# ======================================================================================
# Registries
# ======================================================================================

_EXTRACTORS: dict[str, Callable] = {}


def register_extractor(claim_id: str) -> Callable[[Callable], Callable]:
    """Decorator: register ``func(results: dict[str, DataFrame]) -> ours`` for a claim.

    ``ours`` must have the form the claim's check kind expects (module docstring) and
    be in the claim's ``unit``. Raise :class:`NotEvaluable` when the results cannot
    decide the claim. Extractors live next to their figure in the topic modules of
    :mod:`passmd.experiments`, which are loaded before every evaluation.
    """
    if not isinstance(claim_id, str) or not _ID.match(claim_id):
        raise ValueError(f"claim_id = {claim_id!r} is not allowed: must be a claims.csv id slug")

    def deco(func: Callable) -> Callable:
        previous = _EXTRACTORS.get(claim_id)
        same = previous is not None and (previous.__module__, previous.__qualname__) == (
            func.__module__, func.__qualname__)
        if previous is not None and not same:  # re-importing the same module is fine
            raise ValueError(f"extractor for claim {claim_id!r} is already registered by "
                             f"{previous.__module__}.{previous.__qualname__}")
        _EXTRACTORS[claim_id] = func
        return func

    return deco


def extractors() -> dict[str, Callable]:
    """The registered extractors ``{claim id: function}``, topic modules loaded first."""
    experiments.figure_names()  # imports the topic modules, which register their extractors
    return dict(_EXTRACTORS)


def result_sources() -> dict[str, Callable[[str], pd.DataFrame]]:
    """Every available result table: ``{key: compute(profile) -> DataFrame}``.

    The figure panels registered in :mod:`passmd.experiments` plus ``closed_forms``
    (the closed-form tables some claims are checked against, computed here).
    """
    sources = {name: experiments.figure_spec(name).compute for name in experiments.figure_names()}
    sources["closed_forms"] = closed_form_results
    return sources


def collect_results(profile: str = "quick", figures=None) -> dict[str, pd.DataFrame]:
    """Compute every available result table: the ledger's single entry point.

    Parameters
    ----------
    profile : str
        ``"quick"`` (CI) or ``"paper"`` (the paper's grids); passed to each figure function.
    figures : iterable of str, optional
        Only these keys (each must be available); default all of :func:`result_sources`.

    Returns
    -------
    dict
        ``{key: DataFrame}``. Figures not registered yet are simply absent; their claims
        are then *not evaluated*.
    """
    check_choice("profile", profile, PROFILES)
    available = result_sources()
    keys = list(available) if figures is None else list(figures)
    unknown = [k for k in keys if k not in available]
    if unknown:
        raise ValueError(f"figures = {unknown!r} are not available: must be among {', '.join(available)}")
    results = {}
    for key in keys:
        table = available[key](profile)
        if not isinstance(table, pd.DataFrame):
            raise TypeError(f"figure function for {key!r} returned {type(table).__name__}, not a DataFrame")
        results[key] = table
    return results


# ======================================================================================
# Checks
# ======================================================================================


@dataclass(frozen=True)
class Outcome:
    """Result of one check: pass/fail, what to display, deviations and an explanation."""

    passed: bool
    ours: object  # number or short text shown in the ledger's "ours" column
    abs_deviation: float = math.nan
    rel_deviation: float = math.nan
    detail: str = ""  # why it failed (or what was found)


def _fmt(x) -> str:
    return "—" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.4g}"


def _numbers(name: str, values, *, boolean: bool = False) -> np.ndarray:
    array = np.atleast_1d(np.asarray(values, dtype=bool if boolean else float))
    if array.ndim != 1 or array.size == 0:
        raise ValueError(f"{name} must be a non-empty 1-d array, got shape {array.shape}")
    if not boolean and not np.all(np.isfinite(array)):
        raise ValueError(f"{name} contains non-finite values: {array}")
    return array


def _mapping(name: str, ours, keys) -> Mapping:
    if not isinstance(ours, Mapping) or any(k not in ours for k in keys):
        raise ValueError(f"{name} must be a dict with keys {keys}, got {ours!r}")
    return ours


def _allowance(tolerance: float, kind: str, scale) -> np.ndarray:
    if tolerance is None or (isinstance(tolerance, float) and math.isnan(tolerance)):
        return np.zeros_like(np.asarray(scale, dtype=float))
    return tolerance * np.abs(scale) if kind == "rel" else np.full_like(np.asarray(scale, float), tolerance)


def check_value(ours, paper_value=None, tolerance=0.0, tolerance_kind="rel", curve=None) -> Outcome:
    """``value`` check: a number against ``paper_value``, or a curve ``{'x', 'y'}`` against ``curve``.

    Parameters
    ----------
    ours : float or dict
        A number, or ``{'x': array, 'y': array}`` when ``curve`` is given.
    paper_value : float, optional
        The paper's number (scalar claims).
    tolerance, tolerance_kind : float, str
        Largest accepted deviation: relative (``'rel'``, a fraction) or absolute (``'abs'``).
    curve : tuple of arrays, optional
        ``(x, y)`` of the reference curve; ``ours['x']`` must lie within ``x``'s range.
    """
    check_choice("tolerance_kind", tolerance_kind, TOLERANCE_KINDS)
    if curve is None:
        scalar = not isinstance(ours, (Mapping, str)) and np.ndim(ours) == 0
        value = float(_numbers("ours", ours)[0]) if scalar else None
        if value is None:
            raise ValueError(f"ours must be a number for a value claim, got {ours!r}")
        expected, got, shown = np.array([paper_value], float), np.array([value]), value
    else:
        data = _mapping("ours", ours, ("x", "y"))
        x, got = _numbers("ours['x']", data["x"]), _numbers("ours['y']", data["y"])
        ref_x, ref_y = (np.asarray(a, float) for a in curve)
        if x.shape != got.shape:
            raise ValueError(f"ours['x'] and ours['y'] differ in length: {x.size} vs {got.size}")
        outside = (x < ref_x.min() - 1e-12) | (x > ref_x.max() + 1e-12)
        if outside.any():
            raise ValueError(f"ours['x'] = {x[outside]} lies outside the reference curve's range "
                             f"[{ref_x.min():g}, {ref_x.max():g}]")
        order = np.argsort(ref_x)
        expected = np.interp(x, ref_x[order], ref_y[order])
        shown = f"{got.size} points, {_fmt(got.min())}–{_fmt(got.max())}"
    deviation = np.abs(got - expected)
    with np.errstate(divide="ignore", invalid="ignore"):
        relative = np.where(expected != 0, deviation / np.abs(expected), np.nan)
    worst = int(np.argmax(deviation / np.maximum(_allowance(tolerance, tolerance_kind, expected), 1e-300)))
    passed = bool(np.all(deviation <= _allowance(tolerance, tolerance_kind, expected)))
    abs_dev = float(deviation.max())
    rel_dev = float(np.nanmax(relative)) if np.any(np.isfinite(relative)) else math.nan
    where = f" at x = {_fmt(float(x[worst]))}" if curve is not None else ""
    detail = f"deviation {_fmt(float(deviation[worst]))}{where}"
    if not passed:
        limit = f"{tolerance * 100:g} %" if tolerance_kind == "rel" else _fmt(tolerance)
        rel_worst = relative[worst]
        shown_dev = f"{rel_worst * 100:.3g} %" if tolerance_kind == "rel" else _fmt(float(deviation[worst]))
        detail = f"deviation {shown_dev}{where} exceeds the tolerance {limit}"
    return Outcome(passed, shown, abs_dev, rel_dev, detail)


_SYMBOL = {"<": "<", ">": ">", "approx": "≈"}


def check_ordering(ours, relation, tolerance=None, tolerance_kind="rel") -> Outcome:
    """``ordering`` check: ``lhs < rhs``, ``lhs > rhs`` or ``lhs ≈ rhs`` at every element.

    The margin m is 0 without a tolerance, ``tolerance·|rhs|`` (rel) or ``tolerance`` (abs):
    ``<`` needs lhs < rhs − m, ``>`` needs lhs > rhs + m, ``approx`` needs |lhs − rhs| ≤ m.
    """
    check_choice("relation", relation, RELATIONS["ordering"])
    data = _mapping("ours", ours, ("lhs", "rhs"))
    lhs, rhs = _numbers("ours['lhs']", data["lhs"]), _numbers("ours['rhs']", data["rhs"])
    if lhs.shape != rhs.shape:
        raise ValueError(f"ours['lhs'] and ours['rhs'] differ in length: {lhs.size} vs {rhs.size}")
    margin = _allowance(tolerance, tolerance_kind, rhs)
    difference = lhs - rhs
    if relation == "<":
        ok = difference < -margin
    elif relation == ">":
        ok = difference > margin
    else:
        ok = np.abs(difference) <= margin
    symbol = _SYMBOL[relation]
    shown = (f"{_fmt(float(lhs[0]))} vs {_fmt(float(rhs[0]))}" if lhs.size == 1
             else f"{int(ok.sum())} of {ok.size} hold")
    with np.errstate(divide="ignore", invalid="ignore"):
        relative = np.abs(difference) / np.abs(rhs)
    abs_dev = float(np.abs(difference).max()) if relation == "approx" else math.nan
    rel_dev = float(np.nanmax(relative)) if relation == "approx" and np.isfinite(relative).any() else math.nan
    if ok.all():
        detail = f"lhs {symbol} rhs" + ("" if lhs.size == 1 else f" at all {ok.size} points")
    else:
        bad = int(np.flatnonzero(~ok)[0])
        detail = (f"lhs {symbol} rhs fails at {int((~ok).sum())} of {ok.size} point(s), e.g. "
                  f"{_fmt(float(lhs[bad]))} vs {_fmt(float(rhs[bad]))}")
    return Outcome(bool(ok.all()), shown, abs_dev, rel_dev, detail)


def check_threshold(ours, relation, threshold, tolerance=0.0, tolerance_kind="abs") -> Outcome:
    """``threshold`` check: where a condition holds relative to ``threshold`` (x_t).

    Points inside the band x_t ± m (m = tolerance, or tolerance·|x_t| for rel) are not
    judged. ``holds_below``: holds at every point below the band (at least one);
    ``switch_below``: in addition fails at every point above it (at least one);
    ``*_above``: mirrored. Ours is the observed switch: the first x where the condition
    fails (``*_below``) or the last x where it fails (``*_above``).
    """
    check_choice("relation", relation, RELATIONS["threshold"])
    data = _mapping("ours", ours, ("x", "holds"))
    x, holds = _numbers("ours['x']", data["x"]), _numbers("ours['holds']", data["holds"], boolean=True)
    if x.shape != holds.shape:
        raise ValueError(f"ours['x'] and ours['holds'] differ in length: {x.size} vs {holds.size}")
    order = np.argsort(x)
    x, holds = x[order], holds[order]
    band = float(_allowance(tolerance, tolerance_kind, np.array([threshold]))[0])
    below, above = x < threshold - band, x > threshold + band
    side, other = (below, above) if relation.endswith("below") else (above, below)
    side_name = "below" if relation.endswith("below") else "above"
    if not side.any():
        edge = threshold - band if side is below else threshold + band
        raise NotEvaluable(f"no point {side_name} {_fmt(edge)}")
    switch = relation.startswith("switch")
    if switch and not other.any():
        raise NotEvaluable("no point on the far side of the threshold band")
    failures = x[~holds]
    if relation.endswith("below"):
        observed = float(failures.min()) if failures.size else math.nan
    else:
        observed = float(failures.max()) if failures.size else math.nan
    problems = []
    if not holds[side].all():
        problems.append(f"fails {side_name} the threshold at x = {_fmt(float(x[side & ~holds][0]))}")
    if switch and holds[other].any():
        problems.append(f"still holds beyond it at x = {_fmt(float(x[other & holds][0]))}")
    abs_dev = abs(observed - threshold) if math.isfinite(observed) else math.nan
    shown = observed if math.isfinite(observed) else f"holds over {_fmt(x[0])}–{_fmt(x[-1])}"
    detail = "; ".join(problems) if problems else (
        f"switch observed at x = {_fmt(observed)}" if math.isfinite(observed) else "holds at every point")
    return Outcome(not problems, shown, abs_dev, abs_dev / abs(threshold) if threshold else math.nan, detail)


def check_trend(ours, relation, tolerance=0.0, tolerance_kind="rel") -> Outcome:
    """``trend`` check: each series increases (or decreases) with x.

    Sorted by x, a series may step against the trend by at most the allowance
    (rel: tolerance × the series' range; abs: tolerance), and its last value must lie
    beyond its first in the trend's direction by more than the allowance.
    """
    check_choice("relation", relation, RELATIONS["trend"])
    if isinstance(ours, Mapping) and "x" in ours and "y" in ours:
        series = {"": ours}
    elif isinstance(ours, Mapping) and ours and all(isinstance(s, Mapping) for s in ours.values()):
        series = dict(ours)
    else:
        raise ValueError(f"ours must be {{'x', 'y'}} or {{label: {{'x', 'y'}}}}, got {ours!r}")
    sign = 1.0 if relation == "increasing" else -1.0
    worst, worst_rel, problems, points = 0.0, 0.0, [], 0
    for label, data in series.items():
        x = _numbers(f"ours[{label!r}]['x']", _mapping("series", data, ("x", "y"))["x"])
        y = _numbers(f"ours[{label!r}]['y']", data["y"])
        if x.shape != y.shape:
            raise ValueError(f"series {label!r}: x and y differ in length: {x.size} vs {y.size}")
        if x.size < 2:
            raise NotEvaluable(f"series {label!r} has fewer than two points")
        y = y[np.argsort(x)]
        spread = float(np.ptp(y))
        allowance = tolerance * spread if tolerance_kind == "rel" else tolerance
        counter = float(max(0.0, (-sign * np.diff(y)).max()))
        points += x.size
        worst = max(worst, counter)
        worst_rel = max(worst_rel, counter / spread if spread > 0 else 0.0)
        name = f"series {label}: " if label else ""
        if counter > allowance:
            problems.append(f"{name}steps against the trend by {_fmt(counter)} > allowance {_fmt(allowance)}")
        if sign * (y[-1] - y[0]) <= allowance:
            problems.append(f"{name}last value {_fmt(float(y[-1]))} is not {relation.replace('ing', 'ed')} "
                            f"from first {_fmt(float(y[0]))}")
    shown = f"{relation} over {points} points" if not problems else f"largest counter-step {_fmt(worst)}"
    detail = "; ".join(problems) if problems else f"largest counter-step {_fmt(worst)}"
    return Outcome(not problems, shown, worst, worst_rel, detail)


def curve_deviation(x, y, curve: str, column: str) -> float:
    """Largest relative deviation in % of ``y`` from a reference curve at ``x``.

    Helper for extractors of ordering claims such as ``fig6a-rigid-ac-not-eq10``.
    ``curve`` is a table of :data:`passmd.reference.CURVES` and ``column`` one of its columns.
    """
    table = reference.load_reference_curve(curve)
    outcome = check_value({"x": x, "y": y}, tolerance=0.0, curve=(table.iloc[:, 0], table[column]))
    return 100.0 * outcome.rel_deviation


# ======================================================================================
# Evaluation
# ======================================================================================


def _run_check(claim: Mapping, ours) -> Outcome:
    kind, relation = claim["check"], claim["relation"]
    tolerance, tolerance_kind = claim["tolerance_num"], claim["tolerance_kind"] or "rel"
    if kind == "value":
        curve = None
        if claim["reference"]:
            filename, _, column = claim["reference"].partition(":")
            table = reference.load_reference_curve(filename)
            curve = (table.iloc[:, 0].to_numpy(), table[column].to_numpy())
        return check_value(ours, claim["paper_value_num"], tolerance, tolerance_kind, curve)
    if kind == "ordering":
        return check_ordering(ours, relation, tolerance, tolerance_kind)
    if kind == "threshold":
        return check_threshold(ours, relation, claim["paper_value_num"], tolerance, tolerance_kind)
    return check_trend(ours, relation, tolerance, tolerance_kind)


def _paper_text(claim: Mapping) -> str:
    kind, relation = claim["check"], claim["relation"]
    if kind == "value":
        if claim["paper_value"]:
            return claim["paper_value"]
        filename, _, column = claim["reference"].partition(":")
        return f"curve {column} ({filename})"
    if kind == "ordering":
        return f"lhs {_SYMBOL[relation]} rhs"
    if kind == "threshold":
        return f"{relation.replace('_', ' ')} {claim['paper_value']}"
    return relation


def _tolerance_text(claim: Mapping) -> str:
    if not claim["tolerance"]:
        return "—"
    if claim["tolerance_kind"] == "rel":
        return f"{claim['tolerance_num'] * 100:g} %"
    return f"{claim['tolerance_num']:g} {claim['unit']}".strip()


def _passed_verdict(claim: Mapping, outcome: Outcome) -> str:
    quantitative = claim["check"] == "value" or claim["relation"] == "approx"
    if quantitative and math.isfinite(outcome.rel_deviation):
        percent = max(1, math.ceil(round(outcome.rel_deviation * 100, 9)))
        return f"reproduced within {percent} %"
    return "reproduced"


def evaluate(
    claims: pd.DataFrame, results: Mapping[str, pd.DataFrame], *, strict: bool = True
) -> pd.DataFrame:
    """Evaluate every claim against the result tables.

    Parameters
    ----------
    claims : pandas.DataFrame
        From :func:`load_claims`.
    results : dict
        ``{figure key: DataFrame}``, e.g. from :func:`collect_results`.
    strict : bool
        If True (default), raise ``LookupError`` when a claim's results are present but no
        extractor is registered for it. If False, such claims are *not evaluated* with that
        note. (Extractors registered for ids that are not in claims.csv are reported by
        :func:`orphan_extractors`.)

    Returns
    -------
    pandas.DataFrame
        Columns :data:`LEDGER_COLUMNS`: ``paper`` and ``ours`` as shown (number or text),
        ``abs_deviation`` (in ``unit``) and ``rel_deviation`` (fraction) where defined,
        ``verdict`` (computed text), ``status`` (one of :data:`STATUSES`).
    """
    registered = extractors()
    problems = []
    rows = []
    for _, claim in claims.iterrows():
        missing = [k for k in claim["requires"].split(";") if k and k not in results]
        outcome, status, note = None, None, ""
        if missing:
            status, note = "not evaluated", "needs results: " + ", ".join(missing)
        elif claim["id"] not in registered:
            if strict:
                problems.append(f"claim {claim['id']!r} has its results but no registered extractor")
            status, note = "not evaluated", "no extractor registered"
        else:
            try:
                ours = registered[claim["id"]](results)
                outcome = _run_check(claim, ours)
            except NotEvaluable as reason:
                status, note = "not evaluated", str(reason)
            except Exception as err:
                raise ExtractorError(f"claim {claim['id']!r} ({claim['check']} check): {err!r}") from err
        flagged = claim["expected_to_differ"] == "yes"
        if outcome is None:
            verdict = "not evaluated"
        elif outcome.passed:
            status, verdict, note = "reproduced", _passed_verdict(claim, outcome), outcome.detail
            if flagged:
                note += "; marked expected to differ but reproduced: remove the mark"
        elif flagged:
            status = "expected to differ"
            verdict = f"expected to differ: {claim['expected_difference_reason']}"
            note = outcome.detail
        else:
            status, verdict, note = "not reproduced", f"not reproduced: {outcome.detail}", outcome.detail
        rows.append({
            "claim": claim["id"], "figure": claim["figure"], "quantity": claim["quantity"],
            "paper": _paper_text(claim), "ours": "—" if outcome is None else outcome.ours,
            "unit": claim["unit"],
            "abs_deviation": math.nan if outcome is None else outcome.abs_deviation,
            "rel_deviation": math.nan if outcome is None else outcome.rel_deviation,
            "tolerance": _tolerance_text(claim), "verdict": verdict, "note": note, "status": status,
            "check": claim["check"],
        })
    if problems:
        raise LookupError("ledger evaluation is incomplete:\n  " + "\n  ".join(problems))
    return pd.DataFrame(rows, columns=list(LEDGER_COLUMNS))


def claims_for(claims: pd.DataFrame, figures) -> pd.DataFrame:
    """The claims that need only the given result keys, e.g. a chapter's own ledger rows.

    ``claims_for(load_claims(), ["fig5a", "fig5b"])`` selects the claims whose ``requires``
    are all among ``fig5a`` and ``fig5b``.
    """
    keys = {figures} if isinstance(figures, str) else set(figures)
    needed = claims["requires"].str.split(";").map(lambda parts: {p for p in parts if p})
    return claims[needed.map(lambda parts: parts <= keys)].reset_index(drop=True)


def orphan_extractors(claims: pd.DataFrame | None = None) -> list[str]:
    """Ids with a registered extractor but no row in ``claims`` (default: claims.csv).

    A non-empty list means a claim was renamed or an extractor misspelt its id.
    """
    ids = set((load_claims() if claims is None else claims)["id"])
    return sorted(set(extractors()) - ids)


def summary(evaluated: pd.DataFrame) -> str:
    """One line such as ``"11 of 14 claims reproduced; 3 not evaluated"``."""
    counts = evaluated["status"].value_counts()
    text = f"{int(counts.get('reproduced', 0))} of {len(evaluated)} claims reproduced"
    others = [f"{int(counts[s])} {s}" for s in STATUSES[1:] if counts.get(s, 0)]
    return text + ("; " + ", ".join(others) if others else "")


#: Background colours of the verdict classes in :func:`styled`.
STATUS_COLOURS = {
    "reproduced": "#d4edda",
    "not reproduced": "#f8d7da",
    "expected to differ": "#fff3cd",
    "not evaluated": "#e9ecef",
}


def styled(evaluated: pd.DataFrame):
    """A pandas ``Styler`` of the ledger for the book, claim and verdict coloured by class.

    The table carries the HTML class ``passmd-ledger`` (the rendered-book check looks
    for it); deviations are shown in the claim's unit and in %. The verdict comes third, so
    it is visible on a narrow page.
    """
    order = ["claim", "figure", "verdict", "paper", "ours", "unit", "abs_deviation", "rel_deviation",
             "tolerance", "quantity", "note"]  # the verdict early: visible without scrolling
    shown = evaluated[order].copy()
    shown["rel_deviation"] = shown["rel_deviation"] * 100.0
    shown = shown.rename(columns={"rel_deviation": "rel_deviation_%"})
    statuses = evaluated["status"].to_numpy()

    def colour(column):
        return [f"background-color: {STATUS_COLOURS[s]}" for s in statuses]

    def number(value):
        if isinstance(value, (int, float, np.floating)) and not isinstance(value, bool):
            return "—" if not math.isfinite(value) else f"{value:.4g}"
        return str(value)

    return (
        shown.style.hide(axis="index")
        .format(number)
        .apply(colour, subset=["claim", "verdict"])
        .set_table_attributes('class="passmd-ledger"')
        .set_table_styles([
            {"selector": "td, th", "props": "font-size: 0.8em; vertical-align: top;"},
            # the long text columns: wide enough to keep rows short
            *({"selector": f"td.col{order.index(column)}", "props": "min-width: 16em;"}
              for column in ("quantity", "note")),
        ])
    )


_CONFIG_LABELS = {
    "contacts": ("contacts", ""), "actuator_model": ("actuators", ""), "radius_mm": ("R", "mm"),
    "preload_N": ("F_p", "N"), "friction_coefficient": ("μ", ""), "amplitude_nm": ("A", "nm"),
    "frequency_Hz": ("f", "Hz"), "waveform": ("waveform", ""),
}


def _md_escape(text: str) -> str:
    """Escape the characters MyST would read as markup (u*_x,max must not turn italic)."""
    return re.sub(r"([\\`*_\[\]<>$|#])", r"\\\1", text)


def _config_text(claim: Mapping) -> str:
    assumed = {c for c in claim["assumed"].split(";") if c}
    parts = []
    for column, (label, unit) in _CONFIG_LABELS.items():
        value = claim[column]
        if not value:
            continue
        if ":" in value:
            start, stop, *step = value.split(":")
            value = f"{start}–{stop}" + (f" in steps of {step[0]}" if step else "")
        value = value.replace(";", ", ")
        if value == "grid":
            shown = f"{label} on the preload grid"
        else:
            shown = f"{label} = {value}" + (f" {unit}" if unit else "")
        parts.append(shown + (" (assumed)" if column in assumed else ""))
    return "; ".join(parts) if parts else "—"


def sources_markdown(claims: pd.DataFrame) -> str:
    """Each claim's source as MyST markdown: quotation, configuration, tolerance reason, notes.

    Configuration values the paper does not state are marked *(assumed)*.
    """
    items = []
    for _, claim in claims.iterrows():
        section = claim["source_section"]
        section = f"Section {section}" if section[:1].isdigit() else section
        check = claim["check"] + (f" ({claim['relation']})" if claim["relation"] else "")
        if claim["tolerance"]:
            check += f", tolerance {_tolerance_text(claim)}"
        lines = [
            f"* **{_md_escape(claim['id'])}** (Fig. {_md_escape(claim['figure'])}, {_md_escape(section)}): "
            f"“{_md_escape(claim['source_quote'])}”",
            f"  *Configuration:* {_md_escape(_config_text(claim))}.",
            f"  *Ours:* {_md_escape(claim['ours_definition'])}.",
            f"  *Check:* {_md_escape(check)}. {_md_escape(claim['tolerance_reason'])}",
        ]
        if claim["notes"]:
            lines.append(f"  *Notes:* {_md_escape(claim['notes'])}")
        if claim["expected_to_differ"] == "yes":
            lines.append(f"  *Expected to differ:* {_md_escape(claim['expected_difference_reason'])}")
        items.append("\n".join(line + "  " if i < len(lines) - 1 else line for i, line in enumerate(lines)))
    return "\n".join(items) + "\n"


def assumptions_table() -> pd.DataFrame:
    """Every registered assumption (``passmd.parameters.ASSUMPTIONS``) as a table.

    Imports every module of passmd first, so every assumption registered anywhere is included.
    """
    return pd.DataFrame(
        [{"key": a.key, "symbol": a.symbol, "value": a.value, "unit": a.unit, "rationale": a.rationale,
          "effect on the results": a.sensitivity} for a in all_assumptions().values()]
    )


# ======================================================================================
# Baseline (regression tests)
# ======================================================================================


def load_baseline(path) -> dict[str, str]:
    """``{claim id: status}`` from a baseline CSV written by :func:`write_baseline`."""
    table = pd.read_csv(path, dtype=str, keep_default_na=False)
    return dict(zip(table["claim"], table["status"], strict=True))


def write_baseline(evaluated: pd.DataFrame, path) -> None:
    """Write the claims' statuses as a baseline CSV (``claim,status``), atomically."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp")
    evaluated[["claim", "status"]].to_csv(tmp, index=False, lineterminator="\n")
    tmp.replace(path)


def regressions(evaluated: pd.DataFrame, baseline: Mapping[str, str]) -> pd.DataFrame:
    """Claims reproduced in ``baseline`` that no longer are (or that disappeared).

    Returns the regressed rows of ``evaluated`` (claims missing from it appear with
    status ``"missing"``), with a column ``baseline``.
    """
    current = evaluated.set_index("claim")
    rows = []
    for claim, before in baseline.items():
        if before != "reproduced":
            continue
        if claim not in current.index:
            rows.append({"claim": claim, "status": "missing", "verdict": "claim no longer in the ledger",
                         "baseline": before})
        elif current.at[claim, "status"] != "reproduced":
            rows.append({"claim": claim, "status": current.at[claim, "status"],
                         "verdict": current.at[claim, "verdict"], "baseline": before})
    return pd.DataFrame(rows, columns=["claim", "status", "verdict", "baseline"])


def check_no_regressions(evaluated: pd.DataFrame, baseline: Mapping[str, str]) -> None:
    """Raise ``AssertionError`` listing every claim that regressed from ``reproduced``."""
    regressed = regressions(evaluated, baseline)
    if len(regressed):
        lines = [f"{r.claim}: {r.verdict}" for r in regressed.itertuples()]
        raise AssertionError(f"{len(lines)} claim(s) regressed from 'reproduced':\n  " + "\n  ".join(lines))


# ======================================================================================
# Results computed here: the closed forms (claims checked without a simulation)
# ======================================================================================


def closed_form_results(profile: str = "quick") -> pd.DataFrame:
    """Closed-form contact stiffness 2aG* per side for R = 1 mm and 0.25 mm (profile-independent)."""
    check_choice("profile", profile, PROFILES)
    return reference.tangential_stiffness_table()


@register_extractor("fig10b-r1-stiffer-contact")
def _stiffer_contact(results: Mapping[str, pd.DataFrame]) -> dict:
    table = results["closed_forms"].sort_values(["preload_N", "side"])
    stiffness = {r: g["tangential_stiffness_N_per_m"].to_numpy() for r, g in table.groupby("radius_mm")}
    return {"lhs": stiffness[1.0], "rhs": stiffness[0.25]}
