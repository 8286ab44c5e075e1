"""What an extractor may raise or return besides its numbers, and the tags that mark a function
as a claim's extractor or evidence.

Extractors are plain functions ``(results[, reading]) -> ours`` living next to their figure in
:mod:`passmd.experiments`; :func:`extractor` and :func:`evidence` only tag them with their claim
id (nothing is registered at import), and :func:`collect_claim_functions` finds the tagged
functions of the modules it is given (the ledger passes
``passmd.experiments.figure_table.CLAIM_MODULES``). :mod:`passmd.ledger.checks` re-exports every
name here.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

from passmd.ledger import readings
from passmd.ledger.claims import CLAIM_ID

__all__ = [
    "NO_MEASURED_DATA",
    "ClaimFails",
    "ClaimFunctions",
    "CoarseGrid",
    "ExtractorError",
    "Inconclusive",
    "NoRun",
    "NotEvaluable",
    "Scoped",
    "Subset",
    "collect_claim_functions",
    "evidence",
    "experiment_claim",
    "extractor",
    "no_measured_data",
]


class NotEvaluable(Exception):
    """Raised by an extractor or a check when the results cannot decide a claim.

    The claim is then *inconclusive* at that reading (an extremum at the edge of the grid,
    non-finite values, a run that did not converge, a reading the tables hold no run for);
    the message says what is missing.
    """


#: The name the verdict taxonomy uses for :class:`NotEvaluable`.
Inconclusive = NotEvaluable


class CoarseGrid(NotEvaluable):
    """Raised by an extractor when its table lacks grid points of the paper's grid that could decide the
    claim (a coarser profile): the claim is inconclusive at that reading *because of the grid*, where the
    paper profile may decide it (the coarse-grid rule of :mod:`passmd.ledger.rules`)."""


class NoRun(NotEvaluable):
    """Raised by an extractor when the result tables hold no run at a reading the claim depends on.

    Every table a claim reads must hold a run at every point of its design
    (:func:`passmd.ledger.readings.design`): a missing run is a defect of the tables, which
    :func:`passmd.report.evaluation.evaluate` refuses (``strict``), never a "not covered" point.
    """


@dataclass(frozen=True)
class Scoped:
    """What an extractor returns when the data deciding its claim lie where a method it rests on is
    undefined (e.g. Eq. 15's waveform where its settling time does not fit the period): ``ours`` is
    checked as usual, and ``outside`` (one line: which method, where) goes with the verdict."""

    ours: object
    outside: str = ""


@dataclass(frozen=True)
class Subset:
    """What an extractor returns when its claim speaks of the paper's whole grid (every preload,
    every amplitude below a threshold, every frequency) and its table holds only part of it (a coarse
    profile): a check that holds there is not decided (a missing grid point could fail it), nor one
    that fails unless ``failures_decide`` (the failure is at a point the paper's grid has, computed
    the same way); ``missing`` says what the table lacks."""

    ours: object
    missing: str
    failures_decide: bool = True


#: How the verdict of a claim about the experiment begins: the paper's text tabulates no measurement.
NO_MEASURED_DATA = "no measured data in the paper's text"


def no_measured_data(what: str):
    """Raise :class:`NotEvaluable` for a claim about the experiment: the paper's text gives none of
    its measurements (``what`` names them), so no computation can decide the claim."""
    raise NotEvaluable(f"{NO_MEASURED_DATA}: {what}")


def experiment_claim(claim_id: str, what: str) -> Callable:
    """The extractor of a claim about the experiment of [12] (:mod:`passmd.ledger.rules`): inconclusive
    on every result for want of measured data (``what`` names the data), at the defaults only, tagged
    ``claim_experiment`` so the ledger counts it as resting on no computed evidence."""

    def extract(results):
        no_measured_data(what)

    name = "experiment_" + "".join(c if c.isalnum() else "_" for c in claim_id)
    extract.__qualname__ = extract.__name__ = name
    extract.__module__ = sys._getframe(1).f_globals.get("__name__", __name__)  # the claims module defining it
    func = extractor(claim_id)(extract)
    func.claim_experiment = True
    return func


class ClaimFails(Exception):
    """Raised by an extractor when the results decide the claim *against* the paper outright.

    A total failure (e.g. no step up to the full stroke, no turning point where the paper
    locates one) is *not reproduced*, never "not evaluated"; the message is the evidence.
    ``outside`` says, as :class:`Scoped` does, when the deciding data lie where a method the claim
    rests on is undefined.
    """

    def __init__(self, message: str, outside: str = ""):
        super().__init__(message)
        self.outside = outside


class ExtractorError(ValueError):
    """An extractor failed, or returned something its claim's check cannot use."""


