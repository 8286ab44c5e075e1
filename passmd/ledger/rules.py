"""The ledger's judging rules, stated once: experiments, studies, fragile verdicts and coarse grids.

The replication report quotes :data:`RULES` verbatim; the functions that apply them
(:mod:`passmd.ledger.claims` for studies, :mod:`passmd.ledger.checks` for experiment claims and
coarse grids, ``passmd.ledger.verdicts`` for fragility) take their constants from here.

Claims about the experiment
    A claim whose object is a measurement of [12] (an agreement with it, a discrepancy from it, or
    what causes such a discrepancy) is decided only by that measurement. The paper's text gives
    none of its values, so such a claim is *inconclusive* (no measured data) on every result and
    at every reading, and it rests on no computed evidence. No model stands in for the
    experiment: comparing this paper's model (flexible actuators, μ = 0.2) with the earlier one
    in its place would decide the claim by assuming the paper's own conclusion that the new model
    covers the experiment. That comparison is a study.

Studies: rows that are not sentences of the paper
    A row of ``claims.csv`` without a quotation of the paper is a study: a model-against-model
    stand-in for a claim about the experiment, or a number the paper implies but does not state.
    It names the claim it accompanies (column ``study_of``), is checked like a claim at the
    defaults, and is shown beside that claim; it is never counted: not in the categories, not in
    the joint reading, not in the tensions.

Fragile verdicts
    A verdict is fragile when either (1) the claim holds at the point that decides its category
    (the defaults for *reproduced*, the joint reading otherwise) but not at one of the joint
    reading's :data:`RUNNER_UPS` runner-up readings, or the other way round, or (2) its margin at
    that point is within :data:`FRAGILE_MARGIN` of its tolerance: |deviation/tolerance − 1| <
    FRAGILE_MARGIN for value, trend and approximate-ordering checks, and |switch − x_t| within
    FRAGILE_MARGIN·tolerance of the band's edge for threshold checks. A plain ordering (no
    tolerance) is fragile by rule (1) only.

Coarse grids
    A claim about the paper's whole grid (every preload, every amplitude below a threshold, every
    frequency) is decided on a coarser profile's part of it only where the missing points cannot
    change the verdict (:class:`passmd.ledger.checks.Subset`): a check that holds there is
    inconclusive; a pointwise check that fails at a grid point is decided, each point being computed
    as the paper profile computes it; a check of the grid as a whole (a deviation over the curve, a
    trend, a maximum) is inconclusive either way. So where the quick profile decides a claim at a
    reading, the paper profile decides it alike.
"""

from __future__ import annotations

__all__ = ["FRAGILE_MARGIN", "RULES", "RUNNER_UPS"]

#: Rule (2) of fragility: a margin within this fraction of the tolerance is fragile (a value 8 %
#: off against a 10 % tolerance is 0.8 of it, 0.2 from the edge).
FRAGILE_MARGIN = 0.25
#: Rule (1) of fragility: how many runner-up readings of the joint reading a verdict must survive
#: (the distinct readings with the next most claims holding).
RUNNER_UPS = 5

#: The rules in words, as the replication report shows them (title, text).
RULES = (
    ("Claims about the experiment",
     "A claim whose object is a measurement of [12] (an agreement with it, a discrepancy from it, or "
     "what causes such a discrepancy) is decided only by that measurement. The paper's text gives none "
     "of its values, so such a claim is inconclusive (no measured data) on every result and at every "
     "reading. No model stands in for the experiment: comparing this paper's model (flexible actuators, "
     "μ = 0.2) with the earlier one in its place would decide the claim by assuming the paper's own "
     "conclusion that the new model covers the experiment. That comparison is a study."),
    ("Studies",
     "A row without a quotation of the paper is a study: a model-against-model stand-in for a claim "
     "about the experiment, or a number the paper implies but does not state. It names the claim it "
     "accompanies, is checked like a claim at the defaults and shown beside it, and is never counted: "
     "not in the categories, not in the joint reading, not in the tensions."),
    ("Fragile verdicts",
     f"A verdict is fragile when (1) the claim holds at the point that decides its category (the "
     f"defaults for reproduced, the joint reading otherwise) but not at one of the joint reading's "
     f"{RUNNER_UPS} runner-up readings, or the other way round, or (2) its margin there is within "
     f"{FRAGILE_MARGIN:.0%} of its tolerance (|deviation/tolerance − 1| < {FRAGILE_MARGIN:g} for value, "
     "trend and approximate checks; a threshold's observed switch within that share of the tolerance "
     "of the band's edge). A plain ordering has no tolerance and is fragile by (1) only."),
    ("Coarse grids",
     "A claim about the paper's whole grid (every preload, every amplitude below a threshold, every "
     "frequency) is decided on a coarser profile's part of it only where the missing points cannot change "
     "the verdict: a check that holds there is inconclusive; a pointwise check that fails at a grid point "
     "is decided, each point being computed as the paper profile computes it; a check of the grid as a "
     "whole (a deviation over the curve, a trend, a maximum) is inconclusive either way. So where the "
     "quick profile decides a claim at a reading, the paper profile decides it alike."),
)
