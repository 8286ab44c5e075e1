"""One claim over its readings: the check at each reading, the category, the verdict line.

The ledger (:func:`passmd.report.evaluation.evaluate`) calls :func:`claim_points` for every claim: the
claim's extractor is run at each reading of :func:`passmd.ledger.readings.design` (the full product of
the axes it depends on, the defaults first) and its check applied
(:func:`passmd.ledger.checks.check_claim`). Once every claim's held-out reading is known
(:mod:`passmd.ledger.joint`), :func:`claim_row` gives the category from that one reading
(:func:`category`), with the margin, the counts of holding, failing and undecided readings, the
fragile and informative flags and the computed evidence.
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
    CoarseGrid,
    ExtractorError,
    NoRun,
    NotEvaluable,
    Outcome,
    Scoped,
    Subset,
    check_claim,
    compared_names,
    format_number,
)
from passmd.ledger.claims import REPRODUCED, required_keys, tolerance_text
from passmd.ledger.rules import FRAGILE_MARGIN

__all__ = ["COARSE_GRID", "EXPERIMENT_BASIS", "NO_EXTRACTOR", "PointResult", "category", "claim_points",
           "claim_row", "fragility", "not_informative", "point_at", "shown"]

#: The verdict of a claim whose held-out reading rests on claims a coarse grid leaves undecided.
COARSE_GRID = "not decided on a grid coarser than the paper's"


def _paper_text(claim: Mapping) -> str:
    kind, relation = claim["check"], claim["relation"]
    unit = f" {claim['unit']}" if claim["unit"] and claim["unit"] != "%" else (" %" if claim["unit"] else "")
    if kind == "value":
        if claim["paper_value"]:
            return claim["paper_value"] + unit
        filename, _, column = claim["reference"].partition(":")
        return f"curve {column} ({filename})"
    if kind == "ordering":
        if not claim.get("compares"):
            return claim["quantity"]
        left, right = compared_names(claim)
        return f"{left} {ORDERING_SYMBOLS[relation]} {right}"
    if kind == "threshold":
        return f"{relation.replace('_', ' ')} {claim['paper_value']}{unit}"
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
    ``no_run``: the tables hold no run at this reading (a defect, :class:`passmd.ledger.checks.NoRun`);
    ``coarse``: undecided because the table lacks points of the paper's grid
    (:class:`passmd.ledger.checks.Subset`, :class:`passmd.ledger.checks.CoarseGrid`).
    """

    reading: dict
    state: str  # "holds", "fails", "inconclusive"
    outcome: Outcome | None
    detail: str
    outside: str = ""
    no_run: bool = False
    coarse: bool = False

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
    except CoarseGrid as reason:
        return PointResult(reading, "inconclusive", None, str(reason), coarse=True)
    except NotEvaluable as reason:
        return PointResult(reading, "inconclusive", None, str(reason), coarse=subset is not None)
    except ClaimFails as reason:
        return PointResult(reading, "fails", None, str(reason), reason.outside)
    except Exception as err:
        raise ExtractorError(f"claim {claim['id']!r} ({claim['check']} check) at "
                             f"{readings.describe(reading)}: {err!r}") from err
    if subset is not None and (outcome.passed or not subset.failures_decide):
        verb = "holds" if outcome.passed else "fails"
        return PointResult(reading, "inconclusive", None, f"{verb} on this table's part of the grid "
                           f"({outcome.detail}), which lacks {subset.missing}", coarse=True)
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
    """The claim's point giving its state at ``reading`` (``{axis key: value}``; its projection onto the
    axes the claim is evaluated along); None when its design has no such point."""
    keys = {k for k in depends if len({p.reading[k] for p in points}) > 1} if points else set()
    target = readings.project(reading, keys)
    return next((p for p in points if all(p.reading[k] == target[k] for k in keys)), None)


def category(state: str, at_defaults: str, informative: bool = True) -> str:
    """The category of a claim (or a family) judged at its held-out reading, where its state is
    ``state``, ``at_defaults`` its state at the defaults:

    * ``holds by construction``: it holds and its check cannot fail on any result the model can
      produce (not informative): never counted as reproduced;
    * ``reproduced``: it holds there and at the defaults;
    * ``reproduced under the joint reading``: it holds there, not at the defaults (it rests on a
      reading of what the paper leaves open, chosen without it);
    * ``not reproduced``: it fails there;
    * ``inconclusive``: it is undecided there (tied, degenerate, missing data): never reproduced.
    """
    if state == "holds":
        if not informative:
            return "holds by construction"
        return "reproduced" if at_defaults == "holds" else "reproduced under the joint reading"
    return "not reproduced" if state == "fails" else "inconclusive"


