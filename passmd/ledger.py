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

:func:`evaluate` runs the checks over the readings of the assumption space
(:mod:`passmd.readings`) and computes every claim's category: ``reproduced``,
``reproduced under another reading``, ``not reproduced`` or ``inconclusive``, with its
evidence; no category is typed in. :func:`summary`, :func:`headline_markdown`,
:func:`styled`, :func:`details_markdown` and :func:`assumption_map` present them in the book,
and :func:`check_categories` compares them with a committed baseline in the tests.

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

An extractor raises :class:`NotEvaluable` (alias :data:`Inconclusive`) when the results
cannot decide the claim (e.g. the quick profile's grid has no point where the claim speaks,
an extremum lies at the grid's edge), and :class:`ClaimFails` when they decide it against the
paper outright (a total failure is *not reproduced*).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from passmd import experiments, readings, reference
from passmd._validation import check_choice
from passmd.config import PROFILES

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
    "category_changes",
    "check_categories",
    "ClaimFails",
    "Inconclusive",
    "assumption_map",
    "assumption_map_styled",
    "category_anchor",
    "claim_anchor",
    "depends_on",
    "details_markdown",
    "headline_markdown",
    "register_evidence",
    "records",
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
    "claim_readings",
    "load_baseline",
    "load_baseline_readings",
    "load_claims",
    "orphan_extractors",
    "register_extractor",
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
    "tolerance_reason", "source_section", "source_quote", "notes", "reason",
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
STATUSES = ("reproduced", "reproduced under another reading", "not reproduced", "inconclusive")
#: Columns of :func:`evaluate`'s result.
LEDGER_COLUMNS = ("claim", "figure", "quantity", "paper", "ours", "unit", "abs_deviation", "rel_deviation",
                  "tolerance", "status", "verdict", "evidence", "reason", "basis", "check", "depends_on",
                  "readings", "holds_at", "fraction_holds", "best_reading", "note")

_ID = re.compile(r"^[a-z0-9][a-z0-9._-]*$")
_FIGURE_KEY = re.compile(r"^(fig\d+[a-z_]*|closed_forms)$")
_NUMBER = r"[-+]?(\d+(\.\d*)?|\.\d+)([eE][-+]?\d+)?"
_CONFIG_VALUE = re.compile(rf"^({_NUMBER}(;{_NUMBER})*|{_NUMBER}:{_NUMBER}(:{_NUMBER})?|grid)$")
_WORDS = {"actuator_model": ("rigid", "flexible"), "waveform": ("sawtooth", "optimized")}


class NotEvaluable(Exception):
    """Raised by an extractor or a check when the results cannot decide a claim.

    The claim is then *inconclusive* at that reading (an extremum at the edge of the grid,
    non-finite values, a run that did not converge, a reading the tables hold no run for);
    the message says what is missing.
    """


#: The name the verdict taxonomy uses for :class:`NotEvaluable`.
Inconclusive = NotEvaluable


class ClaimFails(Exception):
    """Raised by an extractor when the results decide the claim *against* the paper outright.

    A total failure (e.g. no step up to the full stroke, no turning point where the paper
    locates one) is *not reproduced*, never "not evaluated"; the message is the evidence.
    """


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
_DEPENDS: dict[str, tuple[str, ...]] = {}
_EVIDENCE: dict[str, Callable] = {}


def register_extractor(claim_id: str, depends_on=()) -> Callable[[Callable], Callable]:
    """Decorator: register ``func(results, [reading]) -> ours`` for a claim.

    ``ours`` must have the form the claim's check kind expects (module docstring) and
    be in the claim's ``unit``. Raise :class:`NotEvaluable` when the results cannot
    decide the claim (inconclusive) and :class:`ClaimFails` when they decide it against
    the paper outright. Extractors live next to their figure in the topic modules of
    :mod:`passmd.experiments`, which are loaded before every evaluation.

    ``depends_on`` names the axes of :data:`passmd.readings.AXES` the claim's result
    depends on; the function then takes a second argument ``reading`` (``{axis: value}``)
    and is evaluated at every reading of :func:`passmd.readings.design`.
    """
    if not isinstance(claim_id, str) or not _ID.match(claim_id):
        raise ValueError(f"claim_id = {claim_id!r} is not allowed: must be a claims.csv id slug")
    depends = tuple(depends_on)
    for key in depends:
        readings.axis(key)  # ValueError naming the declared axes

    def deco(func: Callable) -> Callable:
        previous = _EXTRACTORS.get(claim_id)
        same = previous is not None and (previous.__module__, previous.__qualname__) == (
            func.__module__, func.__qualname__)
        if previous is not None and not same:  # re-importing the same module is fine
            raise ValueError(f"extractor for claim {claim_id!r} is already registered by "
                             f"{previous.__module__}.{previous.__qualname__}")
        _EXTRACTORS[claim_id] = func
        _DEPENDS[claim_id] = depends
        return func

    return deco


def register_evidence(claim_id: str) -> Callable[[Callable], Callable]:
    """Decorator: register ``func(results) -> list[str]`` of computed evidence for a claim.

    Each string states one evaluated quantity with its value (e.g. "first-fly-back onset
    within 0.4 % of Eq. 7"); the ledger shows them beside every claim that is not
    reproduced. Raise :class:`NotEvaluable` when the results hold no data for them.
    """
    if not isinstance(claim_id, str) or not _ID.match(claim_id):
        raise ValueError(f"claim_id = {claim_id!r} is not allowed: must be a claims.csv id slug")

    def deco(func: Callable) -> Callable:
        _EVIDENCE[claim_id] = func
        return func

    return deco


def depends_on(claim_id: str) -> tuple[str, ...]:
    """The assumption axes a claim's extractor reads (empty: evaluated at the defaults only)."""
    extractors()
    return _DEPENDS.get(claim_id, ())


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
        are then *inconclusive*.
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
    score: float = math.nan  # how far from holding: <= 1 holds (value, trend), 0 holds (others)


def _fmt(x) -> str:
    return "—" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.4g}"


