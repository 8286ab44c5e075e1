"""The joint reading is stated alike by ``passmd ledger`` (text and JSON) and the replication report.

One function writes the sentences (``passmd.report.ledger_views.joint_sentences``): the command line
prints them from the evaluated ledger, the JSON carries the record they are written from, and the
report renders them. The first test checks the command and its JSON on a synthetic ledger; the last
opens the built report (``nox -s book`` first) and compares its sentences with those of
``passmd ledger --json`` on the book's profile, from the cache the build filled. It is skipped without
a built book, except under ``nox -s book_check`` (PASSMD_REQUIRE_BROWSER=1), where it must run.
"""

from __future__ import annotations

import html
import io
import json
import os
import re
import subprocess
import sys
import types
from pathlib import Path

import pandas as pd
import pytest

from passmd.ledger import checks
from passmd.ledger.claims import CLAIM_COLUMNS
from passmd.report import evaluation, ledger_views

ROOT = Path(__file__).resolve().parents[1]
REPORT_HTML = ROOT / "book" / "_build" / "html" / "replication_report.html"
REPORT_SOURCE = ROOT / "book" / "replication_report.md"


def _synthetic(tmp_path, monkeypatch):
    """A claims file of three claims over fly-back × A_c protocol and the modules deciding them:
    'a' holds only at (fixed, first), 'b' only with the steady protocol, 'c' everywhere."""
    import csv

    rows = []
    for claim_id in ("a", "b", "c"):
        row = dict.fromkeys(CLAIM_COLUMNS, "")
        row.update(id=claim_id, figure="x", requires="fig5a", quantity="q", ours_definition="d",
                   source_section="4", source_quote="quote", tolerance_reason="because", check="ordering",
                   relation=">")
        rows.append(row)
    path = tmp_path / "claims.csv"
    with open(path, "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(CLAIM_COLUMNS))
        writer.writeheader()
        writer.writerows(rows)
    module = types.ModuleType("synthetic_claims")
    def a(results, reading):
        good = (reading["flyback"], reading["ac_protocol"]) == ("fixed", "first")
        return {"lhs": 2.0 if good else 0.5, "rhs": 1.0}

    module.a = checks.extractor("a", depends_on=("flyback", "ac_protocol"))(a)
    module.b = checks.extractor("b", depends_on=("ac_protocol",))(
        lambda results, reading: {"lhs": 2.0 if reading["ac_protocol"] == "steady" else 0.5, "rhs": 1.0})
    module.c = checks.extractor("c")(lambda results: {"lhs": 2.0, "rhs": 1.0})
    from passmd.ledger import claims

    monkeypatch.setattr(claims, "CLAIMS_PATH", path)
    monkeypatch.setattr(evaluation, "load_claims", lambda path_=None: claims.load_claims(path))
    monkeypatch.setattr(evaluation, "claim_modules", lambda: (module,))
    monkeypatch.setattr(evaluation, "collect_results", lambda config, figures=None: {"fig5a": pd.DataFrame()})


def test_cli_text_and_json_state_the_joint_reading_as_the_report_does(tmp_path, monkeypatch):
    from passmd import cli

    _synthetic(tmp_path, monkeypatch)
    out = io.StringIO()
    assert cli.main(["ledger", "--json"], out=out) == 0
    joint = json.loads(out.getvalue())["joint_reading"]
    # the space is the product of the free axes the claims vary along: fly-back × A_c protocol
    assert joint["covered_points"] == joint["points"] == joint["chosen_from"] == 4
    assert joint["decided_points"] == 4 and joint["holding"] == 2 and joint["claims"] == 3
    assert joint["best_single_point"] == 2 and joint["in_sample_gain"] == ["b"]
    assert [t["described"] for t in joint["ties"]] == ["fly-back rule = fixed; how A_c is read = first"]
    assert [(r["described"], r["holding"], r["margin"]) for r in joint["runner_ups"]] == [
        ("how A_c is read = first", 1, 1)]
    sentences = ledger_views.joint_sentences(joint)
    assert sentences[0] == "Joint reading (in-sample): defaults, where 2 of 3 voting claims hold together."
    assert "chosen from 4 of the 4 points" in sentences[1] and "4 covered" in sentences[1]
    assert sentences[3] == "Runner-ups: how A_c is read = first (1 hold, 1 fewer)."
    text = io.StringIO()
    assert cli.main(["ledger"], out=text) == 0
    printed = text.getvalue().splitlines()
    held_out = [line for line in printed if line.startswith(("Each claim is judged", "In-sample"))]
    assert len(held_out) == 2 and "+1 in-sample pass: b" in held_out[1]
    assert printed[3:3 + len(sentences)] == sentences  # the same sentences, in the same order
    assert "1 pairs of claims never hold together, in 1 tensions:" in printed
    # the report renders the same function's sentences from the same record
    source = REPORT_SOURCE.read_text(encoding="utf-8")
    assert "ledger_views.joint_sentences(joint)" in source
    assert "ledger_views.held_out_sentences(evaluated)" in source
    assert "ledger_views.tension_sentences(evaluated)" in source


def test_the_report_leads_with_one_line_per_claim():
    """The replication report's first screen is the one-line-per-claim table (category, ours against
    the paper, the one reason, the readings): no section heading, rule or explanation comes before it."""
    source = REPORT_SOURCE.read_text(encoding="utf-8")
    table = source.index("ledger_views.styled(evaluation.counted(evaluated), links=True)")
    assert table < source.index("\n## ") and table < source.index("rules.RULES")
    assert source.index("headline_markdown") < table
    if REPORT_HTML.is_file():  # in the page's body, before its first section
        raw = REPORT_HTML.read_text(encoding="utf-8")
        body = raw[raw.index('<h1>Replication report<a class="headerlink"'):]
        assert body.index('class="passmd-ledger"') < body.index("<h2"), "the built report leads otherwise"


def _page_text(path: Path) -> str:
    raw = path.read_text(encoding="utf-8")
    raw = re.sub(r"<(script|style)\b.*?</\1>", " ", raw, flags=re.S)
    return re.sub(r"\s+", " ", html.unescape(re.sub(r"<[^>]+>", " ", raw)))


def test_rendered_report_states_the_joint_reading_of_passmd_ledger():
    if not REPORT_HTML.is_file():
        if os.environ.get("PASSMD_REQUIRE_BROWSER") == "1":
            pytest.fail(f"{REPORT_HTML} is missing: build the book first (nox -s book)")
        pytest.skip("no built book (nox -s book)")
    text = _page_text(REPORT_HTML)
    profile = re.search(r"Profile (quick|paper)\b", text)
    assert profile, "the report does not name its profile"
    cache = os.environ.get("PASSMD_CACHE_DIR") or str(ROOT / ".passmd-cache")
    command = [sys.executable, "-m", "passmd", "ledger", "--profile", profile.group(1), "--json"]
    done = subprocess.run(command, env={**os.environ, "PASSMD_CACHE_DIR": cache}, capture_output=True,
                          text=True, check=True, timeout=3600)
    joint = json.loads(done.stdout)["joint_reading"]
    for sentence in ledger_views.joint_sentences(joint):
        assert re.sub(r"\s+", " ", sentence) in text, f"the report does not say: {sentence}"