def _evidence(claim: Mapping, points: list[PointResult], results, func: Callable | None) -> list[str]:
    """Computed evidence: the check at every reading, then the claim's own evidence function."""
    lines = []
    for p in points:
        ours = "" if p.outcome is None else f"ours {_ours_text(claim, p.outcome)}; "
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


def _ours_text(claim: Mapping, outcome: Outcome) -> str:
    """``ours`` with its unit, as the check wrote it (e.g. ``"17.41 nm vs 23.13 nm"``)."""
    if outcome.text:
        return outcome.text
    unit = claim["unit"] if isinstance(outcome.ours, float) else ""
    return f"{shown(outcome.ours)} {unit}".strip()


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
    """The margin at a point, as a number (the check's ratio against its tolerance, ≤ 1 within it, where
    the check has one; else the share of its points that fail) and in words with units and what it
    compares."""
    if outcome is None:
        return math.nan, "—"
    unit, ratio = claim["unit"], float(outcome.ratio)
    if claim["check"] == "value":
        if claim["tolerance_kind"] == "rel" and math.isfinite(outcome.rel_deviation):
            return ratio, f"{outcome.rel_deviation:.1%} off the paper, tolerance {tolerance_text(claim)}"
        return ratio, (f"off by {format_number(outcome.abs_deviation)} {unit}, tolerance "
                       f"{tolerance_text(claim)}")
    if claim["check"] == "threshold" and math.isfinite(outcome.abs_deviation):
        return ratio, (f"switch {outcome.text}: {format_number(outcome.abs_deviation)} {unit} from the "
                       f"paper's {claim['paper_value']} {unit}, tolerance {tolerance_text(claim)}")
    if claim["check"] == "trend" and math.isfinite(ratio):
        return ratio, f"{ratio:.2f} times the allowance {tolerance_text(claim)} ({outcome.detail})"
    if math.isfinite(ratio):
        return ratio, (f"|{' − '.join(compared_names(claim))}| is {ratio:.2f} times the tolerance "
                       f"{tolerance_text(claim)}")
    if not math.isfinite(outcome.score):
        return math.nan, "—"
    return float(outcome.score), outcome.detail


def fragility(status: str, decisive: PointResult | None, runner_ups: list[tuple[str, PointResult | None]],
              margin_ratio: float) -> str:
    """Why a verdict is fragile (:mod:`passmd.ledger.rules`), or ``""``.

    (1) The claim holds at the decisive point (its held-out reading) but not at a runner-up reading, or
    the other way round (``runner_ups``: ``(reading in words, the claim's point there)``; undecided points
    do not flip it); (2) its margin ratio there (deviation over tolerance) is within ``FRAGILE_MARGIN``
    of 1.
    """
    if decisive is None or not decisive.decided or status == "inconclusive":
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


@dataclass(frozen=True)
class Judgement:
    """Where and how the ledger judges one claim (:func:`passmd.ledger.joint.judge`): its held-out
    reading and state, its in-sample state, its family's category (for the row counted for a family)
    and whether its reading rests on claims a coarse grid leaves undecided."""

    held_out: dict  # the claim's reading ({axis key: value}) at its held-out point
    in_sample: dict  # at the in-sample joint reading
    family_state: str = ""  # the family's state at the held-out reading (the lead row of a family)
    family_at_defaults: str = ""  # the family's state at the defaults
    family: tuple = ()  # the family's members, the lead first (empty for a claim implied by none)
    counted: bool = True
    grid_bound: bool = False
    elsewhere: str = ""
    runner_ups: tuple = ()  # the in-sample reading's runner-ups, as the claim's readings


def _verdict(claim: Mapping, status: str, held: PointResult, default: PointResult, judged: Judgement,
             in_sample: PointResult | None, reason_not: str) -> str:
    where = readings.describe(judged.held_out)
    at = "at its held-out reading" + ("" if where == "defaults" else f" ({where})")
    if judged.grid_bound:
        text = f"{COARSE_GRID}: {held.state} {at} ({held.detail}), but the claims that choose that reading"
        return text + " are undecided there on this grid"
    if status == "holds by construction":
        text = f"holds {at}, by construction: {reason_not}"
    elif status in REPRODUCED:
        text = (_passed_verdict(claim, held.outcome) if held.outcome is not None else "holds") + f" {at}"
        text += "" if status == "reproduced" else f"; {default.state} at the defaults ({default.detail})"
    elif status == "not reproduced":
        text = f"fails {at} ({held.detail})" + (f"; {judged.elsewhere}" if judged.elsewhere else "")
    else:
        text = f"not decided {at}: {held.detail}" + (f"; {judged.elsewhere}" if judged.elsewhere else "")
    if judged.family and judged.family_state and judged.family_state != held.state:
        text += f"; its family ({', '.join(judged.family[1:])}) {judged.family_state} there"
    if in_sample is not None and in_sample.state != held.state:
        text += f"; {in_sample.state} in-sample, at the joint reading chosen with it"
    return text


