"""The ledger's judging rules, stated once: held-out judging, families, construction, ties, experiments,
studies, fragile verdicts and coarse grids.

The replication report quotes :data:`RULES` verbatim; the functions that apply them
(:mod:`passmd.ledger.joint` for held-out judging and families, :mod:`passmd.ledger.checks` for ties and
coarse grids, :mod:`passmd.ledger.claims` for studies, ``passmd.ledger.verdicts`` for categories and
fragility) take their constants from here.
"""

from __future__ import annotations

__all__ = ["FRAGILE_MARGIN", "HELD_OUT", "RULES", "RUNNER_UPS", "TIE_RULE"]

#: Rule (2) of fragility: a margin within this fraction of the tolerance is fragile (a value 8 %
#: off against a 10 % tolerance is 0.8 of it, 0.2 from the edge).
FRAGILE_MARGIN = 0.25
#: Rule (1) of fragility: how many runner-up readings of the joint reading a verdict must survive
#: (the distinct readings with the next most claims holding).
RUNNER_UPS = 5

#: Held-out judging, in two sentences (the book's ledger chapter quotes them).
HELD_OUT = ("Every claim is judged at one reading of what the paper leaves open: the joint reading chosen, "
            "by the same rule (most claims holding together, ties to the defaults), from all the other "
            "claims, so no claim votes for the reading it is judged at. The counts come from those "
            "held-out states; the joint reading chosen with every claim (in-sample) is shown beside them, "
            "with the claims that hold only there.")

#: The tie rule, stated once (:func:`passmd.ledger.checks.check_ordering` applies it).
TIE_RULE = ("Two values closer than the resolution of what they measure (the integrator's stated accuracy "
            "for a simulated position or velocity, one grid step for a frequency located on the grid, "
            "exact equality where none is stated, e.g. two zeros) are equal: an ordering (<, >) between "
            "them is undecided (inconclusive, with the resolution named) and an agreement (≈) between them "
            "holds.")

#: The rules in words, as the replication report shows them (title, text).
RULES = (
    ("Held-out judging", HELD_OUT + " A section's unstated inputs are its own: a reading of Section 5 never "
     "chooses Section 4.1's μ (passmd.ledger.readings)."),
    ("Families", "A row the paper's stronger statement implies (implied_by in claims.csv) is counted once "
     "with it, as one family that holds only if every member holds, fails if one fails, and votes once in "
     "the choice of the joint reading."),
    ("Holds by construction", "A row whose check cannot fail on any result the model can produce (a "
     "closed-form identity, a statement every finite contact stiffness satisfies at the claim's amplitude) "
     "is shown as holding by construction, with the reason, and never counted as reproduced; it does not "
     "vote."),
    ("Ties", TIE_RULE),
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
     f"A verdict is fragile when (1) the claim holds at its held-out reading but not at one of the joint "
     f"reading's {RUNNER_UPS} runner-up readings, or the other way round, or (2) its margin there is within "
     f"{FRAGILE_MARGIN:.0%} of its tolerance (|deviation/tolerance − 1| < {FRAGILE_MARGIN:g} for value, "
     "trend and approximate checks; a threshold's observed switch within that share of the tolerance "
     "of the band's edge). A plain ordering has no tolerance and is fragile by (1) only."),
    ("Coarse grids",
     "A claim about the paper's whole grid (every preload, every amplitude below a threshold, every "
     "frequency) is decided on a coarser profile's part of it only where the missing points cannot change "
     "the verdict: a check that holds there is inconclusive; a pointwise check that fails at a grid point "
     "is decided, each point being computed as the paper profile computes it; a check of the grid as a "
     "whole (a deviation over the curve, a trend, a maximum) is inconclusive either way. A claim whose "
     "state varies over its readings, and whose held-out reading rests on claims the coarser grid leaves "
     "undecided, is not decided on that grid. So where the quick profile decides a claim, the paper "
     "profile decides it alike."),
)