def _numbers(name: str, values, *, boolean: bool = False) -> np.ndarray:
    """A non-empty 1-d float (or bool) array; non-finite data make the claim inconclusive.

    A NaN never counts as "holds": a boolean input given as numbers must be 0 or 1 and finite.
    """
    raw = np.atleast_1d(np.asarray(values))
    if raw.ndim != 1 or raw.size == 0:
        raise ValueError(f"{name} must be a non-empty 1-d array, got shape {raw.shape}")
    if boolean and raw.dtype == bool:
        return raw
    try:
        array = raw.astype(float)
    except (TypeError, ValueError) as err:
        raise ValueError(f"{name} must be numeric, got {raw!r}") from err
    if not np.all(np.isfinite(array)):
        raise NotEvaluable(f"{name} has non-finite values at {int((~np.isfinite(array)).sum())} of "
                           f"{array.size} point(s)")
    if boolean:
        if not np.all((array == 0) | (array == 1)):
            raise ValueError(f"{name} must be booleans, got {raw!r}")
        return array.astype(bool)
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
    limit = f"{tolerance * 100:g} %" if tolerance_kind == "rel" else _fmt(tolerance)
    rel_worst = relative[worst]
    shown_dev = f"{rel_worst * 100:.3g} %" if tolerance_kind == "rel" else _fmt(float(deviation[worst]))
    verb = "within" if passed else "exceeds"
    detail = f"deviation {shown_dev}{where} {verb} the tolerance {limit}"
    allowed = _allowance(tolerance, tolerance_kind, expected)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(allowed > 0, deviation / allowed, np.where(deviation > 0, np.inf, 0.0))
    return Outcome(passed, shown, abs_dev, rel_dev, detail, float(ratio.max()))


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
    return Outcome(bool(ok.all()), shown, abs_dev, rel_dev, detail, float((~ok).mean()))


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
    judged = side | (other if switch else np.zeros_like(side))
    wrong = (side & ~holds) | ((other & holds) if switch else np.zeros_like(side))
    return Outcome(not problems, shown, abs_dev, abs_dev / abs(threshold) if threshold else math.nan, detail,
                   float(wrong.sum() / max(int(judged.sum()), 1)))


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
    worst, worst_rel, problems, points, failing = 0.0, 0.0, [], 0, 0
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
        failing += int(counter > allowance or sign * (y[-1] - y[0]) <= allowance)
        if counter > allowance:
            problems.append(f"{name}steps against the trend by {_fmt(counter)} > allowance {_fmt(allowance)}")
        if sign * (y[-1] - y[0]) <= allowance:
            problems.append(f"{name}last value {_fmt(float(y[-1]))} is not {relation.replace('ing', 'ed')} "
                            f"from first {_fmt(float(y[0]))}")
    shown = f"{relation} over {points} points" if not problems else f"largest counter-step {_fmt(worst)}"
    detail = "; ".join(problems) if problems else f"largest counter-step {_fmt(worst)}"
    return Outcome(not problems, shown, worst, worst_rel, detail, failing / len(series))


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
        return f"within {percent} %"
    return "holds"