def claim_row(claim: Mapping, results, functions: ClaimFunctions, *, judged: Judgement | None = None,
              points: list[PointResult] | None = None) -> tuple[dict, list[PointResult]]:
    """One claim's ledger row (:data:`passmd.report.evaluation.LEDGER_COLUMNS`) and its points (empty when
    the claim is not evaluated: results missing, or no extractor).

    ``judged`` says where it is judged (default: at the defaults, counted, no family: a study);
    ``points`` the claim's :func:`claim_points` when already computed.
    """
    judged = judged or Judgement(readings.default_reading(), readings.default_reading())
    needed = required_keys(claim)
    basis = ("closed form" if set(needed) <= {"closed_forms"}
             else EXPERIMENT_BASIS if claim["id"] in functions.experiment else "simulation")
    depends = functions.depends_on.get(claim["id"], ())
    reason_not = not_informative(functions, claim["id"])
    why = ""
    if points is None:
        points, why = claim_points(claim, results, functions)
    held = in_sample = None
    if not points:
        status, verdict, evidence, reason = "inconclusive", why or NO_EXTRACTOR, [], why or NO_EXTRACTOR
    else:
        held = point_at(points, depends, judged.held_out) or points[0]
        in_sample = point_at(points, depends, judged.in_sample)
        state, at_defaults = held.state, points[0].state
        if judged.family_state:
            state, at_defaults = judged.family_state, judged.family_at_defaults
        status = "inconclusive" if judged.grid_bound else category(state, at_defaults, not reason_not)
        verdict = _verdict(claim, status, held, points[0], judged, in_sample, reason_not)
        if held.outside:
            verdict += f"; decided only where {held.outside}"
        evidence = _evidence(claim, points, results, functions.evidence.get(claim["id"]))
        reason = (COARSE_GRID if judged.grid_bound else
                  f"by construction: {reason_not}" if status == "holds by construction" else held.detail)
    decided = [p for p in points if p.decided]
    outcome = None if held is None else held.outcome
    best = _best(points)
    margin, margin_text = _margin(claim, outcome)
    ratio = outcome.ratio if outcome is not None else math.nan
    fragile_reason = fragility(status, held, [(readings.describe(r), point_at(points, depends, r))
                                              for r in judged.runner_ups] if points else [], ratio)
    row = {
        "claim": claim["id"], "figure": claim["figure"], "quantity": claim["quantity"],
        "paper": _paper_text(claim), "ours": "—" if outcome is None else outcome.ours,
        "ours_text": "—" if outcome is None else _ours_text(claim, outcome),
        "unit": claim["unit"],
        "abs_deviation": math.nan if outcome is None else outcome.abs_deviation,
        "rel_deviation": math.nan if outcome is None else outcome.rel_deviation,
        "tolerance": tolerance_text(claim), "status": status, "verdict": verdict, "why": reason,
        "evidence": " | ".join(evidence), "reason": claim["reason"], "basis": basis,
        "study_of": claim.get("study_of", ""), "family": judged.family[0] if judged.family else "",
        "counted": bool(judged.counted),
        "check": claim["check"], "depends_on": ";".join(depends), "readings": len(points),
        "holds_at": sum(p.state == "holds" for p in points),
        "fails_at": sum(p.state == "fails" for p in points), "decided_at": len(decided),
        "undecided_at": len(points) - len(decided),
        "fraction_holds": (sum(p.state == "holds" for p in decided) / len(decided)
                           if decided else math.nan),
        "best_reading": "—" if best is None else readings.describe(best.reading),
        "default_state": points[0].state if points else "—",
        "held_out_reading": readings.describe(judged.held_out) if points else "—",
        "held_out_state": held.state if held is not None else "—",
        "joint_reading": readings.describe(judged.in_sample) if points else "—",
        "joint_state": "—" if in_sample is None else in_sample.state,
        "margin": margin, "margin_text": margin_text, "fragile": bool(fragile_reason),
        "fragile_reason": fragile_reason, "outside": "" if held is None else held.outside,
        "informative": not reason_not, "not_informative": reason_not,
        "note": points[0].detail if points else verdict,
    }
    return row, points
