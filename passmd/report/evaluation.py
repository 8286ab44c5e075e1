"""The replication ledger: every claim of the paper, checked against the chapters' computed results.

Three pieces meet here:

* **claims**: ``passmd/data/reference/claims.csv``, read and validated by
  :func:`passmd.ledger.claims.load_claims`; rows without a quotation of the paper are studies,
  shown and never counted (:mod:`passmd.ledger.rules`);
* **results**: the figure table of ``passmd.experiments.figure_table`` (``fig5a`` … ``fig10c``, shared with
  the book and the CLI), the tables of the ledger's readings
  (``passmd.experiments.figure_table.READING_TABLES``: every run at every point of the axes that
  change it) and the ledger's own ``closed_forms`` table; :func:`collect_results` computes those
  the claims require (claims.csv's ``requires``, with the figures of its reading tables), so a
  chapter never lists them and its other figures cost the ledger nothing;
* **extractors**: functions ``(results[, reading]) -> ours`` tagged with
  :func:`passmd.ledger.checks.extractor` in the modules
  ``passmd.experiments.figure_table.CLAIM_MODULES`` lists
  (and the closed-form one here); they turn the result tables into what the claim's check
  needs (:mod:`passmd.ledger.checks` says what, for each check kind).

:func:`evaluate` runs the checks over the readings of the assumption space
(:mod:`passmd.ledger.readings`: each claim on the full product of the axes that change the
tables it reads) and computes every claim's category (:data:`passmd.ledger.claims.STATUSES`) from its
state at one reading, its held-out reading: the joint reading chosen from all the other claims
(:mod:`passmd.ledger.joint`), with its evidence, its fragility and the tensions between claims; no
category is typed in. :mod:`passmd.report.ledger_views` presents them in the
book; :mod:`passmd.ledger.baseline` compares them with a committed baseline in the tests, and
:func:`records` gives them to ``passmd ledger --json``.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Iterable, Mapping

import pandas as pd

from passmd.experiments import figure_table
from passmd.ledger import readings, reference
from passmd.ledger.baseline import (  # re-exported: the tests and the command line read them from here
    READINGS_SEPARATOR,
    category_changes,
    check_categories,
    load_baseline,
    load_baseline_readings,
    load_baseline_states,
    readings_of,
    write_baseline,
)
from passmd.ledger.checks import ClaimFunctions, collect_claim_functions, extractor
from passmd.ledger.claims import REPRODUCED, STATUSES, family_of, is_study, load_claims, required_keys
from passmd.ledger.export import SI_UNITS, records  # re-exported: passmd ledger --json
from passmd.ledger.joint import conflicting_pairs, held_out_judgements, judge, map_columns, tensions, variants
from passmd.ledger.joint import joint_map as joint_map  # the ledger's views read it from here too
from passmd.ledger.joint import joint_record as joint_record
from passmd.ledger.verdicts import (
    EXPERIMENT_BASIS,
    NO_EXTRACTOR,
    claim_points,
    claim_row,
    not_informative,
)
from passmd.runtime.config import RunConfig

__all__ = [
    "LEDGER_COLUMNS",
    "READINGS_SEPARATOR",
    "SI_UNITS",
    "assumption_map",
    "category_changes",
    "chapter_rows",
    "check_categories",
    "claim_functions",
    "claim_modules",
    "claim_readings",
    "claims_for",
    "closed_form_results",
    "collect_results",
    "counted",
    "depends_on",
    "evaluate",
    "extractors",
    "headline",
    "load_baseline",
    "load_baseline_readings",
    "load_baseline_states",
    "orphan_extractors",
    "records",
    "result_sources",
    "write_baseline",
]

#: Columns of :func:`evaluate`'s result.
LEDGER_COLUMNS = ("claim", "figure", "quantity", "paper", "ours", "ours_text", "unit", "abs_deviation",
                  "rel_deviation", "tolerance", "status", "verdict", "why", "evidence", "reason", "basis",
                  "study_of", "family", "counted", "check", "depends_on", "readings", "holds_at", "fails_at",
                  "decided_at", "undecided_at", "fraction_holds", "best_reading", "default_state",
                  "held_out_reading", "held_out_state", "joint_reading", "joint_state", "margin",
                  "margin_text", "fragile", "fragile_reason", "outside", "informative", "not_informative",
                  "note")


# ======================================================================================
# Extractors and results
# ======================================================================================


def claim_modules() -> tuple:
    """The modules holding claim extractors: ``passmd.experiments.figure_table.CLAIM_MODULES`` and this one
    (the closed-form claim's extractor)."""
    return (*figure_table.CLAIM_MODULES, sys.modules[__name__])


def claim_functions(modules: Iterable | None = None) -> ClaimFunctions:
    """The extractors, their ``depends_on`` and the evidence functions of ``modules``
    (default :func:`claim_modules`), by claim id (:func:`passmd.ledger.checks.collect_claim_functions`)."""
    return collect_claim_functions(claim_modules() if modules is None else modules)


def extractors(modules: Iterable | None = None) -> dict[str, Callable]:
    """The extractors ``{claim id: function}`` of ``modules`` (default :func:`claim_modules`)."""
    return dict(claim_functions(modules).extractors)


def depends_on(claim_id: str, modules: Iterable | None = None) -> tuple[str, ...]:
    """The assumption axes a claim's extractor reads (empty: evaluated at the defaults only)."""
    return claim_functions(modules).depends_on.get(claim_id, ())


def _check_config(config) -> RunConfig:
    if not isinstance(config, RunConfig):
        raise TypeError(f"config = {config!r} is not allowed: must be a passmd.runtime.config.RunConfig")
    return config


def _figure_source(name: str) -> Callable[[RunConfig], pd.DataFrame]:
    return figure_table.figure_spec(name).compute


def result_sources() -> dict[str, Callable[[RunConfig], pd.DataFrame]]:
    """Every available result table: ``{key: compute(config) -> DataFrame}``.

    The figures of ``passmd.experiments.figure_table`` (in the table's order), the tables of the
    ledger's readings (``passmd.experiments.figure_table.READING_TABLES``: every run a claim reads,
    at every point of the axes that change it) and ``closed_forms`` (the closed-form tables some
    claims are checked against, :func:`closed_form_results`).
    """
    sources = {name: _figure_source(name) for name in figure_table.figure_names()}
    sources.update({key: spec.compute for key, spec in figure_table.READING_TABLES.items()})
    sources["closed_forms"] = closed_form_results
    return sources


def collect_results(config: RunConfig, figures: Iterable[str] | None = None) -> dict[str, pd.DataFrame]:
    """Compute the result tables the claims require: the ledger's single entry point.

    Parameters
    ----------
    config : passmd.runtime.config.RunConfig
        How to run; its ``profile`` (``"quick"`` for CI, ``"paper"`` for the paper's grids)
        selects the grids of each figure.
    figures : iterable of str, optional
        Only these keys (each must be available, any of :func:`result_sources`); default the
        keys claims.csv's ``requires`` name (:func:`passmd.ledger.claims.load_claims`) and the
        figures of the reading tables among them (their runs at the defaults, which extractors
        and evidence read), in the order of :func:`result_sources`.

    Returns
    -------
    dict
        ``{key: DataFrame}``. Figures not in the table are simply absent; their claims
        are then *inconclusive*.
    """
    _check_config(config)
    available = result_sources()
    if figures is None:
        required = {key for _, claim in load_claims().iterrows() for key in required_keys(claim)}
        required |= {name for key in required for name in _figures_of(key)}  # a reading table's defaults
        keys = [key for key in available if key in required]
    else:
        keys = list(figures)
    unknown = [k for k in keys if k not in available]
    if unknown:
        raise ValueError(f"figures = {unknown!r} are not available: must be among {', '.join(available)}")
    results = {}
    for key in keys:
        table = available[key](config)
        if not isinstance(table, pd.DataFrame):
            raise TypeError(f"figure function for {key!r} returned {type(table).__name__}, not a DataFrame")
        results[key] = table
    return results


# ======================================================================================
# Evaluation
# ======================================================================================


def counted(evaluated: pd.DataFrame) -> pd.DataFrame:
    """The rows of an :func:`evaluate` result that are counted: claims of the paper, each family once (its
    lead row), studies and rows implied by another left out."""
    keep = evaluated["study_of"] == ""
    if "counted" in evaluated:
        keep &= evaluated["counted"].astype(bool)
    return evaluated[keep]


def _design_problems(claim: Mapping, functions: ClaimFunctions, points) -> list[str]:
    """Why a claim's evaluation is incomplete: its extractor does not declare an axis that changes a
    table it reads (:func:`passmd.ledger.readings.applicable`), or a table holds no run at a point."""
    problems = []
    declared = functions.depends_on.get(claim["id"], ())
    missing = [k for k in readings.applicable(claim) if k not in declared]
    if claim["id"] in functions.extractors and missing:
        problems.append(f"claim {claim['id']!r} reads tables that {', '.join(missing)} change"
                        f"{'s' if len(missing) == 1 else ''}, but its extractor does not declare "
                        f"{'it' if len(missing) == 1 else 'them'}")
    problems.extend(f"claim {claim['id']!r} has no run at {readings.describe(p.reading)}: {p.detail}"
                    for p in points if p.no_run)
    return problems


def evaluate(
    claims: pd.DataFrame | None = None,
    results: Mapping[str, pd.DataFrame] | None = None,
    *,
    config: RunConfig | None = None,
    strict: bool = True,
    modules: Iterable | None = None,
) -> pd.DataFrame:
    """Evaluate every claim against the result tables, over its readings of the assumption space.

    Each claim is checked at every reading of :func:`passmd.ledger.readings.design` (the full product of the
    axes that change the tables it reads, the defaults first). Each claim of the paper is then judged at
    one reading, its *held-out* reading: the point of the space where the most of the *other* claims
    hold together (:func:`passmd.ledger.joint.judge`: a row implied by another counted once with it, rows
    that cannot fail and claims about the experiment not voting). Its category
    (``passmd.ledger.verdicts.category``) comes from its state there:

    * ``reproduced``: it holds there and at the defaults;
    * ``reproduced under the joint reading``: it holds there, not at the defaults;
    * ``holds by construction``: it holds there, and its check cannot fail on any result the model can
      produce (never counted as reproduced);
    * ``not reproduced``: it fails there; the verdict names another reading where it holds, if any, and
      the claims that reading breaks;
    * ``inconclusive``: it is undecided there (an extremum the grid cannot locate, a tie within the
      resolution, non-finite values, missing results, no measured data for a claim about the
      experiment), or its held-out reading rests on claims a coarser grid than the paper's leaves
      undecided while its own state varies over its readings (not decided on that grid).

    A family (a row and the rows ``implied_by`` it) is counted once, on its lead row, with the state of
    the conjunction of its members. Studies (rows without a quotation, :mod:`passmd.ledger.rules`) are
    checked at the defaults and counted nowhere. The table's ``attrs`` carry ``points`` (every claim at
    every evaluated reading), ``joint`` (the in-sample joint reading, with ``held_out_counts``,
    ``in_sample_gain`` (the claims that hold only in-sample), ``best_single_point`` and ``variants``),
    ``conflicts`` (:func:`~passmd.ledger.joint.conflicting_pairs`) and ``tensions``.

    NaN never counts as holding (:class:`passmd.ledger.checks.NotEvaluable`). Claims whose ``requires``
    are only ``closed_forms`` have ``basis`` "closed form" and are not simulation results.

    Parameters
    ----------
    claims : pandas.DataFrame, optional
        From :func:`passmd.ledger.claims.load_claims` (the default: every claim of claims.csv).
    results : dict, optional
        ``{result key: DataFrame}``, e.g. from :func:`collect_results`; default
        ``collect_results(config)``.
    config : passmd.runtime.config.RunConfig, optional
        The run configuration the results are computed with when ``results`` is not given.
    strict : bool
        If True (default), raise ``LookupError`` when a claim's results are present but no
        extractor is tagged for it, when its extractor does not declare an axis that changes a table
        it reads, or when a table holds no run at one of its readings (a defect, never "not covered").
        If False, such claims are evaluated as far as they go, a missing run inconclusive.
    modules : iterable of modules, optional
        Where the extractors and evidence functions are looked up; default :func:`claim_modules`.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`LEDGER_COLUMNS`: ``paper`` as shown, ``ours`` and ``ours_text`` (with units) at the
        held-out reading, ``abs_deviation`` (in ``unit``) and ``rel_deviation`` (fraction) there,
        ``status`` (the category, one of :data:`passmd.ledger.claims.STATUSES`), ``verdict`` (one computed
        line), ``why`` (the one reason: the check's finding at the held-out reading), ``evidence``
        (computed lines, ``" | "``-separated), ``reason`` (claims.csv's human reason), ``basis``,
        ``study_of``, ``family`` (the lead of its family, empty for a claim implied by none) and
        ``counted``, ``readings`` (evaluated), ``holds_at``, ``fails_at``, ``decided_at`` and
        ``undecided_at`` (of its readings), ``fraction_holds``, ``best_reading``, ``depends_on``,
        ``default_state``, ``held_out_reading`` and ``held_out_state``, ``joint_state`` (in-sample),
        ``margin`` with ``margin_text``, ``fragile`` with ``fragile_reason`` (:mod:`passmd.ledger.rules`),
        ``outside`` (where the deciding data lie outside a method's validity), ``informative`` and
        ``not_informative`` (why its check cannot fail, from the extractor).
    """
    if results is None:
        if config is None:
            raise ValueError("evaluate needs results or a config to compute them with (config = None)")
        results = collect_results(config)
    claims = load_claims() if claims is None else claims
    functions = claim_functions(modules)
    evaluated, problems = {}, []
    for _, claim in claims.iterrows():
        points, why = claim_points(claim, results, functions)
        if strict and why == NO_EXTRACTOR:
            problems.append(f"claim {claim['id']!r} has its results but no registered extractor")
        if strict and not is_study(claim):
            problems.extend(_design_problems(claim, functions, points))
        evaluated[claim["id"]] = (points, functions.depends_on.get(claim["id"], ()))
    if problems:
        raise LookupError("ledger evaluation is incomplete:\n  " + "\n  ".join(problems))
    by_id = claims.set_index("id")
    studies = {c for c, row in by_id.iterrows() if is_study(row)}
    sections = {c: readings.section_of(row) for c, row in by_id.iterrows()}
    families = {c: family_of({**row, "id": c}) for c, row in by_id.iterrows() if c not in studies}
    claims_of_paper = {c: v for c, v in evaluated.items() if c not in studies}
    voters = {c for c, (points, _) in claims_of_paper.items()
              if points and c not in functions.experiment and not not_informative(functions, c)}
    joint = judge(claims_of_paper, sections, families, voters)
    judgements = held_out_judgements(joint, studies)
    rows, point_rows = [], []
    for _, claim in claims.iterrows():
        points, depends = evaluated[claim["id"]]
        row, _ = claim_row(claim, results, functions, judged=judgements[claim["id"]], points=points or None)
        rows.append(row)
        point_rows.extend({"claim": claim["id"], "reading": readings.describe(p.reading),
                           "point": {k: p.reading[k] for k in depends if k in p.reading},
                           "state": p.state, "detail": p.detail, "outside": p.outside,
                           "score": (p.outcome.score if p.outcome is not None
                                     and math.isfinite(p.outcome.score) else None)} for p in points)
    table = pd.DataFrame(rows, columns=list(LEDGER_COLUMNS))
    table.attrs["points"] = point_rows
    counted_rows = [r for r in rows if r["counted"] and r["claim"] not in studies]
    conflicts = conflicting_pairs(joint["states"], voters)
    gain = [r["claim"] for r in counted_rows if r["claim"] in voters and r["status"] not in REPRODUCED
            and joint["unit_states"][r["claim"]][joint["best"]] == 1]
    table.attrs["joint"] = {
        **{k: v for k, v in joint.items() if k not in ("states", "units", "unit_states", "held_out", "best",
                                                        "grid_bound")},
        "reading": joint["point"],
        "held_out_counts": {s: sum(r["status"] == s for r in counted_rows) for s in STATUSES},
        "in_sample_gain": gain,
        "variants": variants(claims_of_paper, sections, families, voters,
                             [r for r in rows if r["claim"] not in studies],
                             {c: evaluated[c] for c in studies}),
    }
    table.attrs["conflicts"] = conflicts
    table.attrs["tensions"] = tensions(joint["states"], conflicts)
    table.attrs["joint_map"] = map_columns(joint)
    return table


def headline(evaluated: pd.DataFrame) -> dict:
    """Counts per category of the claims of the paper, each family once (judged at its held-out
    reading), plus the fragile rows, the rows whose check is not informative, the claims about the
    experiment, the rows counted with their family and the studies (shown, not counted)."""
    claims = counted(evaluated)
    counts = {s: int((claims["status"] == s).sum()) for s in STATUSES}
    counts["fragile"] = int(claims["fragile"].astype(bool).sum())
    counts["not informative"] = int((~claims["informative"].astype(bool)).sum())
    counts["about the experiment"] = int((claims["basis"] == EXPERIMENT_BASIS).sum())
    counts["counted with their family"] = int(((evaluated["study_of"] == "") & ~evaluated["counted"]).sum())
    counts["studies"] = int((evaluated["study_of"] != "").sum())
    return counts


def assumption_map(evaluated: pd.DataFrame) -> pd.DataFrame:
    """The claims × readings map of an :func:`evaluate` result.

    One row per claim that depends on at least one axis; one column per evaluated reading
    (``"defaults"`` and ``"<axis label> = <value>"``); cells ``holds``, ``fails``,
    ``inconclusive``, or empty where the claim does not depend on that axis. Then ``holds at``
    (readings where it holds, of those evaluated) and ``best reading`` (where it holds best).
    """
    points = pd.DataFrame(evaluated.attrs.get("points", []),
                          columns=["claim", "reading", "point", "state", "detail", "score"])
    varied = points.groupby("claim")["reading"].transform("size") > 1
    points = points[varied]
    if points.empty:
        return pd.DataFrame(columns=["claim"])
    columns = ["defaults"] + [r for r in dict.fromkeys(points["reading"]) if r != "defaults"]
    table = points.pivot(index="claim", columns="reading", values="state").reindex(columns=columns)
    order = [c for c in evaluated["claim"] if c in table.index]
    table = table.loc[order].fillna("").reset_index()
    summary_ = evaluated.set_index("claim").loc[order]
    table["holds at"] = [f"{int(h)} of {int(n)}" for h, n in zip(summary_["holds_at"], summary_["readings"],
                                                                   strict=True)]
    table["best reading"] = summary_["best_reading"].to_numpy()
    return table


def _figures_of(key: str) -> tuple[str, ...]:
    """The figures a result key belongs to: a reading table's figures, else the key itself."""
    spec = figure_table.READING_TABLES.get(key)
    return spec.figures if spec is not None else (key,)


def claims_for(claims: pd.DataFrame, figures) -> pd.DataFrame:
    """The claims that need only the given figures' results, e.g. a chapter's own ledger rows.

    ``claims_for(load_claims(), ["fig5a", "fig5b"])`` selects the claims whose ``requires`` are all
    among ``fig5a`` and ``fig5b`` or the tables of their readings (e.g. ``fig5b_readings``).
    """
    keys = {figures} if isinstance(figures, str) else set(figures)
    chosen = [all(set(_figures_of(key)) & keys for key in required_keys(claim))
              for _, claim in claims.iterrows()]
    return claims.loc[chosen].reset_index(drop=True)


def chapter_rows(figures, config: RunConfig, evaluated: pd.DataFrame | None = None) -> pd.DataFrame:
    """A chapter's ledger rows, judged in the whole ledger.

    The category of a claim depends on the joint reading, which only the whole ledger can find:
    every claim is evaluated on ``config``'s results (:func:`evaluate`; ``evaluated``: that
    evaluation, already made) and the rows of the claims that need only the result keys ``figures``
    (:func:`claims_for`) are returned, so that every chapter shows the categories of the
    replication report.
    """
    if evaluated is None:
        evaluated = evaluate(config=_check_config(config))
    ids = set(claims_for(load_claims(), figures)["id"])
    rows = evaluated[evaluated["claim"].isin(ids)].reset_index(drop=True)
    rows.attrs = {**evaluated.attrs,
                  "points": [p for p in evaluated.attrs.get("points", []) if p["claim"] in ids]}
    return rows


def orphan_extractors(claims: pd.DataFrame | None = None, modules=None) -> list[str]:
    """Ids with an extractor but no row in ``claims`` (default: claims.csv).

    A non-empty list means a claim was renamed or an extractor misspelt its id.
    """
    ids = set((load_claims() if claims is None else claims)["id"])
    return sorted(set(extractors(modules)) - ids)


# ======================================================================================
# Baseline (regression tests): passmd.ledger.baseline
# ======================================================================================


def claim_readings(claim_id: str, modules=None) -> tuple[str, ...]:
    """The readings a claim is evaluated at now, in words (:func:`passmd.ledger.readings.describe`)."""
    return readings_of(depends_on(claim_id, modules))


# ======================================================================================
# Results computed here: the closed forms (claims checked without a simulation)
# ======================================================================================


def closed_form_results(config: RunConfig) -> pd.DataFrame:
    """Closed-form contact stiffness 2aG* per side for R = 1 mm and 0.25 mm.

    ``config`` is taken like every result source's; the table does not depend on it.
    """
    _check_config(config)
    return reference.tangential_stiffness_table()


@extractor("fig10b-r1-stiffer-contact", not_informative="closed-form identity: 2aG* with the Hertz radius "
           "a ∝ (F_N R)^(1/3) is 4^(1/3) = 1.587 times larger at R = 1 mm than at R = 0.25 mm at every F_N")
def _stiffer_contact(results: Mapping[str, pd.DataFrame]) -> dict:
    table = results["closed_forms"].sort_values(["preload_N", "side"])
    stiffness = {r: g["tangential_stiffness_N_per_m"].to_numpy() for r, g in table.groupby("radius_mm")}
    return {"lhs": stiffness[1.0], "rhs": stiffness[0.25]}