# ======================================================================================
# Tags: which function extracts (or gives evidence for) which claim
# ======================================================================================


def _check_claim_id(claim_id) -> str:
    if not isinstance(claim_id, str) or not CLAIM_ID.match(claim_id):
        raise ValueError(f"claim_id = {claim_id!r} is not allowed: must be a claims.csv id slug")
    return claim_id


def extractor(claim_id: str, depends_on=(), *, not_informative: str = "") -> Callable[[Callable], Callable]:
    """Decorator: tag ``func(results[, reading]) -> ours`` as the extractor of a claim.

    ``ours`` must have the form the claim's check kind expects (module docstring) and be in
    the claim's ``unit``. Raise :class:`NotEvaluable` when the results cannot decide the claim
    (inconclusive) and :class:`ClaimFails` when they decide it against the paper outright.

    ``depends_on`` names the axes of :data:`passmd.ledger.readings.AXES` the claim's result depends
    on; the function then takes a second argument ``reading`` (``{axis: value}``) and is
    evaluated at every reading of :func:`passmd.ledger.readings.design`.

    ``not_informative`` says why the claim's check cannot fail on any result the model can
    produce (a closed-form identity, a statement every finite contact stiffness satisfies at the
    claim's amplitude); empty (the default) for a check some counter-example makes fail. The
    ledger counts the non-informative claims apart.

    The decorator only sets ``func.claim_extractor`` (the id), ``func.claim_depends_on`` and
    ``func.not_informative``; :func:`collect_claim_functions` finds the tagged functions of a module.
    """
    _check_claim_id(claim_id)
    depends = tuple(depends_on)
    for key in depends:
        readings.axis(key)  # ValueError naming the declared axes
    if not isinstance(not_informative, str):
        raise ValueError(f"not_informative = {not_informative!r} is not allowed: must be a reason (str), "
                         "empty for an informative check")

    def tag(func: Callable) -> Callable:
        func.claim_extractor = claim_id
        func.claim_depends_on = depends
        func.not_informative = not_informative.strip()
        return func

    return tag


def evidence(claim_id: str) -> Callable[[Callable], Callable]:
    """Decorator: tag ``func(results) -> list[str]`` as the computed evidence of a claim.

    Each string states one evaluated quantity with its value (e.g. "first-fly-back onset
    within 0.4 % of Eq. 7"); the ledger shows them beside the claim's checks. Raise
    :class:`NotEvaluable` when the results hold no data for them. Sets ``func.claim_evidence``.
    """
    _check_claim_id(claim_id)

    def tag(func: Callable) -> Callable:
        func.claim_evidence = claim_id
        return func

    return tag


@dataclass(frozen=True)
class ClaimFunctions:
    """The tagged functions of some modules, by claim id (read-only mappings); ``experiment``: the
    ids whose extractor is an :func:`experiment_claim`."""

    extractors: Mapping[str, Callable]
    depends_on: Mapping[str, tuple[str, ...]]
    evidence: Mapping[str, Callable]
    experiment: frozenset = frozenset()


def _module_functions(module) -> Iterable[Callable]:
    """The callables a module holds at its top level, and inside its top-level tuples (functions
    made in a loop, e.g. one evidence function per claim of a table)."""
    for value in vars(module).values():
        if isinstance(value, tuple):
            yield from (item for item in value if callable(item))
        elif callable(value):
            yield value


def collect_claim_functions(modules: Iterable) -> ClaimFunctions:
    """The extractors (with their ``depends_on``) and evidence functions defined in ``modules``.

    Looks at every module-level function (and every function in a module-level tuple) tagged
    by :func:`extractor` or :func:`evidence`; the same function reached twice (e.g. imported
    into another of the modules) counts once.

    Raises
    ------
    ValueError
        When two different functions are tagged for the same claim id (naming both).
    """
    found: dict[str, dict[str, Callable]] = {"claim_extractor": {}, "claim_evidence": {}}
    for module in modules:
        for func in _module_functions(module):
            for tag, by_id in found.items():
                claim_id = getattr(func, tag, None)
                if not isinstance(claim_id, str):
                    continue
                previous = by_id.setdefault(claim_id, func)
                if previous is not func:
                    raise ValueError(f"claim {claim_id!r} is claimed twice ({tag}): by "
                                     f"{previous.__module__}.{previous.__qualname__} and "
                                     f"{func.__module__}.{func.__qualname__}")
    extractors = found["claim_extractor"]
    return ClaimFunctions(
        extractors=MappingProxyType(extractors),
        depends_on=MappingProxyType({c: f.claim_depends_on for c, f in extractors.items()}),
        evidence=MappingProxyType(found["claim_evidence"]),
        experiment=frozenset(c for c, f in extractors.items() if getattr(f, "claim_experiment", False)),
    )
