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

BASELINES = {"quick": Path(__file__).with_name("ledger_baseline_quick.csv")}


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
