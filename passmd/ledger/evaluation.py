"""The replication ledger: the paper's claims, checked against our computed results.

Three pieces meet here:

* **claims**: ``passmd/data/reference/claims.csv``, read and validated by
  :func:`passmd.ledger.claims.load_claims`;
* **results**: the figure table of ``passmd.experiments.figure_table`` (``fig5a`` … ``fig10c``, shared with
  the book and the CLI) plus the ledger's own ``closed_forms`` table; :func:`collect_results`
  computes every one for a run configuration, so a chapter never lists them;
* **extractors**: functions ``(results[, reading]) -> ours`` tagged with
  :func:`passmd.ledger.checks.extractor` in the modules
  ``passmd.experiments.figure_table.CLAIM_MODULES`` lists
  (and the closed-form one here); they turn the result tables into what the claim's check
  needs (:mod:`passmd.ledger.checks` says what, for each check kind).

:func:`evaluate` runs the checks over the readings of the assumption space
(:mod:`passmd.ledger.readings`) and computes every claim's category: ``reproduced``,
``reproduced under the joint reading``, ``not reproduced`` or ``inconclusive``, from the
defaults and the joint reading of all claims (:mod:`passmd.ledger.joint`), with its
evidence; no category is typed in. :mod:`passmd.report.ledger_views` presents them in the book;
:func:`check_categories` compares them with a committed baseline in the tests, and
:func:`records` gives them to ``passmd ledger --json``.
"""

from __future__ import annotations

import math
import re
import sys
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from passmd.experiments import figure_table as figures
from passmd.experiments.force_generation import figures as force_generation
from passmd.ledger import readings, reference
from passmd.ledger.checks import ClaimFunctions, collect_claim_functions, extractor
from passmd.ledger.claims import is_number, load_claims
from passmd.ledger.joint import _elsewhere, _map_columns, conflicting_pairs, joint_reading
from passmd.ledger.joint import joint_map as joint_map  # the ledger's views read it from here too
from passmd.ledger.joint import joint_record as joint_record
from passmd.ledger.verdicts import NO_EXTRACTOR, claim_points, claim_row, shown
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
    "depends_on",
    "evaluate",
    "extractors",
    "headline",
    "load_baseline",
    "load_baseline_readings",
    "orphan_extractors",
    "records",
    "result_sources",
    "write_baseline",
]

#: Columns of :func:`evaluate`'s result.
LEDGER_COLUMNS = ("claim", "figure", "quantity", "paper", "ours", "unit", "abs_deviation", "rel_deviation",
                  "tolerance", "status", "verdict", "evidence", "reason", "basis", "check", "depends_on",
                  "readings", "holds_at", "fails_at", "decided_at", "fraction_holds", "best_reading",
                  "default_state", "joint_state", "margin", "margin_text", "fragile", "informative",
                  "not_informative", "note")


# ======================================================================================
# Extractors and results
# ======================================================================================


def claim_modules() -> tuple:
    """The modules holding claim extractors: ``passmd.experiments.figure_table.CLAIM_MODULES`` and this one
    (the closed-form claim's extractor)."""
    return (*figures.CLAIM_MODULES, sys.modules[__name__])


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
    return figures.figure_spec(name).compute


def result_sources() -> dict[str, Callable[[RunConfig], pd.DataFrame]]:
    """Every available result table: ``{key: compute(config) -> DataFrame}``.

    The figures of ``passmd.experiments.figure_table`` (in the table's order) plus ``closed_forms``
    (the closed-form tables some claims are checked against, :func:`closed_form_results`) and
    ``fig7flyback`` (Figs. 7a and 7b with the fixed fly-back, the force claims' ``flyback``
    readings: :func:`passmd.experiments.force_generation.figures.fig7flyback`).
    """
    sources = {name: _figure_source(name) for name in figures.figure_names()}
    sources["closed_forms"] = closed_form_results
    sources["fig7flyback"] = force_generation.fig7flyback
    return sources


