"""The whole ledger at the quick profile: every available figure evaluated, no verdict regressed.

``tests/ledger_baseline_quick.csv`` records each claim's status (claim, status). The test fails
when a claim the baseline records as ``reproduced`` is no longer reproduced (or was removed),
when a figure's results exist but one of its claims has no extractor (``evaluate(strict=True)``),
and when an extractor is registered for an id that is not in claims.csv. Improvements don't
fail; record them (after reviewing the diff) with

    PASSMD_UPDATE_LEDGER_BASELINE=1 pytest tests/test_ledger_quick.py
"""

import os
from pathlib import Path

import pytest

from passmd import ledger

BASELINE = Path(__file__).with_name("ledger_baseline_quick.csv")


@pytest.mark.slow
def test_quick_ledger_has_no_regressions():
    claims = ledger.load_claims()
    evaluated = ledger.evaluate(claims, ledger.collect_results("quick"), strict=True)
    if os.environ.get("PASSMD_UPDATE_LEDGER_BASELINE") == "1":
        ledger.write_baseline(evaluated, BASELINE)
    baseline = ledger.load_baseline(BASELINE)
    assert set(baseline) <= set(claims["id"]), "baseline names claims that are not in claims.csv"
    ledger.check_no_regressions(evaluated, baseline)
    assert ledger.orphan_extractors(claims) == [], "extractors registered for ids not in claims.csv"
    # The claim computed from closed forms needs no figure: it must always be reproduced.
    assert baseline["fig10b-r1-stiffer-contact"] == "reproduced"
    improved = evaluated[(evaluated["status"] == "reproduced")
                         & (evaluated["claim"].map(baseline) != "reproduced")]
    if len(improved):
        print("newly reproduced (update the baseline):", ", ".join(improved["claim"]))
