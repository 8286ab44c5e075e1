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
from passmd.ledger.rules import TIE_RULE
from passmd.ledger.tags import (  # re-exported: extractors import them from here
    NO_MEASURED_DATA,
    ClaimFails,
    ClaimFunctions,
    CoarseGrid,
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
    "CoarseGrid",
    "ExtractorError",
    "Inconclusive",
    "NO_MEASURED_DATA",
    "NoRun",
    "NotEvaluable",
    "Outcome",
    "Scoped",
    "Subset",
    "TIE_RULE",
    "check_claim",
    "check_ordering",
    "check_threshold",
    "check_trend",
    "check_value",
    "collect_claim_functions",
    "compared_names",
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
    #: ``ours`` as the ledger shows it, with units and what it is (e.g. ``"17.41 nm vs 23.13 nm"``)
    text: str = ""


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


def _with_unit(value, unit: str) -> str:
    """A number as the ledger shows it, with its unit (``"17.41 nm"``, ``"12.4 %"``, ``"3"``)."""
    text = format_number(float(value))
    return f"{text} {unit}".strip() if unit != "%" else f"{text} %"


def check_value(ours, paper_value=None, tolerance=0.0, tolerance_kind="rel", curve=None, *, unit: str = "",
                x_unit: str = "") -> Outcome:
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
    unit, x_unit : str
        Units of the values and of a curve's x, for the texts (e.g. ``"nm"``, ``"N"``).
    """
    check_choice("tolerance_kind", tolerance_kind, TOLERANCE_KINDS)
    if curve is None:
        scalar = not isinstance(ours, (Mapping, str)) and np.ndim(ours) == 0
        value = float(_numbers("ours", ours)[0]) if scalar else None
        if value is None:
            raise ValueError(f"ours must be a number for a value claim, got {ours!r}")
        expected, got, shown, x = np.array([paper_value], float), np.array([value]), value, None
        text = f"{_with_unit(value, unit)} vs the paper's {_with_unit(paper_value, unit)}"
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
        text = f"{got.size} points, {format_number(got.min())}–{_with_unit(got.max(), unit)}"
    deviation = np.abs(got - expected)
    with np.errstate(divide="ignore", invalid="ignore"):
        relative = np.where(expected != 0, deviation / np.abs(expected), np.nan)
    worst = int(np.argmax(deviation / np.maximum(_allowance(tolerance, tolerance_kind, expected), 1e-300)))
    passed = bool(np.all(deviation <= _allowance(tolerance, tolerance_kind, expected)))
    abs_dev = float(deviation.max())
    rel_dev = float(np.nanmax(relative)) if np.any(np.isfinite(relative)) else math.nan
    where = f" at {_with_unit(x[worst], x_unit)}" if x is not None else ""
    limit = f"{tolerance * 100:g} %" if tolerance_kind == "rel" else _with_unit(tolerance, unit)
    rel_worst = relative[worst]
    shown_dev = (f"{rel_worst * 100:.3g} %" if tolerance_kind == "rel"
                 else _with_unit(float(deviation[worst]), unit))
    verb = "within" if passed else "exceeds"
    compared = ("" if x is None else
                f" ({_with_unit(got[worst], unit)} vs {_with_unit(expected[worst], unit)})")
    detail = f"deviation {shown_dev}{where}{compared} {verb} the tolerance {limit}"
    allowed = _allowance(tolerance, tolerance_kind, expected)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(allowed > 0, deviation / allowed, np.where(deviation > 0, np.inf, 0.0))
    return Outcome(passed, shown, abs_dev, rel_dev, detail, float(ratio.max()), float(ratio.max()), text)


#: How the ledger writes each ordering relation.
ORDERING_SYMBOLS = {"<": "<", ">": ">", "approx": "≈"}

def check_ordering(ours, relation, tolerance=None, tolerance_kind="rel", *, unit: str = "",
                   names: tuple[str, str] = ("lhs", "rhs")) -> Outcome:
    """``ordering`` check: ``lhs < rhs``, ``lhs > rhs`` or ``lhs ≈ rhs`` at every element.

    The margin m is 0 without a tolerance, ``tolerance·|rhs|`` (rel) or ``tolerance`` (abs):
    ``<`` needs lhs < rhs − m, ``>`` needs lhs > rhs + m, ``approx`` needs |lhs − rhs| ≤ m. ``ours`` may
    carry ``'resolution'`` (in the values' unit, default 0) and ``'at'`` with ``'at_unit'`` (where each
    element is, e.g. the preloads); the tie rule decides elements closer than the resolution: an
    ordering with tied elements and no failing one is undecided
    (:class:`~passmd.ledger.tags.NotEvaluable`), an agreement counts them as holding
    (:data:`passmd.ledger.rules.TIE_RULE`).
    ``names`` names
    the two sides in the texts.
    """
    check_choice("relation", relation, RELATIONS["ordering"])
    data = _mapping("ours", ours, ("lhs", "rhs"))
    lhs, rhs = _numbers("ours['lhs']", data["lhs"]), _numbers("ours['rhs']", data["rhs"])
    if lhs.shape != rhs.shape:
        raise ValueError(f"ours['lhs'] and ours['rhs'] differ in length: {lhs.size} vs {rhs.size}")
    resolution = float(data.get("resolution", 0.0))
    if not (math.isfinite(resolution) and resolution >= 0):
        raise ValueError(f"ours['resolution'] must be a finite number >= 0, got {resolution!r}")
    at = None if data.get("at") is None else np.atleast_1d(np.asarray(data["at"], dtype=float))
    at_unit = str(data.get("at_unit", ""))
    margin = _allowance(tolerance, tolerance_kind, rhs)
    difference = lhs - rhs
    tied = np.abs(difference) <= resolution
    if relation == "<":
        ok = (difference < -margin) & ~tied
    elif relation == ">":
        ok = (difference > margin) & ~tied
    else:
        ok = np.abs(difference) <= np.maximum(margin, resolution)
        tied = np.zeros_like(ok)
    wrong = ~ok & ~tied
    symbol = ORDERING_SYMBOLS[relation]
    left, right = names

    def pair(i):
        where = "" if at is None else f" at {_with_unit(at[i], at_unit)}"
        return f"{left} {_with_unit(lhs[i], unit)} vs {right} {_with_unit(rhs[i], unit)}{where}"

    shown = (f"{format_number(float(lhs[0]))} vs {format_number(float(rhs[0]))}" if lhs.size == 1
             else f"{int(ok.sum())} of {ok.size} hold")
    text = (f"{_with_unit(lhs[0], unit)} vs {_with_unit(rhs[0], unit)}" if lhs.size == 1
            else f"holds at {int(ok.sum())} of {ok.size} points")
    resolved = f" (resolution {_with_unit(resolution, unit)})" if resolution > 0 else ""
    if wrong.any():
        bad = int(np.flatnonzero(wrong)[0])
        detail = (f"{left} {symbol} {right} fails" + ("" if lhs.size == 1 else
                                                       f" at {int(wrong.sum())} of {wrong.size} points")
                  + f": {pair(bad)}" + (f", needing a margin of {_with_unit(margin[bad], unit)}"
                                        if margin[bad] > 0 else ""))
    elif tied.any():
        i = int(np.flatnonzero(tied)[0])
        raise NotEvaluable(f"tied: {pair(i)} differ by {_with_unit(abs(difference[i]), unit)}, not more than "
                           f"the resolution {_with_unit(resolution, unit)} of what they measure"
                           + ("" if lhs.size == 1 else f" ({int(tied.sum())} of {tied.size} points)")
                           + f": {left} {symbol} {right} is undecided")
    else:
        detail = (f"{left} {symbol} {right}" + ("" if lhs.size == 1 else f" at all {ok.size} points")
                  + (f": {pair(0)}" if lhs.size == 1 else "") + resolved)
    with np.errstate(divide="ignore", invalid="ignore"):
        relative = np.abs(difference) / np.abs(rhs)
    abs_dev = float(np.abs(difference).max()) if relation == "approx" else math.nan
    rel_dev = float(np.nanmax(relative)) if relation == "approx" and np.isfinite(relative).any() else math.nan
    ratio = math.nan
    if relation == "approx":
        allowed = np.maximum(margin, resolution)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = float(np.max(np.where(allowed > 0, np.abs(difference) / allowed,
                                          np.where(difference != 0, np.inf, 0.0))))
    return Outcome(bool(ok.all()), shown, abs_dev, rel_dev, detail, float(wrong.mean()), ratio, text)


def _switch_between(x: np.ndarray, margin: np.ndarray | None, i: int, j: int) -> float:
    """Where the condition changes between grid points i (holds) and j (fails): the zero of the linear
    interpolation of ``margin`` (holds where > 0) when given, else the midpoint."""
    if margin is not None and margin[i] > 0 >= margin[j]:
        return float(x[i] + (x[j] - x[i]) * margin[i] / (margin[i] - margin[j]))
    return float(0.5 * (x[i] + x[j]))


def check_threshold(ours, relation, threshold, tolerance=0.0, tolerance_kind="abs", *,
                    unit: str = "") -> Outcome:
    """``threshold`` check: where a condition holds relative to ``threshold`` (x_t).

    Points inside the band x_t ± m (m = tolerance, or tolerance·|x_t| for rel) are not
    judged. ``holds_below``: holds at every point below the band (at least one);
    ``switch_below``: in addition fails at every point above it (at least one);
    ``*_above``: mirrored. Ours is the observed switch, read at the precision of the data, not at a
    grid point: ``ours['switch']`` when the extractor computes it exactly (e.g. the frequency at
    which Eq. 15 stops fitting, the criterion the command line uses); else between the grid points
    where the condition changes (the first failure going up for ``*_below``, the last for
    ``*_above``), at the zero of ``ours['margin']`` (a continuous quantity positive where the condition
    holds) when given, else their midpoint; a failure at the grid's first point (``*_below``) or last
    (``*_above``) bounds the switch by it.
    """
    check_choice("relation", relation, RELATIONS["threshold"])
    data = _mapping("ours", ours, ("x", "holds"))
    x, holds = _numbers("ours['x']", data["x"]), _numbers("ours['holds']", data["holds"], boolean=True)
    if x.shape != holds.shape:
        raise ValueError(f"ours['x'] and ours['holds'] differ in length: {x.size} vs {holds.size}")
    margin = None if data.get("margin") is None else _numbers("ours['margin']", data["margin"])
    order = np.argsort(x)
    x, holds = x[order], holds[order]
    margin = None if margin is None else margin[order]
    band = float(_allowance(tolerance, tolerance_kind, np.array([threshold]))[0])
    below, above = x < threshold - band, x > threshold + band
    side, other = (below, above) if relation.endswith("below") else (above, below)
    side_name = "below" if relation.endswith("below") else "above"
    if not side.any():
        edge = threshold - band if side is below else threshold + band
        raise CoarseGrid(f"no grid point {side_name} {_with_unit(edge, unit)}")
    switch = relation.startswith("switch")
    if switch and not other.any():
        raise CoarseGrid("no grid point on the far side of the threshold band")
    fail_at = np.flatnonzero(~holds)
    where = f"holds over {format_number(x[0])}–{_with_unit(x[-1], unit)}"
    observed, bracket = math.nan, None
    if fail_at.size:
        j = int(fail_at.min()) if relation.endswith("below") else int(fail_at.max())
        k = j - 1 if relation.endswith("below") else j + 1
        if data.get("switch") is not None:
            observed = float(data["switch"])
            where = f"at {_with_unit(observed, unit)} (computed exactly)"
        elif 0 <= k < x.size:
            lo, hi = sorted((float(x[k]), float(x[j])))
            observed = _switch_between(x, margin, k, j)
            bracket = None if margin is not None else (lo, hi)
            where = (f"at {_with_unit(observed, unit)} (between {format_number(lo)} and "
                     f"{_with_unit(hi, unit)})"
                     if margin is not None else f"between {format_number(lo)} and {_with_unit(hi, unit)}")
        else:
            observed = float(x[j])
            edge = "first" if relation.endswith("below") else "last"
            bound = "below" if relation.endswith("below") else "above"
            where = (f"{bound} {_with_unit(x[j], unit)} (it fails at "
                     f"the grid's {edge} point)")
    problems = []
    if not holds[side].all():
        problems.append(f"fails {side_name} the threshold band ({_with_unit(threshold, unit)} ± "
                        f"{_with_unit(band, unit)}) at {_with_unit(float(x[side & ~holds][0]), unit)}")
    if switch and holds[other].any():
        problems.append(f"still holds beyond it at {_with_unit(float(x[other & holds][0]), unit)}")
    if bracket is not None:  # the switch is known to the bracket: its distance from x_t, 0 inside it
        abs_dev = max(bracket[0] - threshold, threshold - bracket[1], 0.0)
    else:
        abs_dev = abs(observed - threshold) if math.isfinite(observed) else math.nan
    text = where[3:] if where.startswith("at ") else where
    detail = "; ".join(problems) if problems else (
        f"switch observed {where}" if math.isfinite(observed) else "holds at every grid point")
    judged = side | (other if switch else np.zeros_like(side))
    wrong = (side & ~holds) | ((other & holds) if switch else np.zeros_like(side))
    ratio = abs_dev / band if band > 0 and math.isfinite(abs_dev) else math.nan
    shown = observed if math.isfinite(observed) else text
    return Outcome(not problems, shown, abs_dev, abs_dev / abs(threshold) if threshold else math.nan, detail,
                   float(wrong.sum() / max(int(judged.sum()), 1)), ratio, text)


def check_trend(ours, relation, tolerance=0.0, tolerance_kind="rel", *, unit: str = "") -> Outcome:
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
            problems.append(f"{name}steps against the trend by {_with_unit(counter, unit)}, more than the "
                            f"allowance {_with_unit(allowance, unit)}")
        if sign * (y[-1] - y[0]) <= allowance:
            problems.append(f"{name}last value {_with_unit(float(y[-1]), unit)} is not "
                            f"{relation.replace('ing', 'ed')} from the first {_with_unit(float(y[0]), unit)}")
    shown = (f"{relation} over {points} points" if not problems
             else f"largest counter-step {format_number(worst)}")
    text = (f"{relation} over {points} points, largest counter-step {_with_unit(worst, unit)}" if not problems
            else f"largest counter-step {_with_unit(worst, unit)}")
    detail = "; ".join(problems) if problems else f"largest counter-step {_with_unit(worst, unit)}"
    return Outcome(not problems, shown, worst, worst_rel, detail, failing / len(series), ratio, text)


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
    unit = str(claim.get("unit", "") or "")
    while isinstance(ours, (Scoped, Subset)):  # where the data lie does not change the check
        ours = ours.ours
    if kind == "value":
        curve = None
        ours = dict(ours) if isinstance(ours, Mapping) else ours
        if claim["reference"] and isinstance(ours, Mapping) and "reference" in ours:
            # the same closed form at the reading's μ, at ours' x (the extractor computed it)
            curve = (np.asarray(ours["x"], float), np.asarray(ours["reference"], float))
            ours = {"x": ours["x"], "y": ours["y"], "x_unit": ours.get("x_unit", "")}
        elif claim["reference"]:
            filename, _, column = claim["reference"].partition(":")
            table = reference.load_reference_curve(filename)
            curve = (table.iloc[:, 0].to_numpy(), table[column].to_numpy())
        x_unit = str(ours.pop("x_unit", "")) if isinstance(ours, dict) else ""
        return check_value(ours, claim["paper_value_num"], tolerance, tolerance_kind, curve, unit=unit,
                           x_unit=x_unit)
    if kind == "ordering":
        return check_ordering(ours, relation, tolerance, tolerance_kind, unit=unit,
                              names=compared_names(claim))
    if kind == "threshold":
        return check_threshold(ours, relation, claim["paper_value_num"], tolerance, tolerance_kind, unit=unit)
    return check_trend(ours, relation, tolerance, tolerance_kind, unit=unit)


def compared_names(claim: Mapping) -> tuple[str, str]:
    """What an ordering claim compares, as its ``compares`` column names them (``"lhs | rhs"``), else
    ``("lhs", "rhs")``."""
    parts = [p.strip() for p in str(claim.get("compares", "") or "").split("|")]
    return (parts[0], parts[1]) if len(parts) == 2 and all(parts) else ("lhs", "rhs")
