"""The ledger: claims schema, every check kind on synthetic data, verdicts, extractor tags, regressions.

The checks compare numbers exactly against their tolerances, so synthetic data sit clearly
inside or outside a tolerance (never within rounding of it).
"""

import csv
import math
import os
import re
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from passmd.experiments import figure_table
from passmd.ledger import checks, reference
from passmd.ledger.claims import CHECK_KINDS, CLAIM_COLUMNS, load_claims
from passmd.report import evaluation, ledger_views
from passmd.runtime.config import RunConfig

QUICK, PAPER_PROFILE = RunConfig(profile="quick"), RunConfig(profile="paper")
PAPER = Path(os.environ.get("PASSMD_PAPER", "/work/shared/paper/nguyen2018-passmd.md"))

#: Claims the ledger must hold at minimum: the checkable statements of Sections 3-6 and Figs. 5-10.
REQUIRED_CLAIMS = (
    "fig5a-no-step-below-50nm", "fig5b-rigid-ac-matches-eq7", "fig5b-flexible-ac-matches-eq8",
    "fig6a-rigid-ac-matches-eq11", "fig6a-rigid-ac-not-eq10", "fig6b-flexible-r1-ac-matches-eq12",
    "fig6c-flexible-r025-ac-matches-eq12", "fig7a-force-difference-115mn", "fig9a-standard-position-552nm",
    "fig9a-optimized-position-716nm", "fig9a-step-increase-46.8pct", "fig9b-optimized-faster-below-110khz",
    "fig9b-max-gain-2.5mm_s", "fig10a-max-velocity-19mm_s", "fig10a-1n-slower",
    "fig10a-0.1n-stick-lost-above-80khz", "fig10b-r1-faster", "fig10c-youngs-modulus-negligible",
    "abstract-velocity-gain-15pct",
)


# --------------------------------------------------------------------------------------
# helpers: a synthetic claims file and a module of tagged extractors
# --------------------------------------------------------------------------------------

def _claim(**fields):
    row = dict.fromkeys(CLAIM_COLUMNS, "")
    row.update(figure="x", requires="fig5a", quantity="q", ours_definition="d", source_section="4",
               source_quote="quote", tolerance_reason="because")
    row.update(fields)
    return row


