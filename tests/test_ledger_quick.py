"""The whole ledger on both profiles: every claim keeps its category; the profiles agree.

``tests/ledger_baseline_quick.csv`` and ``tests/ledger_baseline_paper.csv`` record each claim's
category (claim, status) on the two profiles, with the command and date that produced them in
their ``#`` header. The quick test fails with a readable diff when any claim changes category
(in either direction), when a figure's results exist but one of its claims has no extractor
(``evaluate(strict=True)``), and when an extractor is tagged for an id that is not in
claims.csv. After reviewing a change, record it with

    PASSMD_UPDATE_LEDGER_BASELINE=1 pytest tests/test_ledger_quick.py

The paper test evaluates the book's own profile (minutes on two cores with an empty cache: the
whole assumption space) and fails with the same diff; its baseline is recorded with
``passmd ledger --profile paper --overwrite --write-baseline tests/ledger_baseline_paper.csv``.

Both profiles evaluate every claim at the same readings, and the baselines record the claim's state
at each (``states``). Where the quick profile decides a claim at a reading, the paper profile must
decide it the same way: the quick profile may only be inconclusive where its coarser grid cannot
decide (the coarse-grid rule of :mod:`passmd.ledger.rules`). A category is the state at the claim's
held-out reading, which the other claims choose; on the quick grid a claim whose state varies over
its readings while those claims are undecided there is not decided, so quick never decides a row
against the paper profile. Both evaluated ledgers count no more claims as reproduced than hold
together at one point of their space, and the README's held-out count is the paper baseline's.
"""

import datetime
import os
import re
from pathlib import Path

import pytest

from passmd.ledger.claims import load_claims
from passmd.report import evaluation
from passmd.runtime.config import PROFILES, RunConfig

BASELINES = {profile: Path(__file__).with_name(f"ledger_baseline_{profile}.csv")
             for profile in PROFILES}


def _evaluate(profile: str):
    """Every claim evaluated on ``profile`` (strict: a computed figure's claim needs an extractor)."""
    claims = load_claims()
    results = evaluation.collect_results(RunConfig(profile=profile))
    return claims, evaluation.evaluate(claims, results, strict=True)


def _check_baseline(profile: str, claims, evaluated) -> dict[str, str]:
    baseline = evaluation.load_baseline(BASELINES[profile])
    assert set(baseline) == set(claims["id"]), f"the {profile} baseline and claims.csv list different claims"
    evaluation.check_categories(evaluated, baseline)
    return baseline


@pytest.mark.slow
def test_quick_ledger_keeps_every_category():
    claims, evaluated = _evaluate("quick")
    if os.environ.get("PASSMD_UPDATE_LEDGER_BASELINE") == "1":
        header = (f"ledger categories, quick profile; produced {datetime.date.today().isoformat()} by\n"
                  "PASSMD_UPDATE_LEDGER_BASELINE=1 pytest tests/test_ledger_quick.py")
        evaluation.write_baseline(evaluated, BASELINES["quick"], header=header, overwrite=True)
    baseline = _check_baseline("quick", claims, evaluated)
    assert evaluation.orphan_extractors(claims) == [], "extractors tagged for ids not in claims.csv"
    # The claim computed from closed forms needs no figure: a closed-form identity, it holds by construction.
    assert baseline["fig10b-r1-stiffer-contact"] == "holds by construction"
    _one_reading_per_count(evaluated)
    _texts_say_what_they_compare(evaluated)


def _texts_say_what_they_compare(evaluated):
    """Every margin, reason and 'ours' of the ledger names what it compares and carries units: no bare
    'lhs'/'rhs', no 'nan', no number written as the verdict of a grid point ('x = 40')."""
    for row in evaluated.itertuples():
        for text in (row.margin_text, row.why, row.ours_text, row.paper):
            assert not re.search(r"\b(lhs|rhs)\b|\bnan\b|x = ", str(text)), (row.claim, text)

def _one_reading_per_count(evaluated):
    """No category is a union of readings: the claims counted as reproduced (either kind) never outnumber
    the claims holding together at one point of the space, and each holds at the in-sample joint reading."""
    counts = evaluation.headline(evaluated)
    joint = evaluated.attrs["joint"]
    reproduced = counts["reproduced"] + counts["reproduced under the joint reading"]
    assert reproduced <= joint["best_single_point"], (reproduced, joint["best_single_point"])
    assert reproduced + len(joint["in_sample_gain"]) == joint["holding"]
    rows = evaluation.counted(evaluated)
    held = rows[rows["status"].isin(("reproduced", "reproduced under the joint reading"))]
    assert (held["held_out_state"] == "holds").all() and (held["joint_state"] == "holds").all()