def collect_results(config: RunConfig, figures: Iterable[str] | None = None) -> dict[str, pd.DataFrame]:
    """Compute every available result table: the ledger's single entry point.

    Parameters
    ----------
    config : passmd.runtime.config.RunConfig
        How to run; its ``profile`` (``"quick"`` for CI, ``"paper"`` for the paper's grids)
        selects the grids of each figure.
    figures : iterable of str, optional
        Only these keys (each must be available); default all of :func:`result_sources`.

    Returns
    -------
    dict
        ``{key: DataFrame}``. Figures not in the table are simply absent; their claims
        are then *inconclusive*.
    """
    _check_config(config)
    available = result_sources()
    keys = list(available) if figures is None else list(figures)
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
    axes its extractor depends on, the defaults first). The joint reading
    (:func:`~passmd.ledger.joint.joint_reading`) is the point of the whole space where the most claims hold
    together; each claim's category is computed from two points only, the defaults and the joint reading:

    * ``reproduced``: the check holds at the defaults;
    * ``reproduced under the joint reading``: it does not hold at the defaults and holds at the
      joint reading;
    * ``not reproduced``: it fails at the defaults or at the joint reading and holds at neither (a
      total failure, e.g. no step up to the full stroke, is a failure); the verdict names another
      reading where it holds, if any, and the claims that reading breaks;
    * ``inconclusive``: neither point decides it (an extremum at the grid's edge, non-finite
      values, missing results, no run at that reading).

    The table's ``attrs`` carry ``points`` (every claim at every evaluated reading), ``joint``
    (:func:`~passmd.ledger.joint.joint_reading` without its state table) and ``conflicts``
    (:func:`~passmd.ledger.joint.conflicting_pairs`).

    NaN never counts as holding (:class:`passmd.ledger.checks.NotEvaluable`). Claims whose ``requires``
    are only ``closed_forms`` have ``basis`` "closed form" and are not simulation results.

    Parameters
    ----------
    claims : pandas.DataFrame, optional
        From :func:`passmd.ledger.claims.load_claims` (the default: every claim of claims.csv).
    results : dict, optional
        ``{figure key: DataFrame}``, e.g. from :func:`collect_results`; default
        ``collect_results(config)``.
    config : passmd.runtime.config.RunConfig, optional
        The run configuration the results are computed with when ``results`` is not given.
    strict : bool
        If True (default), raise ``LookupError`` when a claim's results are present but no
        extractor is tagged for it. If False, such claims are *inconclusive* with that note.
    modules : iterable of modules, optional
        Where the extractors and evidence functions are looked up; default :func:`claim_modules`.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`LEDGER_COLUMNS`: ``paper`` and ``ours`` (at the defaults) as shown,
        ``abs_deviation`` (in ``unit``) and ``rel_deviation`` (fraction) where defined,
        ``status`` (the category, one of :data:`passmd.ledger.claims.STATUSES`), ``verdict`` (one
        computed line), ``evidence`` (computed lines, ``" | "``-separated), ``reason``
        (claims.csv's human reason), ``basis``, ``readings`` (evaluated), ``holds_at`` (how
        many hold), ``fails_at`` and ``decided_at`` (how many fail, of the decided ones),
        ``fraction_holds``, ``best_reading``, ``depends_on``, ``default_state`` and
        ``joint_state``, ``margin`` (the check's score at the defaults: deviation over tolerance
        for value and trend checks) with ``margin_text``, ``fragile`` (holds at the defaults but
        fails at the joint reading or at most of its decided readings), ``informative`` and
        ``not_informative`` (why its check cannot fail, from the extractor).
    """
    if results is None:
        if config is None:
            raise ValueError("evaluate needs results or a config to compute them with (config = None)")
        results = collect_results(config)
    claims = load_claims() if claims is None else claims
    functions = claim_functions(modules)
    evaluated = {}
    problems = []
    for _, claim in claims.iterrows():
        points, why = claim_points(claim, results, functions)
        if strict and why == NO_EXTRACTOR:
            problems.append(f"claim {claim['id']!r} has its results but no registered extractor")
        evaluated[claim["id"]] = (points, functions.depends_on.get(claim["id"], ()))
    if problems:
        raise LookupError("ledger evaluation is incomplete:\n  " + "\n  ".join(problems))
    joint = joint_reading(evaluated)
    states = joint["states"]
    rows, point_rows = [], []
    for _, claim in claims.iterrows():
        points, depends = evaluated[claim["id"]]
        row, _ = claim_row(claim, results, functions, joint=joint["reading"], points=points or None,
                           elsewhere=_elsewhere(claim["id"], states, joint))
        rows.append(row)
        point_rows.extend({"claim": claim["id"], "reading": readings.describe(p.reading),
                           "point": {k: p.reading[k] for k in depends if k in p.reading},
                           "state": p.state, "detail": p.detail,
                           "score": (p.outcome.score if p.outcome is not None
                                     and math.isfinite(p.outcome.score) else None)} for p in points)
    table = pd.DataFrame(rows, columns=list(LEDGER_COLUMNS))
    table.attrs["points"] = point_rows
    table.attrs["joint"] = {k: v for k, v in joint.items() if k != "states"}
    table.attrs["conflicts"] = conflicting_pairs(states)
    table.attrs["joint_map"] = _map_columns(joint)
    return table


def headline(evaluated: pd.DataFrame) -> dict:
    """Counts per category, plus the fragile rows and the rows whose check is not informative."""
    from passmd.ledger.claims import STATUSES
    counts = {s: int((evaluated["status"] == s).sum()) for s in STATUSES}
    counts["fragile"] = int(evaluated["fragile"].astype(bool).sum())
    counts["not informative"] = int((~evaluated["informative"].astype(bool)).sum())
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


def claims_for(claims: pd.DataFrame, figures) -> pd.DataFrame:
    """The claims that need only the given result keys, e.g. a chapter's own ledger rows.

    ``claims_for(load_claims(), ["fig5a", "fig5b"])`` selects the claims whose ``requires``
    are all among ``fig5a`` and ``fig5b``.
    """
    keys = {figures} if isinstance(figures, str) else set(figures)
    needed = claims["requires"].str.split(";").map(lambda parts: {p for p in parts if p})
    return claims[needed.map(lambda parts: parts <= keys)].reset_index(drop=True)


def chapter_rows(figures, config: RunConfig) -> pd.DataFrame:
    """A chapter's ledger rows, judged in the whole ledger.

    The category of a claim depends on the joint reading, which only the whole ledger can find:
    every claim is evaluated on ``config``'s results (:func:`evaluate`) and the rows of the
    claims that need only the result keys ``figures`` (:func:`claims_for`) are returned, so that
    every chapter shows the categories of the replication report.
    """
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


#: SI name and factor of each claim unit, for machine-readable output (keys carry the SI unit).
SI_UNITS = {"nm": ("m", 1e-9), "mm/s": ("m_per_s", 1e-3), "kHz": ("Hz", 1e3), "mN": ("N", 1e-3),
            "N/m": ("N_per_m", 1.0), "%": ("percent", 1.0), "µs": ("s", 1e-6), "periods": ("periods", 1.0),
            "": ("", 1.0)}


def records(evaluated: pd.DataFrame) -> list[dict]:
    """The ledger as plain records with SI keys (``passmd ledger --json``).

    Per claim: ``claim``, ``category``, ``basis``, ``verdict``, ``evidence`` (list),
    ``reason``, ``depends_on`` (list), ``readings`` (``{reading: state}``), ``points`` (every
    evaluated reading as ``{axis: value}`` of its axes, with state, score and detail),
    ``default_state``, ``joint_state``, ``margin`` and ``margin_text``, ``fails_at`` of
    ``decided_at``, ``fragile``, ``informative`` and ``not_informative``, ``fraction_holds``,
    ``best_reading``, ``tolerance`` (as shown), and, where numeric, ``paper_<si>``,
    ``ours_<si>`` and ``abs_deviation_<si>`` in SI units (e.g. ``ours_m``, ``paper_m_per_s``),
    ``rel_deviation`` as a fraction. Non-numeric values are null, with ``ours_text`` as shown.
    """
    points = pd.DataFrame(evaluated.attrs.get("points", []),
                          columns=["claim", "reading", "point", "state", "detail", "score"])
    out = []
    for row in evaluated.itertuples():
        si, factor = SI_UNITS.get(row.unit, (re.sub(r"[^A-Za-z0-9]+", "_", row.unit), 1.0))
        suffix = f"_{si}" if si else ""

        def number(value, factor=factor):
            if isinstance(value, (int, float, np.floating)) and not isinstance(value, bool):
                return float(value) * factor if math.isfinite(value) else None
            return None

        paper = number(float(row.paper)) if is_number(str(row.paper)) else None
        mine = points[points["claim"] == row.claim]
        out.append({
            "claim": row.claim, "figure": row.figure, "category": row.status, "basis": row.basis,
            "verdict": row.verdict, "evidence": [e for e in row.evidence.split(" | ") if e],
            "reason": row.reason, "depends_on": [d for d in row.depends_on.split(";") if d],
            "readings": dict(zip(mine["reading"], mine["state"], strict=True)),
            "points": [{"reading": p, "state": st, "detail": d,
                        "score": float(sc) if sc is not None and math.isfinite(sc) else None}
                       for p, st, sc, d in zip(mine["point"], mine["state"], mine["score"], mine["detail"],
                                               strict=True)],
            "default_state": row.default_state, "joint_state": row.joint_state,
            "margin": None if not math.isfinite(row.margin) else float(row.margin),
            "margin_text": row.margin_text, "fails_at": int(row.fails_at), "decided_at": int(row.decided_at),
            "fragile": bool(row.fragile), "informative": bool(row.informative),
            "not_informative": row.not_informative,
            "fraction_holds": None if not math.isfinite(row.fraction_holds) else float(row.fraction_holds),
            "best_reading": row.best_reading, "tolerance": row.tolerance, "check": row.check,
            f"paper{suffix}": paper, f"ours{suffix}": number(row.ours), "ours_text": shown(row.ours),
            f"abs_deviation{suffix}": number(row.abs_deviation),
            "rel_deviation": None if not math.isfinite(row.rel_deviation) else float(row.rel_deviation),
        })
    return out


# ======================================================================================
# Baseline (regression tests)
# ======================================================================================


def load_baseline(path) -> dict[str, str]:
    """``{claim id: category}`` from a baseline CSV written by :func:`write_baseline`."""
    table = pd.read_csv(path, dtype=str, keep_default_na=False, comment="#")
    return dict(zip(table["claim"], table["status"], strict=True))


#: Separator of the readings in a baseline's ``readings`` column.
READINGS_SEPARATOR = " | "


def claim_readings(claim_id: str, modules=None) -> tuple[str, ...]:
    """The readings a claim is evaluated at now, in words (:func:`passmd.ledger.readings.describe`)."""
    return tuple(readings.describe(r) for r in readings.design(depends_on(claim_id, modules), claim_id))


def load_baseline_readings(path) -> dict[str, tuple[str, ...]]:
    """``{claim id: readings}`` recorded in a baseline CSV (its ``readings`` column).

    Empty when the baseline records no readings: the readings its categories were computed at
    are then unknown, and no claim of it can be compared reading for reading.
    """
    table = pd.read_csv(path, dtype=str, keep_default_na=False, comment="#")
    if "readings" not in table:
        return {}
    return {claim: tuple(text.split(READINGS_SEPARATOR))
            for claim, text in zip(table["claim"], table["readings"], strict=True)}


def write_baseline(evaluated: pd.DataFrame, path, header: str = "") -> None:
    """Write the claims' categories as a baseline CSV (``claim,status,readings``), atomically.

    ``readings`` lists the readings each category was computed at (:func:`claim_readings`), so
    that two baselines are compared only where they evaluated the same readings. ``header``
    (e.g. the command and date that produced it) is written as ``#`` comment lines.
    """
    path = Path(path)
    table = evaluated[["claim", "status"]].copy()
    table["readings"] = [READINGS_SEPARATOR.join(claim_readings(c)) for c in table["claim"]]
    tmp = path.with_name(f".{path.name}.tmp")
    with open(tmp, "w", encoding="utf-8", newline="") as fh:
        for line in header.splitlines():
            fh.write(f"# {line}\n")
        table.to_csv(fh, index=False, lineterminator="\n")
    tmp.replace(path)


def category_changes(evaluated: pd.DataFrame, baseline: Mapping[str, str]) -> pd.DataFrame:
    """Every claim whose category differs from ``baseline`` (or that appeared or disappeared).

    Columns ``claim``, ``baseline``, ``now`` (``"missing"`` where absent) and ``verdict``.
    """
    current = dict(zip(evaluated["claim"], evaluated["status"], strict=True))
    verdicts = dict(zip(evaluated["claim"], evaluated["verdict"], strict=True))
    rows = []
    for claim in list(baseline) + [c for c in current if c not in baseline]:
        before, now = baseline.get(claim, "missing"), current.get(claim, "missing")
        if before != now:
            rows.append({"claim": claim, "baseline": before, "now": now,
                         "verdict": verdicts.get(claim, "claim no longer in the ledger")})
    return pd.DataFrame(rows, columns=["claim", "baseline", "now", "verdict"])


def check_categories(evaluated: pd.DataFrame, baseline: Mapping[str, str]) -> None:
    """Raise ``AssertionError`` with a readable diff when any claim changed category."""
    changed = category_changes(evaluated, baseline)
    if len(changed):
        lines = [f"{r.claim}: {r.baseline} -> {r.now} ({r.verdict})" for r in changed.itertuples()]
        raise AssertionError(f"{len(lines)} claim(s) changed category against the baseline:\n  "
                             + "\n  ".join(lines))


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

