"""The numeric checks of the ledger, and the tags that mark a function as a claim's extractor.

A claim of ``claims.csv`` (:mod:`passmd.ledger.claims`) names one of four kinds of check; each is a
function here that compares *ours* (what an extractor computed from the result tables) with the
paper and returns an :class:`Outcome`. :func:`check_claim` runs the check a claims.csv row names.

Extractors are plain functions ``(results[, reading]) -> ours`` living next to their figure in
:mod:`passmd.experiments`; :func:`extractor` and :func:`evidence` only tag them with their claim
id (nothing is registered at import), and :func:`collect_claim_functions` finds the tagged
functions of the modules it is given (the ledger passes ``passmd.experiments.figure_table.CLAIM_MODULES``).

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
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from passmd.ledger import readings, reference
from passmd.ledger.claims import CLAIM_ID, RELATIONS, TOLERANCE_KINDS
from passmd.runtime.validation import check_choice

__all__ = [
    "ORDERING_SYMBOLS",
    "ClaimFails",
    "ClaimFunctions",
    "ExtractorError",
    "Inconclusive",
    "NO_MEASURED_DATA",
    "NotEvaluable",
    "Outcome",
    "check_claim",
    "check_ordering",
    "check_threshold",
    "check_trend",
    "check_value",
    "collect_claim_functions",
    "curve_deviation",
    "evidence",
    "extractor",
    "format_number",
    "no_measured_data",
]


class NotEvaluable(Exception):
    """Raised by an extractor or a check when the results cannot decide a claim.

    The claim is then *inconclusive* at that reading (an extremum at the edge of the grid,
    non-finite values, a run that did not converge, a reading the tables hold no run for);
    the message says what is missing.
    """


#: The name the verdict taxonomy uses for :class:`NotEvaluable`.
Inconclusive = NotEvaluable


#: How the verdict of a claim about the experiment begins: the paper's text tabulates no measurement.
NO_MEASURED_DATA = "no measured data in the paper's text"


def no_measured_data(what: str):
    """Raise :class:`NotEvaluable` for a claim about the experiment: the paper's text gives none of
    its measurements (``what`` names them), so no computation can decide the claim."""
    raise NotEvaluable(f"{NO_MEASURED_DATA}: {what}")


class ClaimFails(Exception):
    """Raised by an extractor when the results decide the claim *against* the paper outright.

    A total failure (e.g. no step up to the full stroke, no turning point where the paper
    locates one) is *not reproduced*, never "not evaluated"; the message is the evidence.
    """


class ExtractorError(ValueError):
    """An extractor failed, or returned something its claim's check cannot use."""


@dataclass(frozen=True)
class Outcome:
    """Result of one check: pass/fail, what to display, deviations and an explanation."""

    passed: bool
    ours: object  # number or short text shown in the ledger's "ours" column
    abs_deviation: float = math.nan
    rel_deviation: float = math.nan
    detail: str = ""  # why it failed (or what was found)
    score: float = math.nan  # how far from holding: <= 1 holds (value, trend), 0 holds (others)


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
    return Outcome(passed, shown, abs_dev, rel_dev, detail, float(ratio.max()))


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
            problems.append(f"{name}steps against the trend by {format_number(counter)} > allowance "
                            f"{format_number(allowance)}")
        if sign * (y[-1] - y[0]) <= allowance:
            problems.append(f"{name}last value {format_number(float(y[-1]))} is not "
                            f"{relation.replace('ing', 'ed')} from first {format_number(float(y[0]))}")
    shown = (f"{relation} over {points} points" if not problems
             else f"largest counter-step {format_number(worst)}")
    detail = "; ".join(problems) if problems else f"largest counter-step {format_number(worst)}"
    return Outcome(not problems, shown, worst, worst_rel, detail, failing / len(series))


def curve_deviation(x, y, curve: str, column: str) -> float:
    """Largest relative deviation in % of ``y`` from a reference curve at ``x``.

    Helper for extractors of ordering claims such as ``fig6a-rigid-ac-not-eq10``.
    ``curve`` is a table of :data:`passmd.ledger.reference.CURVES` and ``column`` one of its columns.
    """
    table = reference.load_reference_curve(curve)
    outcome = check_value({"x": x, "y": y}, tolerance=0.0, curve=(table.iloc[:, 0], table[column]))
    return 100.0 * outcome.rel_deviation


def check_claim(claim: Mapping, ours) -> Outcome:
    """Run the check a claims.csv row names (``check``, ``relation``, tolerance) on ``ours``.

    ``claim`` is a row of :func:`passmd.ledger.claims.load_claims`; a value claim with a ``reference``
    is compared with that reference curve (:func:`passmd.ledger.reference.load_reference_curve`).
    """
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