@dataclass(frozen=True)
class PointResult:
    """One claim at one reading: ``holds``, ``fails`` or ``inconclusive``, with what was found."""

    reading: dict
    state: str  # "holds", "fails", "inconclusive"
    outcome: Outcome | None
    detail: str


def _evaluate_point(claim: Mapping, func: Callable, depends: tuple, results, reading: dict) -> PointResult:
    try:
        ours = func(results, reading) if depends else func(results)
        outcome = _run_check(claim, ours)
    except NotEvaluable as reason:
        return PointResult(reading, "inconclusive", None, str(reason))
    except ClaimFails as reason:
        return PointResult(reading, "fails", None, str(reason))
    except Exception as err:
        raise ExtractorError(f"claim {claim['id']!r} ({claim['check']} check) at "
                             f"{readings.describe(reading)}: {err!r}") from err
    state = "holds" if outcome.passed else "fails"
    return PointResult(reading, state, outcome, outcome.detail)


def _best(points: list[PointResult]) -> PointResult | None:
    """The reading where the claim holds best: a holding one with the smallest deviation, else the
    failing one closest to holding (smallest score)."""
    decided = [p for p in points if p.state != "inconclusive"]
    if not decided:
        return None

    def key(p):
        score = p.outcome.score if p.outcome is not None and math.isfinite(p.outcome.score) else math.inf
        return (p.state != "holds", score)

    return min(decided, key=key)


def _categorise(points: list[PointResult]) -> tuple[str, str]:
    """Category and a one-line verdict from the claim's results over its readings."""
    default, others = points[0], points[1:]
    holding = [p for p in others if p.state == "holds"]
    open_ = [p for p in others if p.state == "inconclusive"]
    if default.state == "holds":
        return "reproduced", "holds at the defaults"
    if default.state == "inconclusive":
        also = (f"; holds at {', '.join(readings.describe(p.reading) for p in holding)}" if holding else "")
        return "inconclusive", f"at the defaults: {default.detail}{also}"
    if holding:
        return ("reproduced under another reading",
                "holds at " + "; and at ".join(readings.describe(p.reading) for p in holding))
    if open_:
        return ("inconclusive", "fails at the defaults; not covered: "
                + "; ".join(f"{readings.describe(p.reading)} ({p.detail})" for p in open_))
    if others:
        return "not reproduced", f"fails at all {len(points)} readings"
    return "not reproduced", "fails at the defaults (no other reading declared for it)"