@pytest.mark.slow
def test_paper_ledger_keeps_every_category():
    """The book's profile decides every claim as its baseline records: a change of the integrator,
    a grid or a protocol that flips a verdict of the book fails here, not only in a rebuild."""
    claims, evaluated = _evaluate("paper")
    _check_baseline("paper", claims, evaluated)
    _one_reading_per_count(evaluated)


def profile_comparison() -> tuple[list[str], dict[str, str]]:
    """Claims the two baselines can be compared on, and the rest with why they cannot.

    A claim is comparable when both baselines record it at the same readings (their ``readings``
    column): both profiles compute every claim on the full product of its axes, so every claim is.
    """
    quick_readings, paper_readings = (evaluation.load_baseline_readings(BASELINES[p])
                                      for p in ("quick", "paper"))
    assert quick_readings and paper_readings, "a baseline does not record its readings"
    comparable, not_recorded = [], {}
    for claim, readings in quick_readings.items():
        if claim not in paper_readings:
            not_recorded[claim] = "not in the paper baseline"
        elif set(readings) != set(paper_readings[claim]):
            extra = sorted(set(readings) ^ set(paper_readings[claim]))
            not_recorded[claim] = "the baselines differ in the readings " + "; ".join(extra)
        else:
            comparable.append(claim)
    return comparable, not_recorded


#: The categories that decide a claim.
DECIDED = ("reproduced", "reproduced under the joint reading", "holds by construction", "not reproduced")


def test_profiles_agree_or_quick_is_inconclusive():
    """Every state the quick baseline decides, at every reading of every claim, is the paper
    baseline's there; both record every claim at the same readings (the whole product of its axes,
    on either profile). Categories: quick never decides a row against the paper profile, a row is
    decided alike on both or 'not decided on the quick grid' (inconclusive) on quick."""
    quick, paper = (evaluation.load_baseline(BASELINES[p]) for p in ("quick", "paper"))
    assert set(paper) == set(quick), "the two baselines list different claims"
    comparable, not_recorded = profile_comparison()
    assert not not_recorded, not_recorded
    states = {p: evaluation.load_baseline_states(BASELINES[p]) for p in ("quick", "paper")}
    assert states["quick"] and states["paper"], "a baseline does not record its states"
    disagree, decided = [], 0
    for claim in comparable:
        q, p = states["quick"][claim], states["paper"][claim]
        for reading, state in q["states"].items():
            if state != "inconclusive":
                decided += 1
                if p["states"][reading] != state:
                    disagree.append(f"{claim} at {reading}: quick {state}, paper {p['states'][reading]}")
        if quick[claim] in DECIDED and paper[claim] != quick[claim]:
            disagree.append(f"{claim}: quick {quick[claim]!r}, paper {paper[claim]!r}")
    assert not disagree, "profiles disagree:\n  " + "\n  ".join(disagree)
    total = sum(len(states["quick"][c]["states"]) for c in comparable)
    assert decided >= total // 4, f"the quick profile decides only {decided} of {total} claim readings"


def test_the_readme_states_the_paper_baselines_held_out_count():
    """The README's ledger paragraph states the held-out count of the paper profile, as its baseline
    records it (each family once, studies and implied rows left out)."""
    claims = load_claims().set_index("id")
    paper = evaluation.load_baseline(BASELINES["paper"])
    counted = [c for c in paper if c in claims.index and not claims.at[c, "study_of"]
               and not claims.at[c, "implied_by"]]
    status = [paper[c] for c in counted]
    reproduced = sum(s in ("reproduced", "reproduced under the joint reading") for s in status)
    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text(encoding="utf-8")
    found = re.search(r"reproduces (\d+) of its (\d+) claims[^.]*?(\d+) hold by construction, (\d+) are not "
                      r"reproduced and (\d+) inconclusive", re.sub(r"\s+", " ", readme))
    assert found, "the README does not state the ledger's held-out count"
    expected = [reproduced, len(counted), status.count("holds by construction"),
                status.count("not reproduced"), status.count("inconclusive")]
    assert [int(g) for g in found.groups()] == expected


def test_baselines_say_how_they_were_made():
    for profile, path in BASELINES.items():
        header = [line for line in path.read_text(encoding="utf-8").splitlines() if line.startswith("#")]
        assert any(profile in line for line in header), f"{path.name} does not name its profile"
        assert any("produced" in line for line in header), f"{path.name} does not say how it was made"
