"""One claim over its readings: the check at each reading, the category, the verdict line.

The ledger (:func:`passmd.ledger.evaluate`) calls :func:`claim_row` for every claim: the
claim's extractor is run at each reading of :func:`passmd.readings.design` for the axes it
depends on (the defaults first) and its check applied (:func:`passmd.checks.check_claim`);
the category follows from those points (:func:`_categorise`), with the computed evidence.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from passmd import readings
from passmd.checks import (
    ORDERING_SYMBOLS,
    ClaimFails,
    ClaimFunctions,
    ExtractorError,
    NotEvaluable,
    Outcome,
    check_claim,
    format_number,
)
from passmd.claims import tolerance_text

__all__ = ["NO_EXTRACTOR", "PointResult", "claim_row", "shown"]


def _paper_text(claim: Mapping) -> str:
    kind, relation = claim["check"], claim["relation"]
    if kind == "value":
        if claim["paper_value"]:
            return claim["paper_value"]
        filename, _, column = claim["reference"].partition(":")
        return f"curve {column} ({filename})"
    if kind == "ordering":
        return f"lhs {ORDERING_SYMBOLS[relation]} rhs"
    if kind == "threshold":
        return f"{relation.replace('_', ' ')} {claim['paper_value']}"
    return relation


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
        outcome = check_claim(claim, ours)
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


def _evidence(claim: Mapping, points: list[PointResult], results, func: Callable | None) -> list[str]:
    """Computed evidence: the check at every reading, then the claim's own evidence function."""
    lines = []
    for p in points:
        ours = "" if p.outcome is None else f"ours {shown(p.outcome.ours)}{_unit(claim)}; "
        lines.append(f"{readings.describe(p.reading)}: {p.state} ({ours}{p.detail})")
    if func is not None:
        try:
            lines.extend(func(results))
        except NotEvaluable as reason:
            lines.append(f"evidence not available on these results: {reason}")
        except KeyError as missing:
            lines.append(f"evidence needs results: {missing}")
    return lines


def shown(value) -> str:
    """An ``ours`` value as the ledger shows it (numbers with 4 significant digits)."""
    return format_number(value) if isinstance(value, float) else str(value)


def _unit(claim: Mapping) -> str:
    return f" {claim['unit']}" if claim["unit"] and claim["check"] == "value" else ""


#: The verdict of a claim whose results are present but no extractor is tagged for it.
NO_EXTRACTOR = "no extractor registered"


def claim_row(claim: Mapping, results, functions: ClaimFunctions) -> tuple[dict, list[PointResult]]:
    """One claim's ledger row (:data:`passmd.ledger.LEDGER_COLUMNS`) and its points (empty when
    the claim is not evaluated: results missing, or no extractor)."""
    needed = [k for k in claim["requires"].split(";") if k]
    missing = [k for k in needed if k not in results]
    basis = "closed form" if set(needed) <= {"closed_forms"} else "simulation"
    depends = functions.depends_on.get(claim["id"], ())
    points: list[PointResult] = []
    if missing:
        status, verdict, evidence = "inconclusive", "needs results: " + ", ".join(missing), []
    elif claim["id"] not in functions.extractors:
        status, verdict, evidence = "inconclusive", NO_EXTRACTOR, []
    else:
        func = functions.extractors[claim["id"]]
        points = [_evaluate_point(claim, func, depends, results, r) for r in readings.design(depends)]
        status, verdict = _categorise(points)
        if status == "reproduced":
            verdict = _passed_verdict(claim, points[0].outcome) + " at the defaults"
        evidence = _evidence(claim, points, results, functions.evidence.get(claim["id"]))
    default = points[0].outcome if points else None
    decided = [p for p in points if p.state != "inconclusive"]
    best = _best(points)
    row = {
        "claim": claim["id"], "figure": claim["figure"], "quantity": claim["quantity"],
        "paper": _paper_text(claim), "ours": "—" if default is None else default.ours,
        "unit": claim["unit"],
        "abs_deviation": math.nan if default is None else default.abs_deviation,
        "rel_deviation": math.nan if default is None else default.rel_deviation,
        "tolerance": tolerance_text(claim), "status": status, "verdict": verdict,
        "evidence": " | ".join(evidence), "reason": claim["reason"], "basis": basis,
        "check": claim["check"], "depends_on": ";".join(depends), "readings": len(points),
        "holds_at": sum(p.state == "holds" for p in points),
        "fraction_holds": (sum(p.state == "holds" for p in decided) / len(decided)
                           if decided else math.nan),
        "best_reading": "—" if best is None else readings.describe(best.reading),
        "note": points[0].detail if points else verdict,
    }
    return row, points