def _evidence(claim: Mapping, points: list[PointResult], results) -> list[str]:
    """Computed evidence: the check at every reading, then the claim's registered evidence."""
    lines = []
    for p in points:
        shown = "" if p.outcome is None else f"ours {_shown(p.outcome.ours)}{_unit(claim)}; "
        lines.append(f"{readings.describe(p.reading)}: {p.state} ({shown}{p.detail})")
    func = _EVIDENCE.get(claim["id"])
    if func is not None:
        try:
            lines.extend(func(results))
        except NotEvaluable as reason:
            lines.append(f"evidence not available on these results: {reason}")
        except KeyError as missing:
            lines.append(f"evidence needs results: {missing}")
    return lines


def _shown(value) -> str:
    return _fmt(value) if isinstance(value, float) else str(value)


def _unit(claim: Mapping) -> str:
    return f" {claim['unit']}" if claim["unit"] and claim["check"] == "value" else ""


def evaluate(
    claims: pd.DataFrame, results: Mapping[str, pd.DataFrame], *, strict: bool = True
) -> pd.DataFrame:
    """Evaluate every claim against the result tables, over its readings of the assumption space.

    Each claim is checked at every reading of :func:`passmd.readings.design` for the axes its
    extractor depends on (the defaults first). Its category is computed from those checks:

    * ``reproduced``: the check holds at the defaults;
    * ``reproduced under another reading``: it fails at the defaults and holds at a named
      non-default reading;
    * ``not reproduced``: it fails at every reading evaluated (a total failure, e.g. no step up
      to the full stroke, is a failure);
    * ``inconclusive``: the data cannot decide at the defaults (an extremum at the grid's edge,
      non-finite values, missing results), or it fails there and some reading is not covered
      while none holds.

    NaN never counts as holding (:class:`NotEvaluable`). Claims whose ``requires`` are only
    ``closed_forms`` have ``basis`` "closed form" and are not simulation results.

    Parameters
    ----------
    claims : pandas.DataFrame
        From :func:`load_claims`.
    results : dict
        ``{figure key: DataFrame}``, e.g. from :func:`collect_results`.
    strict : bool
        If True (default), raise ``LookupError`` when a claim's results are present but no
        extractor is registered for it. If False, such claims are *inconclusive* with that note.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`LEDGER_COLUMNS`: ``paper`` and ``ours`` (at the defaults) as shown,
        ``abs_deviation`` (in ``unit``) and ``rel_deviation`` (fraction) where defined,
        ``status`` (the category, one of :data:`STATUSES`), ``verdict`` (one computed line),
        ``evidence`` (computed lines, ``" | "``-separated), ``reason`` (claims.csv's human
        reason), ``basis``, ``readings`` (evaluated), ``holds_at`` (how many hold),
        ``fraction_holds``, ``best_reading``, ``depends_on``.
    """
    registered = extractors()
    problems, rows, point_rows = [], [], []
    for _, claim in claims.iterrows():
        needed = [k for k in claim["requires"].split(";") if k]
        missing = [k for k in needed if k not in results]
        basis = "closed form" if set(needed) <= {"closed_forms"} else "simulation"
        depends = _DEPENDS.get(claim["id"], ())
        points: list[PointResult] = []
        if missing:
            status, verdict, evidence = "inconclusive", "needs results: " + ", ".join(missing), []
        elif claim["id"] not in registered:
            if strict:
                problems.append(f"claim {claim['id']!r} has its results but no registered extractor")
            status, verdict, evidence = "inconclusive", "no extractor registered", []
        else:
            func = registered[claim["id"]]
            points = [_evaluate_point(claim, func, depends, results, r) for r in readings.design(depends)]
            status, verdict = _categorise(points)
            if status == "reproduced":
                verdict = _passed_verdict(claim, points[0].outcome) + " at the defaults"
            evidence = _evidence(claim, points, results)
            point_rows.extend({"claim": claim["id"], "reading": readings.describe(p.reading),
                               "state": p.state, "detail": p.detail} for p in points)
        default = points[0].outcome if points else None
        decided = [p for p in points if p.state != "inconclusive"]
        best = _best(points)
        rows.append({
            "claim": claim["id"], "figure": claim["figure"], "quantity": claim["quantity"],
            "paper": _paper_text(claim), "ours": "—" if default is None else default.ours,
            "unit": claim["unit"],
            "abs_deviation": math.nan if default is None else default.abs_deviation,
            "rel_deviation": math.nan if default is None else default.rel_deviation,
            "tolerance": _tolerance_text(claim), "status": status, "verdict": verdict,
            "evidence": " | ".join(evidence), "reason": claim["reason"], "basis": basis,
            "check": claim["check"], "depends_on": ";".join(depends), "readings": len(points),
            "holds_at": sum(p.state == "holds" for p in points),
            "fraction_holds": (sum(p.state == "holds" for p in decided) / len(decided)
                               if decided else math.nan),
            "best_reading": "—" if best is None else readings.describe(best.reading),
            "note": points[0].detail if points else verdict,
        })
    if problems:
        raise LookupError("ledger evaluation is incomplete:\n  " + "\n  ".join(problems))
    table = pd.DataFrame(rows, columns=list(LEDGER_COLUMNS))
    table.attrs["points"] = point_rows
    return table