# ======================================================================================
# Tags: which function extracts (or gives evidence for) which claim
# ======================================================================================


def _check_claim_id(claim_id) -> str:
    if not isinstance(claim_id, str) or not CLAIM_ID.match(claim_id):
        raise ValueError(f"claim_id = {claim_id!r} is not allowed: must be a claims.csv id slug")
    return claim_id


def extractor(claim_id: str, depends_on=(), *, not_informative: str = "") -> Callable[[Callable], Callable]:
    """Decorator: tag ``func(results[, reading]) -> ours`` as the extractor of a claim.

    ``ours`` must have the form the claim's check kind expects (module docstring) and be in
    the claim's ``unit``. Raise :class:`NotEvaluable` when the results cannot decide the claim
    (inconclusive) and :class:`ClaimFails` when they decide it against the paper outright.

    ``depends_on`` names the axes of :data:`passmd.ledger.readings.AXES` the claim's result depends
    on; the function then takes a second argument ``reading`` (``{axis: value}``) and is
    evaluated at every reading of :func:`passmd.ledger.readings.design`.

    ``not_informative`` says why the claim's check cannot fail on any result the model can
    produce (a closed-form identity, a statement every finite contact stiffness satisfies at the
    claim's amplitude); empty (the default) for a check some counter-example makes fail. The
    ledger counts the non-informative claims apart.

    The decorator only sets ``func.claim_extractor`` (the id), ``func.claim_depends_on`` and
    ``func.not_informative``; :func:`collect_claim_functions` finds the tagged functions of a module.
    """
    _check_claim_id(claim_id)
    depends = tuple(depends_on)
    for key in depends:
        readings.axis(key)  # ValueError naming the declared axes
    if not isinstance(not_informative, str):
        raise ValueError(f"not_informative = {not_informative!r} is not allowed: must be a reason (str), "
                         "empty for an informative check")

    def tag(func: Callable) -> Callable:
        func.claim_extractor = claim_id
        func.claim_depends_on = depends
        func.not_informative = not_informative.strip()
        return func

    return tag


def evidence(claim_id: str) -> Callable[[Callable], Callable]:
    """Decorator: tag ``func(results) -> list[str]`` as the computed evidence of a claim.

    Each string states one evaluated quantity with its value (e.g. "first-fly-back onset
    within 0.4 % of Eq. 7"); the ledger shows them beside the claim's checks. Raise
    :class:`NotEvaluable` when the results hold no data for them. Sets ``func.claim_evidence``.
    """
    _check_claim_id(claim_id)

    def tag(func: Callable) -> Callable:
        func.claim_evidence = claim_id
        return func

    return tag


@dataclass(frozen=True)
class ClaimFunctions:
    """The tagged functions of some modules, by claim id (read-only mappings)."""

    extractors: Mapping[str, Callable]
    depends_on: Mapping[str, tuple[str, ...]]
    evidence: Mapping[str, Callable]


def _module_functions(module) -> Iterable[Callable]:
    """The callables a module holds at its top level, and inside its top-level tuples (functions
    made in a loop, e.g. one evidence function per claim of a table)."""
    for value in vars(module).values():
        if isinstance(value, tuple):
            yield from (item for item in value if callable(item))
        elif callable(value):
            yield value


def collect_claim_functions(modules: Iterable) -> ClaimFunctions:
    """The extractors (with their ``depends_on``) and evidence functions defined in ``modules``.

    Looks at every module-level function (and every function in a module-level tuple) tagged
    by :func:`extractor` or :func:`evidence`; the same function reached twice (e.g. imported
    into another of the modules) counts once.

    Raises
    ------
    ValueError
        When two different functions are tagged for the same claim id (naming both).
    """
    found: dict[str, dict[str, Callable]] = {"claim_extractor": {}, "claim_evidence": {}}
    for module in modules:
        for func in _module_functions(module):
            for tag, by_id in found.items():
                claim_id = getattr(func, tag, None)
                if not isinstance(claim_id, str):
                    continue
                previous = by_id.setdefault(claim_id, func)
                if previous is not func:
                    raise ValueError(f"claim {claim_id!r} is claimed twice ({tag}): by "
                                     f"{previous.__module__}.{previous.__qualname__} and "
                                     f"{func.__module__}.{func.__qualname__}")
    extractors = found["claim_extractor"]
    return ClaimFunctions(
        extractors=MappingProxyType(extractors),
        depends_on=MappingProxyType({c: f.claim_depends_on for c, f in extractors.items()}),
        evidence=MappingProxyType(found["claim_evidence"]),
    )
