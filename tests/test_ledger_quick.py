"""The whole ledger at the quick profile: every claim keeps its category; the profiles agree.

``tests/ledger_baseline_quick.csv`` and ``tests/ledger_baseline_paper.csv`` record each claim's
category (claim, status) on the two profiles, with the command and date that produced them in
their ``#`` header. The quick test fails with a readable diff when any claim changes category
(in either direction), when a figure's results exist but one of its claims has no extractor
(``evaluate(strict=True)``), and when an extractor is registered for an id that is not in
claims.csv. After reviewing a change, record it with

    PASSMD_UPDATE_LEDGER_BASELINE=1 pytest tests/test_ledger_quick.py

A claim's category must not depend on the profile: where the quick profile decides a claim,
the paper profile must decide it the same way; the quick profile may only be inconclusive
where its coarser grid cannot decide.
"""

import datetime
import os
from pathlib import Path

import pytest

from passmd import ledger

BASELINES = {profile: Path(__file__).with_name(f"ledger_baseline_{profile}.csv")
             for profile in ledger.PROFILES}


@pytest.mark.slow
def test_quick_ledger_keeps_every_category():
    claims = ledger.load_claims()
    evaluated = ledger.evaluate(claims, ledger.collect_results("quick"), strict=True)
    if os.environ.get("PASSMD_UPDATE_LEDGER_BASELINE") == "1":
        header = (f"ledger categories, quick profile; produced {datetime.date.today().isoformat()} by\n"
                  "PASSMD_UPDATE_LEDGER_BASELINE=1 pytest tests/test_ledger_quick.py")
        ledger.write_baseline(evaluated, BASELINES["quick"], header=header)
    baseline = ledger.load_baseline(BASELINES["quick"])
    assert set(baseline) == set(claims["id"]), "the baseline and claims.csv list different claims"
    ledger.check_categories(evaluated, baseline)
    assert ledger.orphan_extractors(claims) == [], "extractors registered for ids not in claims.csv"
    # The claim computed from closed forms needs no figure: it must always be reproduced.
    assert baseline["fig10b-r1-stiffer-contact"] == "reproduced"


def test_profiles_agree_or_quick_is_inconclusive():
    """Every claim the quick baseline decides has the same category in the paper baseline."""
    quick, paper = (ledger.load_baseline(BASELINES[p]) for p in ("quick", "paper"))
    assert set(quick) == set(paper), "the two baselines list different claims"
    disagree = [f"{claim}: quick {quick[claim]!r}, paper {paper[claim]!r}" for claim in quick
                if quick[claim] != "inconclusive" and quick[claim] != paper[claim]]
    assert not disagree, "profiles disagree:\n  " + "\n  ".join(disagree)


def test_baselines_say_how_they_were_made():
    for profile, path in BASELINES.items():
        header = [line for line in path.read_text(encoding="utf-8").splitlines() if line.startswith("#")]
        assert any(profile in line for line in header), f"{path.name} does not name its profile"
        assert any("produced" in line for line in header), f"{path.name} does not say how it was made"