def assumption_map(evaluated: pd.DataFrame) -> pd.DataFrame:
    """The claims × readings map of an :func:`evaluate` result.

    One row per claim that depends on at least one axis; one column per evaluated reading
    (``"defaults"`` and ``"<axis label> = <value>"``); cells ``holds``, ``fails``,
    ``inconclusive``, or empty where the claim does not depend on that axis. Then ``holds at``
    (readings where it holds, of those evaluated) and ``best reading`` (where it holds best).
    """
    points = pd.DataFrame(evaluated.attrs.get("points", []),
                          columns=["claim", "reading", "state", "detail"])
    varied = points.groupby("claim")["reading"].transform("size") > 1
    points = points[varied]
    if points.empty:
        return pd.DataFrame(columns=["claim"])
    columns = ["defaults"] + [r for r in dict.fromkeys(points["reading"]) if r != "defaults"]
    table = points.pivot(index="claim", columns="reading", values="state").reindex(columns=columns)
    order = [c for c in evaluated["claim"] if c in table.index]
    table = table.loc[order].fillna("").reset_index()
    summary_ = evaluated.set_index("claim").loc[order]
    table["holds at"] = [f"{int(h)} of {int(n)}" for h, n in zip(summary_["holds_at"], summary_["readings"],
                                                                   strict=True)]
    table["best reading"] = summary_["best_reading"].to_numpy()
    return table


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
    """One line such as ``"11 of 40 claims reproduced (1 a closed-form identity); 3 inconclusive"``.

    Closed-form identities are counted apart: they are not simulation results.
    """
    counts = evaluated["status"].value_counts()
    closed = int(((evaluated["status"] == "reproduced") & (evaluated["basis"] == "closed form")).sum())
    text = f"{int(counts.get('reproduced', 0))} of {len(evaluated)} claims reproduced"
    if closed:
        text += f" ({closed} of them a closed-form identity, not a simulation)"
    others = [f"{int(counts[s])} {s}" for s in STATUSES[1:] if counts.get(s, 0)]
    return text + ("; " + ", ".join(others) if others else "")


def category_anchor(status: str) -> str:
    """The anchor of a category's list in the replication report, e.g. ``ledger-not-reproduced``."""
    check_choice("status", status, STATUSES)
    return "ledger-" + status.replace(" ", "-")


def claim_anchor(claim_id: str) -> str:
    """The anchor of a claim's details in the replication report."""
    return "claim-" + re.sub(r"[^a-z0-9-]", "-", claim_id)


