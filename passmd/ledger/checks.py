"""The numeric checks of the ledger.

A claim of ``claims.csv`` (:mod:`passmd.ledger.claims`) names one of four kinds of check; each is a
function here that compares *ours* (what an extractor computed from the result tables) with the
paper and returns an :class:`Outcome`. :func:`check_claim` runs the check a claims.csv row names.
The tags that mark a function as a claim's extractor, and what an extractor may raise or return
besides its numbers, are :mod:`passmd.ledger.tags` (re-exported here).

What ``ours`` must be for each check kind
-----------------------------------------
``value``
    A finite number in the claim's unit; for a claim with a ``reference`` curve,
    ``{'x': array, 'y': array}`` (x inside the curve's range, y in the curve's unit), with
    ``'reference'``: the curve at x when the extractor evaluates it at its reading (μ).
``ordering``
    ``{'lhs': a, 'rhs': b}``, numbers or equal-length arrays; the relation (``<``, ``>``,
    ``approx``) must hold at every element.
``threshold``
    ``{'x': array, 'holds': bool array}``: where the claim's condition holds.
``trend``
    ``{'x': array, 'y': array}`` or ``{label: {'x': array, 'y': array}, ...}``.

An extractor raises :class:`NotEvaluable` (alias :data:`Inconclusive`) when the results
cannot decide the claim (e.g. the quick profile's grid has no point where the claim speaks),
:class:`NoRun` when a table lacks the run of a reading (a defect), and :class:`ClaimFails` when
they decide it against the paper outright (a total failure is *not reproduced*); it returns
:class:`Scoped` when the deciding data lie where a method the claim rests on is undefined, and
:class:`Subset` when its table holds only part of the grid the claim speaks of.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from passmd.ledger import reference
from passmd.ledger.claims import RELATIONS, TOLERANCE_KINDS
from passmd.ledger.tags import (  # re-exported: extractors import them from here
    NO_MEASURED_DATA,
    ClaimFails,
    ClaimFunctions,
    ExtractorError,
    Inconclusive,
    NoRun,
    NotEvaluable,
    Scoped,
    Subset,
    collect_claim_functions,
    evidence,
    experiment_claim,
    extractor,
    no_measured_data,
)
from passmd.runtime.validation import check_choice

__all__ = [
    "ORDERING_SYMBOLS",
    "ClaimFails",
    "ClaimFunctions",
    "ExtractorError",
    "Inconclusive",
    "NO_MEASURED_DATA",
    "NoRun",
    "NotEvaluable",
    "Outcome",
    "Scoped",
    "Subset",
    "check_claim",
    "check_ordering",
    "check_threshold",
    "check_trend",
    "check_value",
    "collect_claim_functions",
    "curve_deviation",
    "evidence",
    "experiment_claim",
    "extractor",
    "format_number",
    "no_measured_data",
    "reference_table",
]


@dataclass(frozen=True)
class Outcome:
    """Result of one check: pass/fail, what to display, deviations and an explanation."""

    passed: bool
    ours: object  # number or short text shown in the ledger's "ours" column
    abs_deviation: float = math.nan
    rel_deviation: float = math.nan
    detail: str = ""  # why it failed (or what was found)
    score: float = math.nan  # how far from holding: <= 1 holds (value, trend), 0 holds (others)
    #: the margin against the tolerance: deviation / allowed deviation (value, approximate ordering),
    #: the worst of counter-step / allowance and allowance / net change (trend), |switch − x_t| / band
    #: (threshold); ≤ 1 within the tolerance; NaN without a tolerance (plain ordering)
    ratio: float = math.nan


def format_number(x) -> str:
    """A number with 4 significant digits as the ledger shows it; ``"—"`` for None or NaN."""
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
        shown = f"{got.size} points, {format_number(got.min())}–{format_number(got.max())}"
    deviation = np.abs(got - expected)
    with np.errstate(divide="ignore", invalid="ignore"):
        relative = np.where(expected != 0, deviation / np.abs(expected), np.nan)
    worst = int(np.argmax(deviation / np.maximum(_allowance(tolerance, tolerance_kind, expected), 1e-300)))
    passed = bool(np.all(deviation <= _allowance(tolerance, tolerance_kind, expected)))
    abs_dev = float(deviation.max())
    rel_dev = float(np.nanmax(relative)) if np.any(np.isfinite(relative)) else math.nan
    where = f" at x = {format_number(float(x[worst]))}" if curve is not None else ""
    limit = f"{tolerance * 100:g} %" if tolerance_kind == "rel" else format_number(tolerance)
    rel_worst = relative[worst]
    shown_dev = (f"{rel_worst * 100:.3g} %" if tolerance_kind == "rel"
                 else format_number(float(deviation[worst])))
    verb = "within" if passed else "exceeds"
    detail = f"deviation {shown_dev}{where} {verb} the tolerance {limit}"
    allowed = _allowance(tolerance, tolerance_kind, expected)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(allowed > 0, deviation / allowed, np.where(deviation > 0, np.inf, 0.0))
    return Outcome(passed, shown, abs_dev, rel_dev, detail, float(ratio.max()), float(ratio.max()))


#: How the ledger writes each ordering relation.
ORDERING_SYMBOLS = {"<": "<", ">": ">", "approx": "≈"}


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
    symbol = ORDERING_SYMBOLS[relation]
    shown = (f"{format_number(float(lhs[0]))} vs {format_number(float(rhs[0]))}" if lhs.size == 1
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
                  f"{format_number(float(lhs[bad]))} vs {format_number(float(rhs[bad]))}")
    ratio = math.nan
    if relation == "approx":
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = float(np.max(np.where(margin > 0, np.abs(difference) / margin,
                                          np.where(difference != 0, np.inf, 0.0))))
    return Outcome(bool(ok.all()), shown, abs_dev, rel_dev, detail, float((~ok).mean()), ratio)


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
        raise NotEvaluable(f"no point {side_name} {format_number(edge)}")
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
        problems.append(f"fails {side_name} the threshold at x = {format_number(float(x[side & ~holds][0]))}")
    if switch and holds[other].any():
        problems.append(f"still holds beyond it at x = {format_number(float(x[other & holds][0]))}")
    abs_dev = abs(observed - threshold) if math.isfinite(observed) else math.nan
    shown = (observed if math.isfinite(observed)
             else f"holds over {format_number(x[0])}–{format_number(x[-1])}")
    detail = "; ".join(problems) if problems else (
        f"switch observed at x = {format_number(observed)}" if math.isfinite(observed)
        else "holds at every point")
    judged = side | (other if switch else np.zeros_like(side))
    wrong = (side & ~holds) | ((other & holds) if switch else np.zeros_like(side))
    ratio = abs_dev / band if band > 0 and math.isfinite(abs_dev) else math.nan
    return Outcome(not problems, shown, abs_dev, abs_dev / abs(threshold) if threshold else math.nan, detail,
                   float(wrong.sum() / max(int(judged.sum()), 1)), ratio)


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
    worst, worst_rel, problems, points, failing, ratio = 0.0, 0.0, [], 0, 0, 0.0
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
        net = sign * (y[-1] - y[0])
        ratio = max(ratio, counter / allowance if allowance > 0 else (math.inf if counter > 0 else 0.0),
                    allowance / net if net > 0 else math.inf)
        if counter > allowance:
            problems.append(f"{name}steps against the trend by {format_number(counter)} > allowance "
                            f"{format_number(allowance)}")
        if sign * (y[-1] - y[0]) <= allowance:
            problems.append(f"{name}last value {format_number(float(y[-1]))} is not "
                            f"{relation.replace('ing', 'ed')} from first {format_number(float(y[0]))}")
    shown = (f"{relation} over {points} points" if not problems
             else f"largest counter-step {format_number(worst)}")
    detail = "; ".join(problems) if problems else f"largest counter-step {format_number(worst)}"
    return Outcome(not problems, shown, worst, worst_rel, detail, failing / len(series), ratio)


def reference_table(curve: str, friction_coefficient: float = reference.REFERENCE_FRICTION_COEFFICIENT):
    """A closed-form reference table (:data:`passmd.ledger.reference.CURVES`) at μ: the committed file at
    the reference μ, else computed by the same code (:func:`passmd.ledger.reference.closed_form_curves`)."""
    if math.isclose(friction_coefficient, reference.REFERENCE_FRICTION_COEFFICIENT, rel_tol=1e-12):
        return reference.load_reference_curve(curve)
    return reference.closed_form_curves(curve, friction_coefficient)


def curve_deviation(x, y, curve: str, column: str,
                    friction_coefficient: float = reference.REFERENCE_FRICTION_COEFFICIENT) -> float:
    """Largest relative deviation in % of ``y`` from a reference curve at ``x``.

    Helper for extractors of ordering claims such as ``fig6a-rigid-ac-not-eq10``.
    ``curve`` is a table of :data:`passmd.ledger.reference.CURVES` and ``column`` one of its columns,
    at μ = ``friction_coefficient`` (:func:`reference_table`).
    """
    table = reference_table(curve, friction_coefficient)
    outcome = check_value({"x": x, "y": y}, tolerance=0.0, curve=(table.iloc[:, 0], table[column]))
    return 100.0 * outcome.rel_deviation


def check_claim(claim: Mapping, ours) -> Outcome:
    """Run the check a claims.csv row names (``check``, ``relation``, tolerance) on ``ours``.

    ``claim`` is a row of :func:`passmd.ledger.claims.load_claims`; a value claim with a ``reference``
    is compared with that reference curve (:func:`passmd.ledger.reference.load_reference_curve`).
    """
    kind, relation = claim["check"], claim["relation"]
    tolerance, tolerance_kind = claim["tolerance_num"], claim["tolerance_kind"] or "rel"
    while isinstance(ours, (Scoped, Subset)):  # where the data lie does not change the check
        ours = ours.ours
    if kind == "value":
        curve = None
        if claim["reference"] and isinstance(ours, Mapping) and "reference" in ours:
            # the same closed form at the reading's μ, at ours' x (the extractor computed it)
            curve = (np.asarray(ours["x"], float), np.asarray(ours["reference"], float))
            ours = {"x": ours["x"], "y": ours["y"]}
        elif claim["reference"]:
            filename, _, column = claim["reference"].partition(":")
            table = reference.load_reference_curve(filename)
            curve = (table.iloc[:, 0].to_numpy(), table[column].to_numpy())
        return check_value(ours, claim["paper_value_num"], tolerance, tolerance_kind, curve)
    if kind == "ordering":
        return check_ordering(ours, relation, tolerance, tolerance_kind)
    if kind == "threshold":
        return check_threshold(ours, relation, claim["paper_value_num"], tolerance, tolerance_kind)
    return check_trend(ours, relation, tolerance, tolerance_kind)
