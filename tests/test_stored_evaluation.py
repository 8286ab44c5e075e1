"""The book's one evaluation of the ledger: read back exactly, and never for another profile, code or data."""

import math

import pandas as pd
import pytest

from passmd.report import publish, stored_evaluation
from passmd.runtime.config import RunConfig


def _table() -> pd.DataFrame:
    table = pd.DataFrame({"claim": ["a", "b"], "ours": ["text", 1.5], "margin": [math.nan, 0.25],
                          "counted": [True, False], "readings": [4, 2]})
    table.attrs = {"points": [{"claim": "a", "point": {"mu": 0.2}, "score": None}],
                   "joint": {"point": {("mu", 0.3): 3}, "reading": (("flyback", "fixed"),),
                             "odd": {"__items__": 1}}}
    return table


def test_a_table_reads_back_exactly():
    table = _table()
    back = stored_evaluation.decode_table(stored_evaluation.encode_table(table))
    pd.testing.assert_frame_equal(back, table)
    assert back.attrs == table.attrs


def test_read_only_what_this_profile_code_and_data_wrote(tmp_path, monkeypatch):
    path = tmp_path / "ledger.pmc"
    assert stored_evaluation.read(path, "paper") is None  # no file: the caller evaluates
    path.write_bytes(stored_evaluation.encode(_table(), "paper"))
    pd.testing.assert_frame_equal(stored_evaluation.read(path, "paper"), _table())
    assert stored_evaluation.read(path, "quick") is None
    monkeypatch.setattr(stored_evaluation, "_data_fingerprint", lambda: "an edited claims.csv")
    assert stored_evaluation.read(path, "paper") is None
    monkeypatch.undo()
    monkeypatch.setattr(stored_evaluation, "code_fingerprint", lambda: "another package")
    assert stored_evaluation.read(path, "paper") is None
    path.write_bytes(path.read_bytes()[:-5])  # a torn file is not read either
    monkeypatch.undo()
    assert stored_evaluation.read(path, "paper") is None


def test_the_ledger_command_writes_the_evaluation_it_printed(tmp_path, monkeypatch):
    """``passmd ledger --write-evaluation``: the file holds the evaluation the command judged with,
    readable for its profile only."""
    import io
    import json

    from passmd import cli
    from passmd.report import evaluation

    monkeypatch.setattr(evaluation, "collect_results",  # the closed forms alone: every claim still evaluated
                        lambda config: {"closed_forms": evaluation.closed_form_results(config)})
    path = tmp_path / "ledger.pmc"
    out = io.StringIO()
    status = cli.main(["ledger", "--profile", "quick", "--cache-dir", str(tmp_path), "--json",
                       "--write-evaluation", str(path)], out=out)
    assert status == 0
    printed = {c["claim"]: c["category"] for c in json.loads(out.getvalue())["claims"]}
    stored = stored_evaluation.read(path, "quick")
    assert dict(zip(stored["claim"], stored["status"], strict=True)) == printed
    assert stored_evaluation.read(path, "paper") is None


@pytest.mark.parametrize("stored", [True, False], ids=["stored", "absent"])
def test_book_evaluation_reads_the_builds_file_or_evaluates(tmp_path, monkeypatch, stored):
    from passmd.report import evaluation

    path = tmp_path / "ledger.pmc"
    if stored:
        path.write_bytes(stored_evaluation.encode(_table(), "quick"))
    monkeypatch.setenv(publish.LEDGER_ENV, str(path))
    calls = []
    monkeypatch.setattr(evaluation, "evaluate", lambda config: calls.append(config) or "evaluated here")
    config = RunConfig(profile="quick", cache_dir=tmp_path)
    got = publish.book_evaluation(config)
    if stored:
        pd.testing.assert_frame_equal(got, _table())
        assert calls == []
    else:
        assert got == "evaluated here" and calls == [config]


def test_the_data_fingerprint_follows_claims_and_references_not_benchmark_records(tmp_path, monkeypatch):
    (tmp_path / "reference").mkdir()
    (tmp_path / "benchmarks").mkdir()
    (tmp_path / "reference" / "claims.csv").write_text("id,paper\na,1\n")
    (tmp_path / "benchmarks" / "book.json").write_text("[]")
    monkeypatch.setattr(stored_evaluation, "_DATA_DIR", tmp_path)
    before = stored_evaluation._data_fingerprint()
    (tmp_path / "benchmarks" / "book.json").write_text("[{}]")
    assert stored_evaluation._data_fingerprint() == before
    (tmp_path / "reference" / "claims.csv").write_text("id,paper\na,2\n")
    assert stored_evaluation._data_fingerprint() != before