def headline_markdown(evaluated: pd.DataFrame, page: str = "replication_report", *, ref: bool = False) -> str:
    """The per-category counts as MyST markdown, each linking to that category's claims.

    Links go to the targets :func:`details_markdown` writes: ``{ref}`` roles when ``ref`` is
    true (the book), markdown links to ``page.md#anchor`` otherwise.
    """
    counts = evaluated["status"].value_counts()
    parts = []
    for status in STATUSES:
        n = int(counts.get(status, 0))
        label = f"{n} {status}"
        if n and ref:
            label = f"{{ref}}`{label} <{category_anchor(status)}>`"
        elif n:
            label = f"[{label}]({page}.md#{category_anchor(status)})"
        parts.append(label)
    closed = int(((evaluated["status"] == "reproduced") & (evaluated["basis"] == "closed form")).sum())
    note = f" ({closed} of the reproduced a closed-form identity, not a simulation)" if closed else ""
    return f"{len(evaluated)} claims: " + ", ".join(parts) + note


#: Background colours of the categories in :func:`styled`.
STATUS_COLOURS = {
    "reproduced": "#d4edda",
    "reproduced under another reading": "#d1ecf1",
    "not reproduced": "#f8d7da",
    "inconclusive": "#e9ecef",
}


def styled(evaluated: pd.DataFrame, *, links: bool = False):
    """A pandas ``Styler`` of the ledger for the book: one short line per claim.

    Columns: claim, figure, paper, ours, category (coloured badge). Details (quote, reason,
    evidence, readings) are in :func:`details_markdown`; with ``links=True`` each claim links
    to its details on the same page. The table carries the HTML class ``passmd-ledger`` (the
    rendered-book check looks for it) and wraps inside the content column.
    """
    shown = evaluated[["claim", "figure", "paper", "ours", "status"]].copy()
    shown["ours"] = [_fmt(v) if isinstance(v, (float, np.floating)) else str(v) for v in shown["ours"]]
    if links:
        shown["claim"] = [f'<a href="#{claim_anchor(c)}">{c}</a>' for c in evaluated["claim"]]
    shown["status"] = [s + (" (closed form)" if b == "closed form" else "")
                       for s, b in zip(evaluated["status"], evaluated["basis"], strict=True)]
    shown = shown.rename(columns={"status": "category"})
    statuses = evaluated["status"].to_numpy()

    def colour(column):
        return [f"background-color: {STATUS_COLOURS[s]}" for s in statuses]

    return (
        shown.style.hide(axis="index")
        .apply(colour, subset=["category"])
        .set_table_attributes('class="passmd-ledger"')
        .set_table_styles([
            {"selector": "", "props": "table-layout: fixed; width: 100%; max-width: 100%;"},
            {"selector": "td, th", "props": "font-size: 0.8em; vertical-align: top; overflow-wrap: anywhere; "
                                            "word-break: break-word; white-space: normal;"},
        ])
    )


