"""One claim over its readings: the check at each reading, the category, the verdict line.

The ledger (:func:`passmd.report.evaluation.evaluate`) calls :func:`claim_points` for every claim: the
claim's extractor is run at each reading of :func:`passmd.ledger.readings.design` (the full product of
the axes it depends on, the defaults first) and its check applied
(:func:`passmd.ledger.checks.check_claim`). Once the joint reading of all claims is known,
:func:`claim_row` gives the category from two points only, the defaults and the joint reading
(:func:`_categorise`), with the margin, the fail count, the fragile and informative flags and
the computed evidence.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from passmd.ledger import readings
from passmd.ledger.checks import (
    ORDERING_SYMBOLS,
    ClaimFails,
    ClaimFunctions,
    ExtractorError,
    NoRun,
    NotEvaluable,
    Outcome,
    Scoped,
    Subset,
    check_claim,
    format_number,
)
from passmd.ledger.claims import required_keys, tolerance_text
from passmd.ledger.rules import FRAGILE_MARGIN

__all__ = ["EXPERIMENT_BASIS", "NO_EXTRACTOR", "PointResult", "claim_points", "claim_row", "decisive_point",
           "fragility", "not_informative", "point_at", "shown"]


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
    """One claim at one reading: ``holds``, ``fails`` or ``inconclusive``, with what was found.

    ``outside``: the method the deciding data lie outside of (:class:`passmd.ledger.checks.Scoped`);
    ``no_run``: the tables hold no run at this reading (a defect, :class:`passmd.ledger.checks.NoRun`).
    """

    reading: dict
    state: str  # "holds", "fails", "inconclusive"
    outcome: Outcome | None
    detail: str
    outside: str = ""
    no_run: bool = False

    @property
    def decided(self) -> bool:
        return self.state in ("holds", "fails")


def _evaluate_point(claim: Mapping, func: Callable, depends: tuple, results, reading: dict) -> PointResult:
    subset = None
    try:
        ours = func(results, reading) if depends else func(results)
        outside = ""
        while isinstance(ours, (Subset, Scoped)):
            if isinstance(ours, Subset):
                subset = ours
            else:
                outside = ours.outside
            ours = ours.ours
        outcome = check_claim(claim, ours)
    except NoRun as reason:
        return PointResult(reading, "inconclusive", None, f"no run: {reason}", no_run=True)
    except NotEvaluable as reason:
        return PointResult(reading, "inconclusive", None, str(reason))
    except ClaimFails as reason:
        return PointResult(reading, "fails", None, str(reason), reason.outside)
    except Exception as err:
        raise ExtractorError(f"claim {claim['id']!r} ({claim['check']} check) at "
                             f"{readings.describe(reading)}: {err!r}") from err
    if subset is not None and (outcome.passed or not subset.failures_decide):
        verb = "holds" if outcome.passed else "fails"
        return PointResult(reading, "inconclusive", None, f"{verb} on this table's part of the grid "
                           f"({outcome.detail}), which lacks {subset.missing}")
    state = "holds" if outcome.passed else "fails"
    return PointResult(reading, state, outcome, outcome.detail, outside)


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


def point_at(points: list[PointResult], depends: tuple, reading: Mapping) -> PointResult | None:
    """The claim's point giving its state at ``reading`` of the whole space (its projection onto
    the axes the claim is evaluated along); None when its design has no such point."""
    keys = {k for k in depends if len({p.reading[k] for p in points}) > 1} if points else set()
    target = readings.project(reading, keys)
    return next((p for p in points if all(p.reading[k] == target[k] for k in keys)), None)


def _categorise(default: PointResult, joint: PointResult | None, elsewhere: str = "") -> tuple[str, str]:
    """Category and one-line verdict from two points only: the defaults and the joint reading.

    * ``reproduced``: holds at the defaults;
    * ``reproduced under the joint reading``: does not hold at the defaults, holds at the joint reading;
    * ``not reproduced``: fails at the defaults or at the joint reading, holding at neither (a failure
      is never turned into *inconclusive* because the other point is undecided);
    * ``inconclusive``: neither point decides it.

    ``elsewhere`` says where else the claim holds and what that reading breaks (evidence only).
    """
    joint = default if joint is None else joint
    same = joint is default
    if default.state == "holds":
        tail = ("" if same or joint.state == "holds"
                else f"; {joint.state} at the joint reading ({joint.detail})")
        return "reproduced", "holds at the defaults" + tail
    if joint.state == "holds":
        return ("reproduced under the joint reading",
                f"{default.state} at the defaults ({default.detail}); holds at the joint reading")
    if "fails" in (default.state, joint.state):
        where = ("at the defaults" if same else
                 "at the defaults and at the joint reading" if default.state == joint.state == "fails" else
                 "at the defaults; the joint reading does not decide it" if default.state == "fails" else
                 "at the joint reading; the defaults do not decide it")
        detail = default.detail if default.state == "fails" else joint.detail
        return "not reproduced", f"fails {where} ({detail})" + (f"; {elsewhere}" if elsewhere else "")
    where = "at the defaults" if same else "at the defaults or the joint reading"
    return "inconclusive", f"not decided {where}: {default.detail}" + (f"; {elsewhere}" if elsewhere else "")


def _evidence(claim: Mapping, points: list[PointResult], results, func: Callable | None) -> list[str]:
    """Computed evidence: the check at every reading, then the claim's own evidence function."""
    lines = []
    for p in points:
        ours = "" if p.outcome is None else f"ours {shown(p.outcome.ours)}{_unit(claim)}; "
        where = f"; decided only where {p.outside}" if p.outside else ""
        lines.append(f"{readings.describe(p.reading)}: {p.state} ({ours}{p.detail}{where})")
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