def _write(tmp_path, rows, columns=CLAIM_COLUMNS):
    path = tmp_path / "claims.csv"
    with open(path, "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(columns), extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)
    return path


def _tag(module, claim_id, func, depends_on=()):
    """Put ``func`` into ``module`` as the extractor of ``claim_id`` (replacing an earlier one)."""
    setattr(module, "extract_" + re.sub(r"\W", "_", claim_id), checks.extractor(claim_id, depends_on)(func))
    return module


SYNTHETIC = [
    _claim(id="val", check="value", paper_value="100", unit="nm", tolerance="0.05", tolerance_kind="rel"),
    _claim(id="ord", check="ordering", relation=">", unit="mm/s"),
    _claim(id="thr", check="threshold", relation="switch_below", paper_value="50", unit="nm",
           tolerance="5", tolerance_kind="abs"),
    _claim(id="trd", check="trend", relation="increasing", tolerance="0.05", tolerance_kind="rel"),
    _claim(id="other", check="value", paper_value="1", tolerance="0.1", tolerance_kind="rel",
           requires="fig9b"),
]


def _good_module(values=None):
    """A module whose extractors make every synthetic claim hold (``values`` overrides 'val')."""
    values = {"val": 103.0, **(values or {})}
    module = types.ModuleType("synthetic_claims")
    _tag(module, "val", lambda results: values["val"])
    _tag(module, "ord", lambda results: {"lhs": 2.0, "rhs": 1.0})
    _tag(module, "thr", lambda results: {"x": np.arange(0, 100, 10.0), "holds": np.arange(0, 100, 10.0) < 50})
    _tag(module, "trd", lambda results: {"x": [1, 2, 3], "y": [1.0, 2.0, 3.0]})
    _tag(module, "other", lambda results: 1.0)
    return module


# --------------------------------------------------------------------------------------
# claims.csv
# --------------------------------------------------------------------------------------

def test_real_claims_load_and_contain_the_required_rows():
    claims = load_claims()
    assert claims["id"].is_unique
    missing = set(REQUIRED_CLAIMS) - set(claims["id"])
    assert not missing
    assert set(claims["check"]) == set(CHECK_KINDS)  # every kind is used
    # No paper value typed for a curve claim; tolerances stated with a reason everywhere.
    curve = claims[claims["reference"] != ""]
    assert (curve["paper_value"] == "").all() and len(curve) == 5
    assert (claims["tolerance_reason"].str.len() > 10).all()


def test_every_ordering_names_what_it_compares():
    """An ordering of computed values names its two sides (``compares``), so that its margin and verdict
    say what is compared; the claims about the experiment compare nothing computed."""
    claims = load_claims()
    experiment = evaluation.claim_functions().experiment
    orderings = claims[(claims["check"] == "ordering") & ~claims["id"].isin(experiment)]
    unnamed = list(orderings.loc[orderings["compares"].str.count(r"\|") != 1, "id"])
    assert not unnamed, unnamed
    assert (claims.loc[claims["check"] != "ordering", "compares"] == "").all()


def test_stated_numbers_of_the_paper():
    """The numbers the paper states in its text (a typo here would move a claim)."""
    claims = load_claims().set_index("id")
    stated = {
        "fig5a-no-step-below-50nm": 50, "fig7a-force-difference-115mn": 115,
        "fig9a-standard-position-552nm": 552, "fig9a-optimized-position-716nm": 716,
        "fig9a-step-increase-46.8pct": 46.8, "fig9b-optimized-faster-below-110khz": 110,
        "fig9b-max-gain-2.5mm_s": 2.5, "fig10a-max-velocity-19mm_s": 19,
        "fig10a-0.1n-stick-lost-above-80khz": 80, "abstract-velocity-gain-15pct": 15,
        # implied: Fig. 10a's 19 minus the 2.5 gain (a study: not a sentence of the paper)
        "study-fig9b-sawtooth-velocity-16.5mm_s-at-110khz": 19 - 2.5,
    }
    for claim, value in stated.items():
        assert claims.at[claim, "paper_value_num"] == value, claim


@pytest.mark.skipif(not PAPER.is_file(), reason=f"paper text not available at {PAPER}")
def test_every_quote_is_in_the_paper():
    """Quotes are verbatim up to notation: compare letters and digits only (the paper's LaTeX
    '$u_{x,max,e}^{*}$' and our 'u*_x,max,e' both reduce to 'uxmaxe')."""
    def letters(text):
        return re.sub(r"[^0-9a-z]", "", text.lower())

    paper = letters(PAPER.read_text(encoding="utf-8"))
    claims = load_claims()
    absent = [c for c, q in zip(claims["id"], claims["source_quote"], strict=True) if letters(q) not in paper]
    assert not absent


def test_schema_errors_name_the_row_and_the_problem(tmp_path):
    rows = [
        _claim(id="bad-kind", check="guess"),
        _claim(id="dup", check="ordering", relation="<"),
        _claim(id="dup", check="ordering", relation="<"),
        _claim(id="no-value", check="value", tolerance="0.1", tolerance_kind="rel"),
        _claim(id="no-kind", check="trend", relation="increasing", tolerance="0.1"),
        _claim(id="bad-rel", check="ordering", relation="=="),
        _claim(id="ref", check="value", reference="fig5b_closed_form.csv:nope", tolerance="0.1",
               tolerance_kind="rel"),
        _claim(id="cfg", check="ordering", relation="<", preload_N="0.4 N", actuator_model="stiff"),
        _claim(id="Upper", check="ordering", relation="<", requires="figure5"),
        _claim(id="quote", check="ordering", relation="<", source_quote=""),
    ]
    path = _write(tmp_path, rows)
    # reference curves are looked up next to the claims file
    (tmp_path / "fig5b_closed_form.csv").write_text("preload_N,u_x_max_nm\n0.1,1\n")
    with pytest.raises(ValueError) as info:
        load_claims(path)
    message = str(info.value)
    for expected in (
        "row 'bad-kind': check = 'guess' is not allowed",
        "id 'dup' appears more than once",
        "row 'no-value': a value claim needs exactly one of paper_value and reference",
        "row 'no-kind': tolerance_kind = '' is not allowed",
        "row 'bad-rel': relation = '==' is not allowed",
        "row 'ref': reference column 'nope' is not in fig5b_closed_form.csv",
        "row 'cfg': preload_N = '0.4 N' is not allowed",
        "row 'cfg': actuator_model = 'stiff' is not allowed",
        "row 'Upper': id = 'Upper' is not allowed",
        "row 'Upper': requires = 'figure5' is not allowed",
        "row 'quote': source_quote is empty",
    ):
        assert expected in message


def test_missing_columns_and_file(tmp_path):
    path = _write(tmp_path, [_claim(id="a", check="ordering", relation="<")],
                  columns=[c for c in CLAIM_COLUMNS if c != "source_quote"])
    with pytest.raises(ValueError, match="missing required columns: source_quote"):
        load_claims(path)
    with pytest.raises(FileNotFoundError):
        load_claims(tmp_path / "none.csv")


# --------------------------------------------------------------------------------------
# check kinds
# --------------------------------------------------------------------------------------

def test_value_check_scalar_relative_and_absolute():
    inside = checks.check_value(103.0, 100.0, 0.05, "rel")
    assert inside.passed and inside.abs_deviation == pytest.approx(3.0)
    assert inside.rel_deviation == pytest.approx(0.03)
    outside = checks.check_value(107.0, 100.0, 0.05, "rel")
    assert not outside.passed and "7 % exceeds the tolerance 5 %" in outside.detail
    assert checks.check_value(104.0, 110.0, 5.0, "abs").rel_deviation == pytest.approx(6 / 110)
    assert not checks.check_value(104.0, 110.0, 5.0, "abs").passed
    assert checks.check_value(106.0, 110.0, 5.0, "abs").passed
    with pytest.raises(ValueError, match="must be a number"):
        checks.check_value([1.0, 2.0], 1.0, 0.1)
    with pytest.raises(ValueError, match="must be a number"):
        checks.check_value({"x": [1.0], "y": [1.0]}, 1.0, 0.1)  # a curve for a scalar claim
    with pytest.raises(checks.NotEvaluable, match="non-finite"):  # inconclusive, never a pass
        checks.check_value(math.nan, 1.0, 0.1)


def test_value_check_curve_interpolates_the_reference():
    curve = (np.array([0.1, 0.2, 0.3]), np.array([10.0, 20.0, 40.0]))
    # At x = 0.25 the reference is 30 (linear); 31 is 3.3 % off.
    result = checks.check_value({"x": [0.1, 0.25], "y": [10.0, 31.0]}, None, 0.05, "rel", curve)
    assert result.passed and result.rel_deviation == pytest.approx(1 / 30)
    failing = checks.check_value({"x": [0.1, 0.25], "y": [10.0, 33.0]}, None, 0.05, "rel", curve)
    assert not failing.passed and "at 0.25 (33 vs 30)" in failing.detail
    united = checks.check_value({"x": [0.1, 0.25], "y": [10.0, 33.0]}, None, 0.05, "rel", curve, unit="nm",
                                x_unit="N")
    assert "deviation 10 % at 0.25 N (33 nm vs 30 nm) exceeds the tolerance 5 %" == united.detail
    scalar = checks.check_value(133.8, 0.0, 1.0, "abs", unit="t_a")
    assert scalar.detail == "deviation 133.8 t_a exceeds the tolerance 1 t_a"
    assert scalar.text == "133.8 t_a vs the paper's 0 t_a"
    with pytest.raises(ValueError, match="outside the reference curve's range"):
        checks.check_value({"x": [0.5], "y": [1.0]}, None, 0.05, "rel", curve)
    with pytest.raises(ValueError, match="differ in length"):
        checks.check_value({"x": [0.1, 0.2], "y": [1.0]}, None, 0.05, "rel", curve)


def test_ordering_check():
    assert checks.check_ordering({"lhs": 1.0, "rhs": 2.0}, "<").passed
    assert checks.check_ordering({"lhs": 3.0, "rhs": 2.0}, ">").passed
    arrays = checks.check_ordering({"lhs": [3.0, 1.0, 5.0], "rhs": [2.0, 2.0, 2.0]}, ">")
    assert not arrays.passed and arrays.ours == "2 of 3 hold" and "fails at 1 of 3" in arrays.detail
    named = checks.check_ordering({"lhs": 9.7, "rhs": 15.4, "at": 0.1, "at_unit": "N"}, ">", unit="nm",
                                  names=("flexible A_c", "rigid A_c"))
    assert named.detail == "flexible A_c > rigid A_c fails: flexible A_c 9.7 nm vs rigid A_c 15.4 nm at 0.1 N"
    assert named.text == "9.7 nm vs 15.4 nm"
    # a relative margin: lhs must exceed rhs by 10 %
    assert not checks.check_ordering({"lhs": 1.05, "rhs": 1.0}, ">", 0.1, "rel").passed
    assert checks.check_ordering({"lhs": 1.15, "rhs": 1.0}, ">", 0.1, "rel").passed
    approx = checks.check_ordering({"lhs": 1.04, "rhs": 1.0}, "approx", 0.05, "rel")
    assert approx.passed and approx.rel_deviation == pytest.approx(0.04)
    assert not checks.check_ordering({"lhs": 1.06, "rhs": 1.0}, "approx", 0.05, "rel").passed
    with pytest.raises(ValueError, match="keys"):
        checks.check_ordering({"left": 1.0}, "<")


def test_one_tie_rule_for_every_comparison():
    """passmd.ledger.rules.TIE_RULE: two values closer than the resolution of what they measure (exactly
    equal without one: two zeros) are equal; an ordering between them is undecided, never held or failed,
    an agreement between them holds. Counter-examples: a difference beyond the resolution decides."""
    for relation in ("<", ">"):
        with pytest.raises(checks.NotEvaluable, match="tied"):
            checks.check_ordering({"lhs": 0.0, "rhs": 0.0}, relation)  # two zeros
        with pytest.raises(checks.NotEvaluable, match="resolution 5"):
            checks.check_ordering({"lhs": 5.0, "rhs": 10.0, "resolution": 5.0}, relation)  # one grid step
    assert checks.check_ordering({"lhs": 5.0, "rhs": 10.1, "resolution": 5.0}, "<").passed
    assert not checks.check_ordering({"lhs": 5.0, "rhs": 10.1, "resolution": 5.0}, ">").passed
    # an agreement within the resolution holds, however small the tolerance
    assert checks.check_ordering({"lhs": 1.0, "rhs": 1.0}, "approx", 0.0, "rel").passed
    assert checks.check_ordering({"lhs": 1.0, "rhs": 1.5, "resolution": 0.5}, "approx", 0.01, "rel").passed
    far = {"lhs": 1.0, "rhs": 1.6, "resolution": 0.5}
    assert not checks.check_ordering(far, "approx", 0.01, "rel").passed
    # a failing element decides against a tied one
    assert not checks.check_ordering({"lhs": [0.0, 3.0], "rhs": [0.0, 1.0]}, "<").passed
    with pytest.raises(ValueError, match="resolution"):
        checks.check_ordering({"lhs": 1.0, "rhs": 2.0, "resolution": -1.0}, "<")
    from passmd.ledger import rules
    assert rules.TIE_RULE in dict(rules.RULES).values()


def test_threshold_check():
    x = np.arange(0.0, 101.0, 10.0)
    step_is_zero = x < 50  # zero step below 50 nm, steps above
    result = checks.check_threshold({"x": x, "holds": step_is_zero}, "switch_below", 50.0, 5.0, "abs")
    # the switch is known to lie between the grid points 40 and 50, which bracket the paper's 50
    assert result.passed and result.ours == 45.0 and result.abs_deviation == 0.0
    assert result.text == "between 40 and 50"
    # a continuous margin (positive where the condition holds) puts the switch where it crosses zero
    sharp = checks.check_threshold({"x": x, "holds": step_is_zero, "margin": 48.0 - x}, "switch_below", 50.0,
                                   5.0, "abs", unit="nm")
    assert sharp.ours == pytest.approx(48.0) and sharp.text == "48 nm (between 40 and 50 nm)"
    exact = checks.check_threshold({"x": x, "holds": step_is_zero, "switch": 47.5}, "switch_below", 50.0, 5.0,
                                   "abs", unit="kHz")
    assert exact.ours == 47.5 and exact.text == "47.5 kHz (computed exactly)"
    # a failure at the grid's first point bounds the switch by it: no grid point is written as a fact
    first = checks.check_threshold({"x": x, "holds": x < 0}, "holds_below", 50.0, 5.0, "abs", unit="kHz")
    assert not first.passed and first.text == "below 0 kHz (it fails at the grid's first point)"
    # The switch at 70 is outside the ±5 band around 50: the condition still holds above.
    late = checks.check_threshold({"x": x, "holds": x < 70}, "switch_below", 50.0, 5.0, "abs")
    assert not late.passed and "still holds beyond it at 60" in late.detail
    early = checks.check_threshold({"x": x, "holds": x < 30}, "holds_below", 50.0, 5.0, "abs", unit="nm")
    assert not early.passed and "fails below the threshold band (50 nm ± 5 nm) at 30 nm" in early.detail
    # one-sided: failing or holding above the band does not matter
    always = {"x": x, "holds": np.ones_like(x, bool)}
    assert checks.check_threshold(always, "holds_below", 50.0, 5.0, "abs").passed
    # points inside the band are not judged (60 would fail a 'switch_below' at 55 ± 10)
    assert checks.check_threshold({"x": x, "holds": x <= 60}, "switch_below", 55.0, 10.0, "abs").passed
    above = checks.check_threshold({"x": x, "holds": x > 80}, "switch_above", 80.0, 5.0, "abs")
    assert above.passed and above.ours == 85.0 and above.abs_deviation == 0.0
    with pytest.raises(checks.CoarseGrid, match="no grid point below"):
        checks.check_threshold({"x": [60.0, 70.0], "holds": [True, True]}, "holds_below", 50.0, 5.0, "abs")
    with pytest.raises(checks.NotEvaluable, match="far side"):
        checks.check_threshold({"x": [10.0, 20.0], "holds": [True, True]}, "switch_below", 50.0, 5.0, "abs")
    # NaN never counts as holding: a boolean read from a column with gaps is inconclusive
    with pytest.raises(checks.NotEvaluable, match="non-finite"):
        checks.check_threshold({"x": [10.0, 20.0, 60.0], "holds": [1.0, np.nan, 0.0]}, "switch_below", 50.0,
                               5.0, "abs")
    with pytest.raises(ValueError, match="must be booleans"):
        checks.check_threshold({"x": [10.0, 60.0], "holds": [0.5, 0.0]}, "switch_below", 50.0, 5.0, "abs")


def test_trend_check():
    rising = checks.check_trend({"x": [3, 1, 2], "y": [3.0, 1.0, 2.0]}, "increasing", 0.0)  # sorted by x
    assert rising.passed and rising.abs_deviation == 0.0
    noisy = {"x": [1, 2, 3, 4], "y": [0.0, 5.0, 4.8, 10.0]}  # counter-step 0.2 = 2 % of the range 10
    assert checks.check_trend(noisy, "increasing", 0.05, "rel").passed
    assert not checks.check_trend(noisy, "increasing", 0.01, "rel").passed
    assert not checks.check_trend(noisy, "increasing", 0.1, "abs").passed
    assert not checks.check_trend({"x": [1, 2], "y": [1.0, 1.0]}, "increasing", 0.0).passed  # flat
    falling = checks.check_trend({"x": [1, 2, 3], "y": [3.0, 2.0, 1.0]}, "decreasing", 0.0)
    assert falling.passed
    several = {"0.3 N": {"x": [1, 2], "y": [0.0, 1.0]}, "0.8 N": {"x": [1, 2], "y": [1.0, 0.0]}}
    result = checks.check_trend(several, "increasing", 0.05)
    assert not result.passed and "series 0.8 N" in result.detail
    with pytest.raises(checks.NotEvaluable):
        checks.check_trend({"x": [1], "y": [1.0]}, "increasing", 0.0)


def test_curve_deviation_helper():
    table = reference.load_reference_curve("fig6a_closed_form")
    x, eq11 = table["preload_N"].to_numpy(), table["u_x_max_e_nm"].to_numpy()
    assert checks.curve_deviation(x, 1.02 * eq11, "fig6a_closed_form", "u_x_max_e_nm") == pytest.approx(2.0)


# --------------------------------------------------------------------------------------
# evaluation and verdicts
# --------------------------------------------------------------------------------------

def test_evaluate_computes_categories(tmp_path):
    claims = load_claims(_write(tmp_path, SYNTHETIC))
    evaluated = evaluation.evaluate(claims, {"fig5a": pd.DataFrame()}, modules=[_good_module()])
    evaluated = evaluated.set_index("claim")
    assert list(evaluated.reset_index().columns) == list(evaluation.LEDGER_COLUMNS)
    assert evaluated.at["val", "verdict"] == "within 3 % at its held-out reading"
    assert evaluated.at["val", "paper"] == "100 nm" and evaluated.at["val", "ours"] == 103.0
    assert evaluated.at["val", "ours_text"] == "103 nm vs the paper's 100 nm"
    assert evaluated.at["val", "tolerance"] == "5 %"
    for claim in ("val", "ord", "thr", "trd"):
        assert evaluated.at[claim, "status"] == "reproduced", claim
    assert evaluated.at["thr", "tolerance"] == "5 nm"
    # results that are missing leave the claim inconclusive, naming what is missing
    assert evaluated.at["other", "status"] == "inconclusive"
    assert evaluated.at["other", "verdict"] == "needs results: fig9b"
    assert ledger_views.summary(evaluated.reset_index()) == "4 of 5 claims reproduced; 1 inconclusive"


def test_evaluate_computes_the_results_from_a_config_when_none_are_given(tmp_path, monkeypatch):
    claims = load_claims(_write(tmp_path, SYNTHETIC[:1]))
    configs = []

    def collect(config):
        configs.append(config)
        return {"fig5a": pd.DataFrame()}

    monkeypatch.setattr(evaluation, "collect_results", collect)
    evaluated = evaluation.evaluate(claims, config=QUICK, modules=[_good_module()])
    assert configs == [QUICK] and evaluated.at[0, "status"] == "reproduced"
    with pytest.raises(ValueError, match="needs results or a config"):
        evaluation.evaluate(claims, modules=[_good_module()])


def test_failures_are_not_reproduced_with_their_evidence(tmp_path):
    rows = [dict(r) for r in SYNTHETIC]
    rows[1].update(reason="our runner is lighter")
    claims = load_claims(_write(tmp_path, rows))
    module = _good_module({"val": 120.0})
    _tag(module, "ord", lambda results: {"lhs": 0.5, "rhs": 1.0})

    def total_failure(results):
        raise checks.ClaimFails("no step up to the full stroke")

    _tag(module, "thr", total_failure)
    tables = {"fig5a": pd.DataFrame(), "fig9b": pd.DataFrame()}
    evaluated = evaluation.evaluate(claims, tables, modules=[module])
    evaluated = evaluated.set_index("claim")
    assert evaluated.at["val", "status"] == "not reproduced"
    assert "deviation 20 % exceeds the tolerance 5 %" in evaluated.at["val", "evidence"]
    assert evaluated.at["ord", "status"] == "not reproduced"
    assert evaluated.at["ord", "reason"] == "our runner is lighter"  # a human reason, never the category
    assert evaluated.at["thr", "status"] == "not reproduced"  # a total failure is a failure
    assert "no step up to the full stroke" in evaluated.at["thr", "evidence"]
    assert ledger_views.summary(evaluated.reset_index()) == "2 of 5 claims reproduced; 3 not reproduced"


def test_evidence_functions_follow_the_checks(tmp_path):
    """A claim's evidence lists the check at each reading, then its evidence function's lines; an
    evidence function without data says so instead of failing the ledger."""
    claims = load_claims(_write(tmp_path, SYNTHETIC[:2]))
    module = _good_module()
    module.val_evidence = checks.evidence("val")(lambda results: ["step 103 nm at 100 Hz"])

    @checks.evidence("ord")
    def ord_evidence(results):
        raise checks.NotEvaluable("no runs at 100 Hz")

    module.ord_evidence = ord_evidence
    evaluated = evaluation.evaluate(claims, {"fig5a": pd.DataFrame()}, modules=[module]).set_index("claim")
    assert evaluated.at["val", "evidence"].split(" | ") == [
        "defaults: holds (ours 103 nm vs the paper's 100 nm; deviation 3 % within the tolerance 5 %)",
        "step 103 nm at 100 Hz"]
    assert evaluated.at["ord", "evidence"].endswith(
        "evidence not available on these results: no runs at 100 Hz")


def test_joint_reading_is_chosen_among_covered_points(tmp_path):
    """The joint reading is chosen among the covered points (every claim resting on computed evidence
    evaluated from runs there): with no run of 'ord' at the fixed fly-back (a lenient ledger), the
    defaults are the only covered point, so 'val', which holds only at the fixed fly-back, is not
    reproduced, and its verdict names where it holds. A claim the runs cannot decide there (it is
    evaluated, undecided) leaves the point covered but not decided; once 'ord' is decided there (it
    fails), the point is decided too. Either way the fixed fly-back is chosen: 'val' is reproduced under
    the joint reading, and 'ord', failing at the defaults, is not."""
    claims = load_claims(_write(tmp_path, SYNTHETIC[:2]))
    module = types.ModuleType("synthetic_claims")
    at_fixed = {"ord": checks.NoRun("no run at the fixed fly-back")}

    @checks.extractor("val", depends_on=("flyback",))
    def _val(results, reading):
        return 100.0 if reading["flyback"] == "fixed" else 130.0

    @checks.extractor("ord", depends_on=("flyback",))
    def _ord(results, reading):
        if reading["flyback"] == "fixed" and at_fixed["ord"] is not None:
            raise at_fixed["ord"]
        return {"lhs": 0.5, "rhs": 1.0}

    module._val, module._ord = _val, _ord
    evaluated = evaluation.evaluate(claims, {"fig5a": pd.DataFrame()}, strict=False, modules=[module])
    joint = evaluated.attrs["joint"]
    assert joint["described"] == "defaults" and joint["covered_points"] == joint["points"] // 2
    assert joint["chosen_from"] == joint["covered_points"]
    by_id = evaluated.set_index("claim")
    assert by_id.at["val", "status"] == "not reproduced"
    assert "holds at fly-back rule = fixed" in by_id.at["val", "verdict"]
    assert by_id.at["val", "best_reading"] == "fly-back rule = fixed"
    assert by_id.at["val", "fraction_holds"] == 0.5
    with pytest.raises(LookupError, match="no run at the fixed fly-back"):
        evaluation.evaluate(claims, {"fig5a": pd.DataFrame()}, modules=[module])  # strict: a defect
    at_fixed["ord"] = checks.NotEvaluable("the grid cannot locate it")
    joint = evaluation.evaluate(claims, {"fig5a": pd.DataFrame()}, modules=[module]).attrs["joint"]
    assert joint["covered_points"] == joint["points"] == joint["chosen_from"]
    assert joint["decided_points"] == joint["points"] // 2 and joint["described"] == "fly-back rule = fixed"
    at_fixed["ord"] = None
    evaluated = evaluation.evaluate(claims, {"fig5a": pd.DataFrame()}, modules=[module])
    assert evaluated.attrs["joint"]["described"] == "fly-back rule = fixed"
    assert evaluated.attrs["joint"]["decided_points"] == evaluated.attrs["joint"]["points"]
    by_id = evaluated.set_index("claim")
    # held out: the reading is chosen from 'ord' alone, which holds nowhere, so 'val' is judged at the
    # defaults and fails there; it holds only in-sample, at the reading it chose itself
    assert by_id.at["val", "status"] == "not reproduced" and by_id.at["val", "held_out_reading"] == "defaults"
    assert by_id.at["val", "joint_state"] == "holds" and "holds in-sample" in by_id.at["val", "verdict"]
    assert evaluated.attrs["joint"]["in_sample_gain"] == ["val"]
    assert by_id.at["ord", "status"] == "not reproduced"
    # a second claim holding only at the fixed fly-back chooses it without 'val': now 'val' is judged there
    also = _claim(id="also", check="ordering", relation=">")
    claims3 = load_claims(_write(tmp_path, [*SYNTHETIC[:2], also]))
    module.also = checks.extractor("also", depends_on=("flyback",))(
        lambda results, reading: {"lhs": 2.0 if reading["flyback"] == "fixed" else 0.5, "rhs": 1.0})
    evaluated = evaluation.evaluate(claims3, {"fig5a": pd.DataFrame()}, modules=[module])
    by_id = evaluated.set_index("claim")
    assert by_id.at["val", "status"] == "reproduced under the joint reading"
    assert by_id.at["val", "held_out_reading"] == "fly-back rule = fixed"
    assert "fails at the defaults" in by_id.at["val", "verdict"]
    assert evaluated.attrs["joint"]["in_sample_gain"] == []
    table = evaluation.assumption_map(evaluated)
    assert list(table.columns) == ["claim", "defaults", "fly-back rule = fixed", "holds at", "best reading"]
    row = table.set_index("claim").loc["val"].tolist()
    assert row == ["fails", "holds", "1 of 2", "fly-back rule = fixed"]
    html = ledger_views.assumption_map_styled(evaluated).to_html()
    assert "R1: fly-back rule = fixed" in html
    assert evaluation.depends_on("val", modules=[module]) == ("flyback",)
    assert evaluation.claim_readings("val", modules=[module]) == ("defaults", "fly-back rule = fixed")


def test_a_missing_run_or_an_undeclared_axis_stops_the_ledger(tmp_path):
    """Declared = computed: an extractor that finds no run at a reading (NoRun), or that does not declare
    an axis changing a table its claim reads, is a defect the strict ledger refuses; leniently the
    missing run is an undecided point, named."""
    rows = [_claim(id="val", check="value", paper_value="100", unit="nm", tolerance="0.05",
                   tolerance_kind="rel", requires="fig7_readings")]
    claims = load_claims(_write(tmp_path, rows))
    module = types.ModuleType("synthetic_claims")

    @checks.extractor("val", depends_on=("flyback", "force_frequency"))
    def _val(results, reading):
        if reading["force_frequency"] != 100.0:
            raise checks.NoRun("no force runs at 1 kHz")
        return 100.0

    module._val = _val
    with pytest.raises(LookupError, match="claim 'val' has no run at drive frequency = 1000 Hz"):
        evaluation.evaluate(claims, {"fig7_readings": pd.DataFrame()}, modules=[module])
    lenient = evaluation.evaluate(claims, {"fig7_readings": pd.DataFrame()}, modules=[module], strict=False)
    assert "no run: no force runs at 1 kHz" in lenient.at[0, "evidence"]
    module._val = checks.extractor("val", depends_on=("flyback",))(lambda results, reading: 100.0)
    with pytest.raises(LookupError, match="claim 'val' reads tables that force_frequency changes, but its "
                                          "extractor does not declare it"):
        evaluation.evaluate(claims, {"fig7_readings": pd.DataFrame()}, modules=[module])


def _point(state, reading=None, score=math.nan):
    from passmd.ledger.verdicts import PointResult
    outcome = None if state == "inconclusive" else checks.Outcome(state == "holds", 1.0, score=score)
    return PointResult(reading or {}, state, outcome, f"{state} here")


def test_category_comes_from_the_held_out_reading_alone():
    """passmd.ledger.verdicts.category: the state at the held-out reading decides; holding there and at
    the defaults is 'reproduced', there only 'reproduced under the joint reading'; a check that cannot
    fail holds 'by construction', never reproduced; an undecided state is never reproduced, whatever the
    defaults show; a failure there is 'not reproduced' even where the defaults hold."""
    from passmd.ledger.verdicts import category

    assert category("holds", "holds") == "reproduced"
    assert category("holds", "fails") == category("holds", "inconclusive")
    assert category("holds", "fails") == "reproduced under the joint reading"
    assert category("holds", "holds", informative=False) == "holds by construction"
    assert category("inconclusive", "holds") == "inconclusive"
    assert category("fails", "holds") == category("fails", "fails") == "not reproduced"


def test_joint_reading_is_the_argmax_with_ties_runner_ups_and_conflicts(tmp_path):
    """Three claims over fly-back × A_c protocol: 'a' holds only at (fixed, first), 'b' only with the
    steady protocol, 'c' (no axis) everywhere. Two claims hold at the steady points (b, c) and at
    (fixed, first) (a, c): a tie, which the defaults win; one at (slew, first). 'a' and 'b' never
    hold together and each fails where the other holds: a conflicting pair."""
    rows = [_claim(id=i, check="ordering", relation=">", unit="") for i in ("a", "b", "c")]
    claims = load_claims(_write(tmp_path, rows))
    module = types.ModuleType("synthetic_claims")

    @checks.extractor("a", depends_on=("flyback", "ac_protocol"))
    def _a(results, reading):
        good = reading["flyback"] == "fixed" and reading["ac_protocol"] == "first"
        return {"lhs": 2.0 if good else 0.5, "rhs": 1.0}

    @checks.extractor("b", depends_on=("ac_protocol",))
    def _b(results, reading):
        return {"lhs": 2.0 if reading["ac_protocol"] == "steady" else 0.5, "rhs": 1.0}

    @checks.extractor("c")
    def _c(results):
        return {"lhs": 2.0, "rhs": 1.0}

    module._a, module._b, module._c = _a, _b, _c
    evaluated = evaluation.evaluate(claims, {"fig5a": pd.DataFrame()}, modules=[module])
    joint = evaluated.attrs["joint"]
    assert joint["described"] == "defaults" and joint["holding"] == 2 and joint["claims"] == 3
    # (slew, steady) and (fixed, steady) give every claim the same states: one reading, the defaults
    assert joint["equivalent_points"] == joint["points"] // 2
    assert [(r["described"], r["holding"]) for r in joint["ties"]] == [
        ("fly-back rule = fixed; how A_c is read = first", 2)]
    assert [(r["described"], r["holding"]) for r in joint["runner_ups"]] == [("how A_c is read = first", 1)]
    assert [p["claims"] for p in evaluated.attrs["conflicts"]] == [["a", "b"]]
    by_id = evaluated.set_index("claim")
    assert by_id.at["a", "status"] == "not reproduced"
    assert ("holds at fly-back rule = fixed; how A_c is read = first, which breaks b"
            in by_id.at["a", "verdict"])
    # held out, 'b' is judged where 'a' and 'c' hold together, and fails there: the tie the defaults won
    # in-sample was won by 'b' itself
    assert by_id.at["b", "status"] == "not reproduced" and by_id.at["b", "joint_state"] == "holds"
    assert by_id.at["b", "held_out_reading"] == "how A_c is read = first"
    assert joint["in_sample_gain"] == ["b"] and joint["best_single_point"] == 2
    assert evaluation.headline(evaluated)["reproduced"] == 1  # 'c', never more than at one point
    assert by_id.at["a", "readings"] == 4 and by_id.at["a", "fails_at"] == 3  # the full product, 2 × 2
    table = evaluation.joint_map(evaluated)
    both = "fly-back rule = fixed; how A_c is read = first"
    assert list(table.columns) == ["joint reading: defaults", both,
                                   "how A_c is read = first"]
    assert table["how A_c is read = first"].tolist() == ["fails", "fails", "holds"]
    import matplotlib
    matplotlib.use("Agg")
    from passmd.plots.ledger_map import plot_joint_map
    fig = plot_joint_map(table)
    assert fig.axes[0].has_data() and "(2 hold)" in fig.axes[0].get_xticklabels()[0].get_text()
    # counter-example: once 'a' holds everywhere, the three hold together and nothing conflicts
    module._a = checks.extractor("a", depends_on=("flyback", "ac_protocol"))(
        lambda results, reading: {"lhs": 2.0, "rhs": 1.0})
    again = evaluation.evaluate(claims, {"fig5a": pd.DataFrame()}, modules=[module])
    assert again.attrs["joint"]["holding"] == 3 and again.attrs["conflicts"] == []


def test_conflicts_are_every_pair_never_holding_together_grouped_into_tensions():
    """Every pair of claims that each hold somewhere but never together is listed, also where one is
    undecided where the other holds; pairs are grouped by the axes that separate them, near-duplicate
    rows (the same holding points) are linked, and a pair no single axis separates is described by the
    combinations of values each side holds at."""
    from passmd.ledger import readings
    from passmd.ledger.joint import conflicting_pairs, tensions

    free = [("flyback", ""), ("ac_protocol", "")]
    space = readings.space(free)

    def state(point, claim):
        fixed, first = point[free[0]] == "fixed", point[free[1]] == "first"
        return {"a1": first, "a2": first, "b": not first, "c": fixed == first, "d": fixed != first,
                "e": True if fixed else None, "f": not fixed}[claim]

    names = ("a1", "a2", "b", "c", "d", "e", "f")
    codes = {True: 1, False: 0, None: -1}
    table = {c: np.array([codes[state(p, c)] for p in space]) for c in names}
    states = {"space": space, "table": table, "free": free}
    pairs = conflicting_pairs(states)
    assert sorted(tuple(p["claims"]) for p in pairs) == [("a1", "b"), ("a2", "b"), ("c", "d"), ("e", "f")]
    found = {tuple(t["separated_by"]): t for t in tensions(states, pairs)}
    protocol, flyback = readings.AXES["ac_protocol"].label, readings.AXES["flyback"].label
    by_protocol = found[(protocol,)]
    assert by_protocol["pairs"] == 2 and not by_protocol["jointly"]
    assert [s["linked"] for s in by_protocol["sides"]] == [[["a1", "a2"]], []]
    assert by_protocol["sides"][0]["holds_only_at"] == f"{protocol} = first"
    both = found[(flyback, protocol)]
    assert both["jointly"] and both["pairs"] == 1
    assert both["sides"][0]["holds_only_at"] == (f"({flyback} = fixed, {protocol} = first) or "
                                                 f"({flyback} = slew, {protocol} = steady)")
    assert found[(flyback,)]["pairs"] == 1  # e is undecided where f holds: still never together


def test_fragile_margin_and_informative_flags(tmp_path):
    """A claim holding at the defaults but failing at the joint reading's runner-ups is fragile (rule 1
    of passmd.ledger.rules); the margin is the deviation against the tolerance; an extractor marked not
    informative says why."""
    claims = load_claims(_write(tmp_path, SYNTHETIC[:2]))
    module = types.ModuleType("synthetic_claims")

    @checks.extractor("val", depends_on=("ac_protocol", "flyback"))
    def _val(results, reading):
        return 103.0 if reading["flyback"] == "slew" and reading["ac_protocol"] == "steady" else 150.0

    def _ord(results):
        return {"lhs": 2.0, "rhs": 1.0}

    _ord = checks.extractor("ord")(_ord)
    _ord.not_informative = "holds for any finite stiffness"
    module._val, module._ord = _val, _ord
    evaluated = evaluation.evaluate(claims, {"fig5a": pd.DataFrame()}, modules=[module]).set_index("claim")
    assert evaluated.at["val", "status"] == "reproduced"
    assert evaluated.at["val", "fails_at"] == 3 and evaluated.at["val", "decided_at"] == 4
    assert evaluated.at["val", "fragile"]
    assert evaluated.at["val", "fragile_reason"].startswith("fails at the runner-up reading")
    assert evaluated.at["val", "margin_text"] == "3.0% off the paper, tolerance 5 %"
    assert evaluated.at["ord", "margin_text"] == "lhs > rhs: lhs 2 mm/s vs rhs 1 mm/s"
    assert evaluated.at["val", "margin"] == pytest.approx(0.6)
    assert not evaluated.at["ord", "fragile"] and not evaluated.at["ord", "informative"]
    assert evaluated.at["ord", "not_informative"] == "holds for any finite stiffness"
    # a check that cannot fail holds by construction: shown with its reason, never counted as reproduced
    assert evaluated.at["ord", "status"] == "holds by construction"
    assert "by construction: holds for any finite stiffness" in evaluated.at["ord", "verdict"]
    counts = evaluation.headline(evaluated.reset_index())
    assert counts["fragile"] == 1 and counts["not informative"] == 1 and counts["reproduced"] == 1
    assert counts["holds by construction"] == 1


def test_fragile_means_fragile():
    """passmd.ledger.rules: a verdict is fragile when the claim's holding at the point deciding its
    category differs at a runner-up reading (undecided runner-ups do not count), or when its margin is
    within FRAGILE_MARGIN of its tolerance; a failing verdict can be fragile too, an inconclusive one
    cannot. Counter-examples: a margin at 0.5 of the tolerance and the same state at every runner-up."""
    from passmd.ledger.rules import FRAGILE_MARGIN
    from passmd.ledger.verdicts import fragility

    holds, fails, undecided = _point("holds"), _point("fails"), _point("inconclusive")
    assert fragility("reproduced", holds, [("R1", holds), ("R2", undecided)], 0.5) == ""
    assert fragility("reproduced", holds, [("R1", fails)], 0.5).startswith(
        "fails at the runner-up reading R1")
    assert fragility("not reproduced", fails, [("R1", holds), ("R2", holds)], 3.0) == (
        "holds at the runner-up reading R1 and 1 more")
    near = 1.0 - FRAGILE_MARGIN / 2
    assert "within 25% of it" in fragility("reproduced", holds, [], near)  # 8.8 % against a 10 % tolerance
    assert "within 25% of it" in fragility("not reproduced", fails, [], 1.1)  # a failure by a hair
    assert fragility("reproduced", holds, [], 1.0 - 2 * FRAGILE_MARGIN) == ""
    assert fragility("inconclusive", None, [("R1", fails)], 1.0) == ""


def test_a_coarse_grid_decides_only_what_the_paper_grid_would():
    """The coarse-grid rule of passmd.ledger.rules: a check holding on part of the paper's grid is
    inconclusive; a pointwise failure there decides (failures_decide); a failure of a check of the whole
    grid does not. The extractors wrap the quick grids and leave the paper's alone."""
    from passmd.experiments.critical_amplitude_one import claims
    from passmd.experiments.waveform_velocity.claims import on_paper_grid
    from passmd.experiments.waveform_velocity.figures import FREQUENCIES
    from passmd.ledger.verdicts import _evaluate_point

    claim = {"id": "o", "check": "ordering", "relation": ">", "tolerance_num": math.nan,
             "tolerance_kind": "", "paper_value_num": math.nan}
    at = {"x": 1}

    def state(ours):
        return _evaluate_point(claim, lambda results: ours, (), {}, at)

    holds, fails = {"lhs": 2.0, "rhs": 1.0}, {"lhs": 0.5, "rhs": 1.0}
    assert state(holds).state == "holds" and state(fails).state == "fails"
    part = state(checks.Subset(holds, "the paper's preloads 0.1 N"))
    assert part.state == "inconclusive" and part.detail.startswith("holds on this table's part of the grid")
    assert part.detail.endswith("which lacks the paper's preloads 0.1 N")
    assert state(checks.Subset(fails, "0.1 N")).state == "fails"
    assert state(checks.Subset(fails, "0.1 N", failures_decide=False)).state == "inconclusive"
    scoped = state(checks.Subset(checks.Scoped(fails, "outside Eq. 15"), "0.1 N"))
    assert scoped.state == "fails" and scoped.outside == "outside Eq. 15"
    # the extractors' wrappers: the quick grids lack points of the paper's, the paper's lacks none
    wrapped = claims.on_paper_grid(holds, "fig5b", (0.2, 0.6, 1.0))
    assert isinstance(wrapped, checks.Subset) and "0.1, 0.3" in wrapped.missing
    assert claims.on_paper_grid(holds, "fig6c", (0.1, 0.2, 0.3, 0.4, 0.5)) is holds
    for profile, whole in (("quick", False), ("paper", True)):
        part = pd.DataFrame({"frequency_kHz": FREQUENCIES[profile] / 1e3})
        assert (on_paper_grid(holds, part) is holds) == whole


def test_design_is_the_full_product_and_the_short_period_rule_has_both_values():
    """A claim is evaluated on the product of its axes (not one at a time); where Eq. 15's settling time
    does not fit the period, neither cutting it nor skipping it is Eq. 15, so both are readings of the
    claims that rest on it, and a verdict decided only there says so (Scoped)."""
    from passmd.ledger import readings

    points = readings.design(("flyback", "ac_protocol", "damping_ratio"))
    assert len(points) == 2 * 2 * 3 and points[0] == readings.default_reading()
    assert {"flyback": "fixed", "ac_protocol": "first"}.items() <= points[-1].items()
    for claim in ("fig9b-max-gain-2.5mm_s", "abstract-velocity-gain-15pct", "fig10a-max-velocity-19mm_s"):
        assert "short_period" in evaluation.depends_on(claim)
        assert {r["short_period"] for r in readings.design(evaluation.depends_on(claim))} == {"cut", "skip"}
    assert readings.axis("short_period").values() == ("cut", "skip")


def test_each_section_chooses_what_it_leaves_unstated():
    """The paper states its simulations section by section: an unstated input is free per section (μ of
    Section 4.1 and of Section 5 are two free axes, so no Section 5 claim can choose Fig. 5a's μ), a value
    a section states is no axis there (Section 4.2's μ = 0.2), and Table 2's lost damping is one value for
    every section using it. Every claim reads the runs of one section."""
    from passmd.ledger import readings

    free = readings.declared_free_axes()
    assert ("friction_coefficient", "4.1") in free and ("friction_coefficient", "5") in free
    assert ("friction_coefficient", "4.2") not in free and ("damping_ratio", "") in free
    assert ("flyback", "4.1") in free and ("flyback", "4.2") in free and ("flyback", "5") not in free
    for section in readings.SECTIONS.values():
        for key, _, _ in section.stated:
            assert not set(readings.AXES[key].tables) & set(section.tables), (section.key, key)
    claims = load_claims()
    sections = {c["id"]: readings.section_of(c) for _, c in claims.iterrows()}
    assert sections["fig5a-no-step-below-50nm"] == "4.1" and sections["fig10a-1n-slower"] == "5"
    assert sections["fig7-force-depends-on-amplitude"] == "4.2"
    assert sections["fig10b-r1-stiffer-contact"] == ""
    # a claim's reading at a point takes only its own section's values
    point = {**readings.default_point(free), ("friction_coefficient", "5"): 0.3}
    assert readings.claim_reading(point, readings.free_axes(("friction_coefficient",), "4.1"))[
        "friction_coefficient"] == 0.2
    assert readings.claim_reading(point, readings.free_axes(("friction_coefficient",), "5"))[
        "friction_coefficient"] == 0.3
    assert readings.describe_point(point) == "μ (Section 5) = 0.3"
    with pytest.raises(ValueError, match="reads the tables of 4.1 and 5"):
        readings.section_of({"id": "x", "requires": "fig5b_readings;fig9b_readings"})


def test_every_claim_declares_exactly_the_axes_that_change_its_tables():
    """Declared = computed: each claim of the paper is evaluated along exactly the axes that change the
    result tables it reads (passmd.ledger.readings.applicable), so no claim is called independent of an
    input its runs depend on; every axis with alternatives changes some claim's tables."""
    from passmd.ledger import readings

    claims = load_claims()
    functions = evaluation.claim_functions()
    paper = claims[claims["study_of"] == ""]
    for _, claim in paper.iterrows():
        assert set(functions.depends_on[claim["id"]]) == set(readings.applicable(claim)), claim["id"]
    used = {k for _, claim in paper.iterrows() for k in readings.applicable(claim)}
    assert {k for k, a in readings.AXES.items() if a.alternatives} <= used
    # μ changes every table a claim that assumes it reads; ζ only claims with flexible actuators
    assumes_mu = paper["assumed"].str.split(";").map(lambda c: "friction_coefficient" in c)
    assert all("friction_coefficient" in readings.applicable(c) for _, c in paper[assumes_mu].iterrows()
               if c["id"] not in functions.experiment and c["requires"] != "closed_forms")
    assert "damping_ratio" not in functions.depends_on["fig5b-rigid-ac-matches-eq7"]
    assert "damping_ratio" in functions.depends_on["fig5b-flexible-above-rigid"]
    # Section 5 drives at the full stroke, where the two fly-back rules are the same 2 µs
    from passmd.experiments.driving_waveform.figures import section5_fields
    from passmd.model import waveforms
    from passmd.protocols.section5 import section5_drive
    for radius in (1e-3, 0.25e-3):
        drive = section5_drive(**section5_fields(radius))
        full = drive.actuator.full_stroke_amplitude
        assert waveforms.flyback_time(full, drive, "slew") == waveforms.flyback_time(full, drive, "fixed")


def test_unknown_assumption_axis_is_refused():
    with pytest.raises(ValueError, match="assumption axis = 'colour' is not declared"):
        checks.extractor("x", depends_on=("colour",))


def test_missing_extractor_is_an_error_unless_lenient(tmp_path):
    claims = load_claims(_write(tmp_path, SYNTHETIC[:2]))
    module = _tag(_tag(types.ModuleType("synthetic_claims"), "val", lambda results: 100.0),
                  "typo", lambda results: 1.0)
    with pytest.raises(LookupError, match="claim 'ord' has its results but no registered extractor"):
        evaluation.evaluate(claims, {"fig5a": pd.DataFrame()}, modules=[module])
    lenient = evaluation.evaluate(claims, {"fig5a": pd.DataFrame()}, strict=False, modules=[module])
    lenient = lenient.set_index("claim")
    assert lenient.at["ord", "verdict"] == "no extractor registered"
    assert lenient.at["ord", "status"] == "inconclusive"
    assert evaluation.orphan_extractors(claims, modules=[module]) == ["typo"]


def test_claims_for_selects_a_chapters_rows():
    claims = load_claims()
    fig5 = evaluation.claims_for(claims, ["fig5a", "fig5b"])
    assert set(fig5["figure"]) == {"5a", "5b"} and len(fig5) == 5  # their readings tables belong to them
    assert set(fig5["requires"]) == {"fig5a_readings", "fig5b_readings"}
    # a claim needing fig7a and fig7b belongs to a chapter that has both
    assert "fig7-critical-amplitude-both-models" not in set(evaluation.claims_for(claims, "fig7a")["id"])
    both = evaluation.claims_for(claims, ["fig7a", "fig7b"])
    assert "fig7-critical-amplitude-both-models" in set(both["id"])


def test_extractor_errors_name_the_claim(tmp_path):
    claims = load_claims(_write(tmp_path, SYNTHETIC[1:2]))
    module = _tag(types.ModuleType("synthetic_claims"), "ord",
                  lambda results: results["fig5a"]["missing_column"])
    with pytest.raises(checks.ExtractorError, match="claim 'ord' \\(ordering check\\)"):
        evaluation.evaluate(claims, {"fig5a": pd.DataFrame()}, modules=[module])


def test_not_evaluable_from_extractor(tmp_path):
    claims = load_claims(_write(tmp_path, SYNTHETIC[:1]))

    def _coarse(results):
        raise checks.NotEvaluable("quick grid has no point at 100 Hz")

    module = _tag(types.ModuleType("synthetic_claims"), "val", _coarse)
    evaluated = evaluation.evaluate(claims, {"fig5a": pd.DataFrame()}, modules=[module])
    assert evaluated.at[0, "status"] == "inconclusive"
    assert evaluated.at[0, "verdict"] == ("not decided at its held-out reading: quick grid has no point at "
                                          "100 Hz")


def test_any_category_change_fails_with_a_readable_diff(tmp_path):
    """Every change of category against the baseline fails, not only a lost 'reproduced'."""
    claims = load_claims(_write(tmp_path, SYNTHETIC))
    module = _good_module()
    results = {"fig5a": pd.DataFrame()}
    baseline_path = tmp_path / "baseline.csv"
    evaluation.write_baseline(evaluation.evaluate(claims, results, modules=[module]), baseline_path,
                          header="made by a test\non a day")
    assert baseline_path.read_text().startswith("# made by a test\n# on a day\nclaim,status,readings,states,"
                                                "held_out,joint\n")
    # the readings each category was computed at (these synthetic claims depend on no axis), the
    # state at each, and the point besides the defaults its category was judged at
    assert evaluation.load_baseline_readings(baseline_path)["val"] == ("defaults",)
    assert evaluation.load_baseline_states(baseline_path)["other"] == {
        "states": {"defaults": "inconclusive"}, "held_out": "defaults", "joint": "defaults"}
    baseline = evaluation.load_baseline(baseline_path)
    assert baseline["val"] == "reproduced" and baseline["other"] == "inconclusive"
    unchanged = evaluation.evaluate(claims, results, modules=[module])
    evaluation.check_categories(unchanged, baseline)  # unchanged: fine
    _tag(module, "val", lambda results: 90.0)  # the model drifts 10 % away from the paper
    with pytest.raises(AssertionError, match="val: reproduced -> not reproduced"):
        evaluation.check_categories(evaluation.evaluate(claims, results, modules=[module]), baseline)
    # an inconclusive claim that becomes decidable is a change too (review it, then record it)
    _tag(module, "val", lambda results: 100.0)
    changed = evaluation.category_changes(
        evaluation.evaluate(claims, {**results, "fig9b": pd.DataFrame()}, modules=[module]), baseline)
    assert changed[["claim", "baseline", "now"]].values.tolist() == [["other", "inconclusive", "reproduced"]]


# --------------------------------------------------------------------------------------
# extractor tags, results, presentation
# --------------------------------------------------------------------------------------

def test_collect_results_computes_what_the_claims_require_and_any_figure_named(monkeypatch):
    """By default only the tables claims.csv's ``requires`` name (fig6b_readings) and their figures
    (fig6b) are computed, a chapter's other figure is not; an explicit list may name any table."""
    calls = []

    def _computed(config):
        calls.append(config)
        return pd.DataFrame({"amplitude_nm": [1.0]})

    def _not_required(config):
        raise AssertionError("a figure no claim requires was computed")

    table = {"design_example": types.SimpleNamespace(compute=_not_required),
             "fig6b": types.SimpleNamespace(compute=_computed)}
    monkeypatch.setattr(figure_table, "figure_names", lambda: list(table))
    monkeypatch.setattr(figure_table, "figure_spec", lambda name: table[name])
    reading_tables = {"fig6b_readings": types.SimpleNamespace(compute=_computed, figures=("fig6b",)),
                      "fig99_readings": types.SimpleNamespace(compute=_not_required, figures=("fig99",))}
    monkeypatch.setattr(figure_table, "READING_TABLES", reading_tables)
    assert list(evaluation.result_sources()) == [*table, *reading_tables, "closed_forms"]
    results = evaluation.collect_results(QUICK)
    assert list(results) == ["fig6b", "fig6b_readings", "closed_forms"]
    assert calls == [QUICK, QUICK]
    pd.testing.assert_frame_equal(results["closed_forms"], reference.tangential_stiffness_table())
    with pytest.raises(AssertionError, match="no claim requires"):
        evaluation.collect_results(QUICK, figures=["design_example"])
    with pytest.raises(TypeError, match="config = 'quick' is not allowed: "
                       "must be a passmd.runtime.config.RunConfig"):
        evaluation.collect_results("quick")
    with pytest.raises(ValueError, match="are not available"):
        evaluation.collect_results(QUICK, figures=["fig9z"])
    table["fig5b"] = types.SimpleNamespace(compute=lambda config: [1, 2])
    with pytest.raises(TypeError, match="not a DataFrame"):
        evaluation.collect_results(QUICK, figures=["fig5b"])


def test_the_default_results_are_every_table_a_claim_requires_and_no_other(monkeypatch):
    """The ledger's default tables are the union of claims.csv's ``requires`` (each available) and the
    figures of its reading tables (their defaults, e.g. the fig8a an evidence line reads), so the
    figures only a chapter shows (the design maps, the calibration fits) cost it nothing."""
    named = {key for keys in load_claims()["requires"] for key in keys.split(";") if key}
    required = named | {name for key in named if key in figure_table.READING_TABLES
                        for name in figure_table.READING_TABLES[key].figures}
    assert "fig8a" in required - named
    computed = []
    sources = {key: (lambda config, key=key: computed.append(key) or pd.DataFrame())
               for key in evaluation.result_sources()}
    assert required <= set(sources)
    monkeypatch.setattr(evaluation, "result_sources", lambda: sources)
    evaluation.collect_results(QUICK)
    assert set(computed) == required
    assert not any(key.startswith(("design_", "calibration_")) for key in computed)


def test_tags_only_mark_the_function():
    with pytest.raises(ValueError, match="claim_id = 'Bad Id' is not allowed"):
        checks.extractor("Bad Id")
    with pytest.raises(ValueError, match="claim_id = 3 is not allowed"):
        checks.evidence(3)

    def first(results, reading):
        return 1.0

    assert checks.extractor("x", depends_on=["flyback"])(first) is first
    assert (first.claim_extractor, first.claim_depends_on) == ("x", ("flyback",))
    assert "x" not in evaluation.extractors()  # tagging registers nothing anywhere


def test_collect_claim_functions_finds_each_claim_once():
    def first(results):
        return 1.0

    def second(results):
        return 2.0

    def lines(results):
        return ["a line"]

    one = types.SimpleNamespace(first=checks.extractor("x")(first), helper=len, number=3)
    # the same function reached twice (imported into a second module) counts once
    found = checks.collect_claim_functions([one, types.SimpleNamespace(alias=first)])
    assert dict(found.extractors) == {"x": first} and dict(found.depends_on) == {"x": ()}
    # functions made in a loop are found in a module-level tuple
    made = types.SimpleNamespace(EVIDENCE=(checks.evidence("x")(lines), "not a function"))
    assert dict(checks.collect_claim_functions([one, made]).evidence) == {"x": lines}
    two = types.SimpleNamespace(second=checks.extractor("x")(second))
    with pytest.raises(ValueError, match="claim 'x' is claimed twice .*first and .*second"):
        checks.collect_claim_functions([one, two])


def test_real_extractors_live_in_the_figures_claim_modules():
    """Every extractor of the package is found in passmd.experiments.figure_table.CLAIM_MODULES (and the
    ledger's own
    closed-form one), and the experiments do not import the ledger (the layers are one-way)."""
    found = evaluation.claim_functions()
    homes = {f.__module__ for f in found.extractors.values()}
    assert homes == {m.__name__ for m in figure_table.CLAIM_MODULES} | {"passmd.report.evaluation"}
    assert found.extractors["fig10b-r1-stiffer-contact"].__module__ == "passmd.report.evaluation"
    assert found.depends_on["fig5a-no-step-below-50nm"] == (
        "flyback", "ac_protocol", "drive_frequency_s4", "damping_ratio", "friction_coefficient")
    assert {"fig10a-1n-slower", "sec5-response-to-optimized-similar"} <= set(found.evidence)
    assert evaluation.orphan_extractors() == []
    code = ("import sys; import " + ", ".join(m.__name__ for m in figure_table.CLAIM_MODULES)
            + "; print(sorted(m for m in sys.modules if m.startswith('passmd.report.evaluation')))")
    imported = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert imported.stdout.strip() == "[]"


def test_real_ledger_closed_form_claim_is_labelled_and_the_rest_wait():
    claims = load_claims()
    results = {"closed_forms": evaluation.closed_form_results(QUICK)}
    evaluated = evaluation.evaluate(claims, results).set_index("claim")
    # a closed-form identity holds by construction: shown, never a reproduced simulation
    assert evaluated.at["fig10b-r1-stiffer-contact", "status"] == "holds by construction"
    assert evaluated.at["fig10b-r1-stiffer-contact", "basis"] == "closed form"
    others = evaluated.drop(index="fig10b-r1-stiffer-contact")
    assert (others["status"] == "inconclusive").all()
    assert others["verdict"].str.startswith("needs results: ").all()
    text = ledger_views.summary(evaluated.reset_index())
    assert text.startswith("0 of ") and "1 holds by construction" in text


def test_styled_one_line_per_claim_and_details(tmp_path):
    claims = load_claims(_write(tmp_path, SYNTHETIC))
    evaluated = evaluation.evaluate(claims, {"fig5a": pd.DataFrame()}, modules=[_good_module({"val": 150.0})])
    html = ledger_views.styled(evaluated, links=True).to_html()
    assert 'class="passmd-ledger"' in html and 'href="#claim-val"' in html
    for status in ("reproduced", "not reproduced", "inconclusive"):
        assert ledger_views.STATUS_COLOURS[status] in html
    # one line per claim: the category, ours against the paper with units, the one reason, the readings
    table = ledger_views.styled(evaluated).data.set_index("claim")
    assert list(table.columns) == ["category", "ours vs paper", "why", "readings"]
    assert table.at["val", "ours vs paper"] == "150 nm vs the paper's 100 nm"
    assert table.at["ord", "ours vs paper"] == "2 mm/s vs 1 mm/s; paper: q"  # no 'compares': the quantity
    # cells are HTML: a relation's '<' is escaped, never read as a tag
    named = claims.copy()
    named.loc[named["id"] == "ord", "compares"] = "a | b"
    named.loc[named["id"] == "ord", "relation"] = "<"
    module = _good_module({"val": 150.0})
    _tag(module, "ord", lambda results: {"lhs": 2.0, "rhs": 1.0})
    again = evaluation.evaluate(named, {"fig5a": pd.DataFrame()}, modules=[module])
    assert "a &lt; b fails" in ledger_views.styled(again).to_html()
    assert table.at["val", "why"] == "deviation 50 % exceeds the tolerance 5 %"
    assert table.at["val", "readings"] == "holds 0, fails 1, undecided 0 of 1"
    details = ledger_views.details_markdown(evaluated, claims)
    assert "(ledger-not-reproduced)=" in details and "(claim-val)=" in details
    assert "deviation 50 % exceeds the tolerance 5 %" in details
    headline = ledger_views.headline_markdown(evaluated)
    assert "[1 not reproduced](replication_report.md#ledger-not-reproduced)" in headline
    assert "0 reproduced under the joint reading" in headline and "held-out reading" in headline


def test_assumptions_table_lists_the_registered_assumptions():
    table = ledger_views.assumptions_table()
    expected = {"actuator_viscosity", "preload_grids", "friction_coefficient_sections_4_1_and_5"}
    assert expected <= set(table["key"])
    assert table["rationale"].str.len().min() > 0


def test_sources_markdown_escapes_markup_and_marks_assumptions():
    claims = load_claims().set_index("id", drop=False)
    two = claims.loc[["fig6b-flexible-r1-ac-matches-eq12", "fig9a-step-increase-46.8pct"]]
    text = ledger_views.sources_markdown(two)
    assert text.count("\n* **") == 1 and text.startswith("* **fig6b-flexible-r1-ac-matches-eq12**")
    assert "u\\*\\_x,max,e" in text  # 'u*_x,max,e' must not start italics in MyST
    assert "μ = 0.2 (assumed)" in text and "F\\_p on the preload grid" in text
    assert "*Check:* value, tolerance 20 %." in text


def test_ledger_command_prints_categories_and_si_json(monkeypatch, capsys):
    """`passmd ledger --json` gives every claim's computed category with SI keys."""
    import io
    import json

    from passmd import cli

    calls = []

    def closed_forms_only(config):
        calls.append(config.profile)
        return {"closed_forms": evaluation.closed_form_results(config)}

    monkeypatch.setattr(evaluation, "collect_results", closed_forms_only)
    out = io.StringIO()
    assert cli.main(["ledger", "--profile", "paper", "--json"], out=out) == 0
    payload = json.loads(out.getvalue())
    assert calls == ["paper"] and payload["profile"] == "paper"
    claims = {c["claim"]: c for c in payload["claims"]}
    assert set(claims) == set(load_claims()["id"])
    stiffer = claims["fig10b-r1-stiffer-contact"]
    assert stiffer["category"] == "holds by construction" and stiffer["basis"] == "closed form"
    assert stiffer["readings"] == {"defaults": "holds"} and stiffer["evidence"]
    assert stiffer["held_out_reading"] == {} and stiffer["held_out_state"] == "holds"
    waiting = claims["fig9a-standard-position-552nm"]
    assert waiting["category"] == "inconclusive" and waiting["paper_m"] == pytest.approx(552e-9)
    assert waiting["held_out_reading"] == {} and waiting["held_out_state"] == "—"  # not evaluated: no results
    flags = ("fragile", "not informative", "about the experiment", "counted with their family", "studies")
    categories = {k: n for k, n in payload["counts"].items() if k not in flags}
    # the categories count the claims of the paper, each family once; implied rows and studies are shown
    implied = int(((load_claims()["implied_by"] != "")).sum())
    assert payload["counts"]["counted with their family"] == implied > 0
    assert sum(categories.values()) + payload["counts"]["studies"] + implied == len(claims)
    assert payload["counts"]["studies"] == int((load_claims()["study_of"] != "").sum()) > 0
    assert payload["joint_reading"]["held_out_counts"] == categories
    text = io.StringIO()
    assert cli.main(["ledger"], out=text) == 0
    assert "fig10b-r1-stiffer-contact: holds by construction (closed form)" in text.getvalue()
    assert cli.main(["ledger", "--workers", "0"], out=io.StringIO()) == 2
    assert "--workers = 0 is out of range" in capsys.readouterr().err


def test_baseline_readings_of_a_claim_along_several_axes(tmp_path):
    """A baseline records every reading of a claim's design; one without the column records none."""
    readings_ = evaluation.claim_readings("fig6b-flexible-r1-ac-matches-eq12")
    assert readings_[0] == "defaults" and "actuator damping ratio ζ = 0.005" in readings_
    path = tmp_path / "old.csv"
    path.write_text("# made before readings were recorded\nclaim,status\nval,reproduced\n", encoding="utf-8")
    assert evaluation.load_baseline_readings(path) == {}
    assert evaluation.load_baseline(path) == {"val": "reproduced"}


def test_reading_tables_hold_the_full_product():
    """The A_c readings of a flexible panel hold every point of fly-back × A_c protocol × drive frequency
    × ζ × μ, a rigid panel every point but ζ; the force readings every point of fly-back × ζ × drive
    frequency; each default point is the figure's own run (the same sweep parameters)."""
    from passmd.experiments.critical_amplitude_one import figures
    from passmd.ledger import readings

    rigid_axes = tuple(k for k in figures._AC_AXES if k != "damping_ratio")
    for model, axes in (("flexible", figures._AC_AXES), ("rigid", rigid_axes)):
        points = figures._reading_points(model, figures._AC_AXES)
        assert len(points) == len({tuple(sorted(p.items())) for p in points}) == len(readings.design(axes))
    figure_combos = figures._protocols("flexible", (100.0,))
    default = figures._reading_points("flexible", figures._AC_AXES)[0]
    zeta = default["damping_ratio"]
    assert default in [{**c, "damping_ratio": c.get("damping_ratio", zeta)} for c in figure_combos]


def test_force_readings_at_a_reading():
    """This paper's force runs at a reading come from fig7_readings by fly-back rule, ζ and frequency;
    a reading the table lacks is a missing run, not an undecided point."""
    from passmd.experiments.force_generation import claims
    from passmd.ledger import readings

    table = pd.DataFrame({"flyback": ["slew", "fixed"], "damping_ratio": [0.05, 0.05],
                          "frequency_Hz": [100.0, 100.0], "generated_force_mN": [1.0, 2.0]})
    reading = {**readings.default_reading(), "flyback": "fixed"}
    assert claims.readings_at({"fig7_readings": table}, reading)["generated_force_mN"].tolist() == [2.0]
    with pytest.raises(checks.NoRun, match="ζ = 0.5"):
        claims.readings_at({"fig7_readings": table}, {**reading, "damping_ratio": 0.5})
    assert "fig7_readings" in evaluation.result_sources()


def test_held_out_passes_hold_together_at_one_point():
    """Held-out judging never counts a union of readings: on random ledgers (claims over three axes with
    random states, some in families), every unit holding at its held-out reading holds at the in-sample
    joint reading, so the held-out passes never outnumber the claims holding at one point; a unit
    failing in-sample is judged at the in-sample reading itself. Counter-check: the in-sample reading
    differs from some held-out ones, so the property is not vacuous."""
    from passmd.ledger import readings
    from passmd.ledger.joint import judge
    from passmd.ledger.verdicts import PointResult

    rng = np.random.default_rng(47)
    axes = ("flyback", "ac_protocol", "drive_frequency_s4")
    design = readings.design(axes)
    moved = 0
    for _ in range(200):
        n = int(rng.integers(3, 8))
        evaluated, families = {}, {}
        for k in range(n):
            mine = axes[:int(rng.integers(1, 4))]
            states = rng.choice(["holds", "fails", "inconclusive"], p=[0.45, 0.45, 0.1], size=len(design))
            points, seen = [], {}
            for reading, state in zip(design, states, strict=True):
                key = tuple(reading[a] for a in mine)
                state = seen.setdefault(key, state)
                if key in {tuple(p.reading[a] for a in mine) for p in points}:
                    continue
                points.append(PointResult(readings.project(reading, mine), state, None, state))
            evaluated[f"c{k}"] = (points, mine)
            families[f"c{k}"] = "c0" if k == n - 1 and n > 3 else f"c{k}"
        joint = judge(evaluated, dict.fromkeys(evaluated, "4.1"), families, set(families.values()))
        best = joint["best"]
        passes = 0
        for unit in joint["units"]:
            codes = joint["unit_states"][unit.lead]
            at = joint["held_out"][unit.lead]
            moved += at != best
            if codes[at] == 1:
                passes += 1
                assert codes[best] == 1, (unit.lead, at, best)
            elif codes[best] != 1:
                assert at == best
        assert passes <= joint["best_single_point"]
    assert moved > 0