def details_markdown(evaluated: pd.DataFrame, claims: pd.DataFrame) -> str:
    """Per claim, a collapsed block with an anchor: verdict, quote, evidence, reason and source.

    Claims are grouped by category; each group starts with the target of
    :func:`category_anchor` (so the intro's headline can link to it) and each claim with the
    target of :func:`claim_anchor` (the ledger table links to it). The blocks are dropdown
    admonitions: closed until the reader opens them.
    """
    by_id = claims.set_index("id")
    blocks = []
    for status in STATUSES:
        rows = evaluated[evaluated["status"] == status]
        blocks.append(f"({category_anchor(status)})=\n**{status.capitalize()}: {len(rows)}**\n")
        for row in rows.itertuples():
            claim = by_id.loc[row.claim]
            section = claim["source_section"]
            section = f"Section {section}" if section[:1].isdigit() else section
            check = claim["check"] + (f" ({claim['relation']})" if claim["relation"] else "")
            if claim["tolerance"]:
                check += f", tolerance {_tolerance_text(claim)}"
            basis = " (closed form)" if row.basis == "closed form" else ""
            lines = [f"({claim_anchor(row.claim)})=",
                     "```{admonition} " + f"{_md_escape(row.claim)}: {status}{basis}",
                     ":class: dropdown",
                     "",
                     f"*Paper* ({_md_escape(section)}): “{_md_escape(claim['source_quote'])}”", "",
                     f"*Verdict (computed):* {_md_escape(row.verdict)}.", ""]
            if row.basis == "closed form":
                lines += ["*Basis:* a closed-form identity, not a simulation result.", ""]
            if row.evidence:
                lines.append("*Evidence (computed):*")
                lines.append("")
                lines += [f"- {_md_escape(item)}" for item in row.evidence.split(" | ")]
                lines.append("")
            if row.depends_on:
                lines += [f"*Readings:* holds at {row.holds_at} of {row.readings}; best: "
                          f"{_md_escape(row.best_reading)}.", ""]
            if row.reason and status != "reproduced":
                lines += [f"*Reason (our reading of the evidence):* {_md_escape(row.reason)}", ""]
            lines += [f"*Configuration:* {_md_escape(_config_text(claim))}. "
                      f"*Ours:* {_md_escape(claim['ours_definition'])}. "
                      f"*Check:* {_md_escape(check)}. {_md_escape(claim['tolerance_reason'])}"]
            if claim["notes"]:
                lines += ["", f"*Notes:* {_md_escape(claim['notes'])}"]
            lines.append("```")
            blocks.append("\n".join(lines) + "\n")
    return "\n".join(blocks)


def assumption_map_styled(evaluated: pd.DataFrame):
    """:func:`assumption_map` as a compact coloured table (✓ holds, ✗ fails, ? inconclusive).

    The columns are numbered readings; the caption lists what each number means, so the table
    stays inside the content column.
    """
    table = assumption_map(evaluated)
    readings_ = [c for c in table.columns if c not in ("claim", "holds at", "best reading")]
    symbols = {"holds": "✓", "fails": "✗", "inconclusive": "?", "": ""}
    shown = table.rename(columns={r: f"R{i}" for i, r in enumerate(readings_)})
    for i in range(len(readings_)):
        shown[f"R{i}"] = shown[f"R{i}"].map(symbols)
    colours = {"✓": STATUS_COLOURS["reproduced"], "✗": STATUS_COLOURS["not reproduced"],
               "?": STATUS_COLOURS["inconclusive"], "": ""}
    caption = "; ".join(f"R{i}: {r}" for i, r in enumerate(readings_))
    return (shown.style.hide(axis="index")
            .map(lambda v: f"background-color: {colours[v]}" if colours.get(v) else "",
                 subset=[f"R{i}" for i in range(len(readings_))])
            .set_caption("✓ holds, ✗ fails, ? inconclusive, blank: the claim does not depend on it. "
                         f"{caption}.")
            .set_table_attributes('class="passmd-assumption-map"')
            .set_table_styles([
                {"selector": "", "props": "table-layout: fixed; width: 100%; max-width: 100%;"},
                {"selector": "td, th, caption", "props": "font-size: 0.8em; overflow-wrap: anywhere; "
                                                         "white-space: normal;"},
            ]))


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
        items.append("\n".join(line + "  " if i < len(lines) - 1 else line for i, line in enumerate(lines)))
    return "\n".join(items) + "\n"


def assumptions_table() -> pd.DataFrame:
    """Every registered assumption (``passmd.parameters.ASSUMPTIONS``) as a table.

    Imports every module of passmd first, so every assumption registered anywhere is included.
    """
    from passmd.assumptions import all_assumptions  # imports the experiment modules, which import this one

    return pd.DataFrame(
        [{"key": a.key, "symbol": a.symbol, "value": a.value, "unit": a.unit, "rationale": a.rationale,
          "effect on the results": a.sensitivity} for a in all_assumptions().values()]
    )