def claim_points(claim: Mapping, results, functions: ClaimFunctions) -> tuple[list[PointResult], str]:
    """A claim's results at every reading of its :func:`passmd.ledger.readings.design` (defaults first),
    or no points and why it is not evaluated (results missing, no extractor)."""
    needed = required_keys(claim)
    missing = [k for k in needed if k not in results]
    if missing:
        return [], "needs results: " + ", ".join(missing)
    if claim["id"] not in functions.extractors:
        return [], NO_EXTRACTOR
    func = functions.extractors[claim["id"]]
    depends = functions.depends_on.get(claim["id"], ())
    return [_evaluate_point(claim, func, depends, results, r) for r in readings.design(depends)], ""


def not_informative(functions: ClaimFunctions, claim_id: str) -> str:
    """Why a claim's check cannot fail on any result (its extractor's ``not_informative``), or ``""``."""
    func = functions.extractors.get(claim_id)
    return str(getattr(func, "not_informative", "") or "") if func is not None else ""


#: The basis of a claim about the experiment of [12] (:mod:`passmd.ledger.rules`).
EXPERIMENT_BASIS = "experiment (no measured data)"


def _margin(claim: Mapping, outcome: Outcome | None) -> tuple[float, str]:
    """The margin at a point: the check's ratio against its tolerance (≤ 1 within it) where the check
    has a tolerance, else its score (how far from holding, 0 when it holds), and in words."""
    if outcome is None:
        return math.nan, "—"
    if math.isfinite(outcome.ratio):
        relative = claim["check"] == "value" and claim["tolerance_kind"] == "rel"
        if relative and math.isfinite(outcome.rel_deviation):
            return float(outcome.ratio), f"{outcome.rel_deviation:.1%} against {tolerance_text(claim)}"
        return float(outcome.ratio), f"{outcome.ratio:.2f} of the tolerance ({tolerance_text(claim)})"
    if not math.isfinite(outcome.score):
        return math.nan, "—"
    return float(outcome.score), ("holds" if outcome.passed else f"{outcome.score:.3g} from holding")


def decisive_point(status: str, default: PointResult, joint: PointResult | None) -> PointResult | None:
    """The point that decides a category: the defaults for *reproduced* and for a failure at the
    defaults, the joint reading otherwise; None for *inconclusive*."""
    if status == "inconclusive":
        return None
    if status == "reproduced" or (status == "not reproduced" and default.state == "fails") or joint is None:
        return default
    return joint