#: SI name and factor of each claim unit, for machine-readable output (keys carry the SI unit).
SI_UNITS = {"nm": ("m", 1e-9), "mm/s": ("m_per_s", 1e-3), "kHz": ("Hz", 1e3), "mN": ("N", 1e-3),
            "N/m": ("N_per_m", 1.0), "%": ("percent", 1.0), "µs": ("s", 1e-6), "periods": ("periods", 1.0),
            "": ("", 1.0)}


def records(evaluated: pd.DataFrame) -> list[dict]:
    """The ledger as plain records with SI keys (``passmd ledger --json``).

    Per claim: ``claim``, ``category``, ``basis``, ``verdict``, ``evidence`` (list),
    ``reason``, ``depends_on`` (list), ``readings`` (``{reading: state}``), ``fraction_holds``,
    ``best_reading``, ``tolerance`` (as shown), and, where numeric, ``paper_<si>``,
    ``ours_<si>`` and ``abs_deviation_<si>`` in SI units (e.g. ``ours_m``, ``paper_m_per_s``),
    ``rel_deviation`` as a fraction. Non-numeric values are null, with ``ours_text`` as shown.
    """
    points = pd.DataFrame(evaluated.attrs.get("points", []), columns=["claim", "reading", "state", "detail"])
    out = []
    for row in evaluated.itertuples():
        si, factor = SI_UNITS.get(row.unit, (re.sub(r"[^A-Za-z0-9]+", "_", row.unit), 1.0))
        suffix = f"_{si}" if si else ""

        def number(value, factor=factor):
            if isinstance(value, (int, float, np.floating)) and not isinstance(value, bool):
                return float(value) * factor if math.isfinite(value) else None
            return None

        paper = number(float(row.paper)) if _is_number(str(row.paper)) else None
        mine = points[points["claim"] == row.claim]
        out.append({
            "claim": row.claim, "figure": row.figure, "category": row.status, "basis": row.basis,
            "verdict": row.verdict, "evidence": [e for e in row.evidence.split(" | ") if e],
            "reason": row.reason, "depends_on": [d for d in row.depends_on.split(";") if d],
            "readings": dict(zip(mine["reading"], mine["state"], strict=True)),
            "fraction_holds": None if not math.isfinite(row.fraction_holds) else float(row.fraction_holds),
            "best_reading": row.best_reading, "tolerance": row.tolerance, "check": row.check,
            f"paper{suffix}": paper, f"ours{suffix}": number(row.ours), "ours_text": _shown(row.ours),
            f"abs_deviation{suffix}": number(row.abs_deviation),
            "rel_deviation": None if not math.isfinite(row.rel_deviation) else float(row.rel_deviation),
        })
    return out


# ======================================================================================
# Baseline (regression tests)
# ======================================================================================


def load_baseline(path) -> dict[str, str]:
    """``{claim id: category}`` from a baseline CSV written by :func:`write_baseline`."""
    table = pd.read_csv(path, dtype=str, keep_default_na=False, comment="#")
    return dict(zip(table["claim"], table["status"], strict=True))


#: Separator of the readings in a baseline's ``readings`` column.
READINGS_SEPARATOR = " | "


def claim_readings(claim_id: str) -> tuple[str, ...]:
    """The readings a claim is evaluated at now, in words (:func:`passmd.readings.describe`)."""
    return tuple(readings.describe(r) for r in readings.design(depends_on(claim_id)))


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

    ``readings`` lists the readings each category was computed at (:func:`claim_readings`), so
    that two baselines are compared only where they evaluated the same readings. ``header``
    (e.g. the command and date that produced it) is written as ``#`` comment lines.
    """
    path = Path(path)
    table = evaluated[["claim", "status"]].copy()
    table["readings"] = [READINGS_SEPARATOR.join(claim_readings(c)) for c in table["claim"]]
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