def fragility(status: str, decisive: PointResult | None, runner_ups: list[tuple[str, PointResult | None]],
              margin_ratio: float) -> str:
    """Why a verdict is fragile (:mod:`passmd.ledger.rules`), or ``""``.

    (1) The claim holds at the decisive point but not at a runner-up reading, or the other way
    round (``runner_ups``: ``(reading in words, the claim's point there)``; undecided points do not
    flip it); (2) its margin ratio there (deviation over tolerance) is within ``FRAGILE_MARGIN`` of 1.
    """
    if decisive is None or not decisive.decided:
        return ""
    reasons = []
    flips = [name for name, p in runner_ups
             if p is not None and p.decided and (p.state == "holds") != (decisive.state == "holds")]
    if flips:
        verb = "fails" if decisive.state == "holds" else "holds"
        reasons.append(f"{verb} at the runner-up reading {flips[0]}"
                       + (f" and {len(flips) - 1} more" if len(flips) > 1 else ""))
    if math.isfinite(margin_ratio) and abs(margin_ratio - 1.0) < FRAGILE_MARGIN:
        reasons.append(f"its margin is {margin_ratio:.2f} of the tolerance, within {FRAGILE_MARGIN:.0%} "
                       "of it")
    return "; ".join(reasons)


def claim_row(claim: Mapping, results, functions: ClaimFunctions, *, joint: Mapping | None = None,
              runner_ups: tuple = (), points: list[PointResult] | None = None,
              elsewhere: str = "") -> tuple[dict, list[PointResult]]:
    """One claim's ledger row (:data:`passmd.report.evaluation.LEDGER_COLUMNS`) and its points (empty when
    the claim is not evaluated: results missing, or no extractor).

    ``joint`` is the joint reading of the whole space (default: the defaults) and ``runner_ups``
    its runner-up readings (fragility, :mod:`passmd.ledger.rules`); ``points`` the claim's
    :func:`claim_points` when already computed; ``elsewhere`` what the claim's best other reading
    breaks (for the verdict of a claim that is not reproduced).
    """
    needed = required_keys(claim)
    basis = ("closed form" if set(needed) <= {"closed_forms"}
             else EXPERIMENT_BASIS if claim["id"] in functions.experiment else "simulation")
    depends = functions.depends_on.get(claim["id"], ())
    why = ""
    if points is None:
        points, why = claim_points(claim, results, functions)
    joint_point = decisive = None
    if not points:
        status, verdict, evidence = "inconclusive", why or NO_EXTRACTOR, []
    else:
        joint_point = point_at(points, depends, joint or readings.default_reading())
        status, verdict = _categorise(points[0], joint_point, elsewhere)
        if status == "reproduced":
            verdict = (_passed_verdict(claim, points[0].outcome) + " at the defaults"
                       + verdict[len("holds at the defaults"):])
        decisive = decisive_point(status, points[0], joint_point)
        if decisive is not None and decisive.outside:
            verdict += f"; decided only where {decisive.outside}"
        evidence = _evidence(claim, points, results, functions.evidence.get(claim["id"]))
    default = points[0].outcome if points else None
    decided = [p for p in points if p.decided]
    fails_at = sum(p.state == "fails" for p in decided)
    best = _best(points)
    margin, margin_text = _margin(claim, None if decisive is None else decisive.outcome)
    ratio = decisive.outcome.ratio if decisive is not None and decisive.outcome is not None else math.nan
    fragile_reason = fragility(status, decisive, [(readings.describe(r), point_at(points, depends, r))
                                                  for r in runner_ups] if points else [], ratio)
    reason_not = not_informative(functions, claim["id"])
    joint_state = "—" if joint_point is None else joint_point.state
    row = {
        "claim": claim["id"], "figure": claim["figure"], "quantity": claim["quantity"],
        "paper": _paper_text(claim), "ours": "—" if default is None else default.ours,
        "unit": claim["unit"],
        "abs_deviation": math.nan if default is None else default.abs_deviation,
        "rel_deviation": math.nan if default is None else default.rel_deviation,
        "tolerance": tolerance_text(claim), "status": status, "verdict": verdict,
        "evidence": " | ".join(evidence), "reason": claim["reason"], "basis": basis,
        "study_of": claim.get("study_of", ""),
        "check": claim["check"], "depends_on": ";".join(depends), "readings": len(points),
        "holds_at": sum(p.state == "holds" for p in points),
        "fails_at": fails_at, "decided_at": len(decided),
        "fraction_holds": (sum(p.state == "holds" for p in decided) / len(decided)
                           if decided else math.nan),
        "best_reading": "—" if best is None else readings.describe(best.reading),
        "default_state": points[0].state if points else "—", "joint_state": joint_state,
        "margin": margin, "margin_text": margin_text, "fragile": bool(fragile_reason),
        "fragile_reason": fragile_reason,
        "outside": "" if decisive is None else decisive.outside,
        "informative": not reason_not, "not_informative": reason_not,
        "note": points[0].detail if points else verdict,
    }
    return row, points
