"""The joint readings of the ledger: where the claims are judged, chosen without the claim judged.

A claim's state depends on the readings of what the paper leaves open (:mod:`passmd.ledger.readings`).
Choosing the reading at which the most claims hold and judging every claim there would let each
claim vote for the reading it is judged at. So the ledger judges every claim **held out**: at the
point of the space chosen, by the same rule, from all the *other* claims (leave-one-out); the
in-sample joint reading (chosen with every claim) is reported beside it, with the claims that hold
only there.

The rule. The units of the choice are the counted claims of the paper, a row implied by another
(``implied_by``) counted once with it as one *family* whose state at a point is the conjunction of
its members' (fails if one fails, holds if all hold, else undecided); a row whose check cannot fail
on any result the model can produce (not informative) and a claim about the experiment (no computed
evidence) do not vote. Among the *covered* points (every voting unit evaluated there from its runs)
the chosen point is the one with the most voting units holding, an undecided unit counting as not
holding; ties go to the point with the fewest free axes away from their defaults, then to the order
of the space. Points at which every voting unit has the same state are one reading, represented by
the member closest to the defaults.

Since a claim that does not hold at the in-sample joint reading leaves the choice unchanged when it
is held out, every claim holding at its held-out reading holds at the in-sample one: the number of
claims judged as holding never exceeds the number holding together at one point of the space
(:func:`judge` records ``best_single_point``).

:func:`judge` does all of this on a state matrix and :func:`held_out_judgements` says where it judges
each claim; :func:`variants` chooses again with rows left out or studies counted;
:func:`conflicting_pairs` lists every pair of claims that each hold somewhere but never together and
:func:`tensions` groups them by the free axes that separate them; :func:`joint_map` gives the claims ×
readings map of an evaluated ledger and :func:`joint_record` the joint reading as plain data.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from passmd.ledger import readings
from passmd.ledger.rules import RUNNER_UPS
from passmd.ledger.verdicts import Judgement, PointResult

__all__ = ["DECIDED", "Unit", "conflicting_pairs", "held_out_judgements", "joint_map", "joint_record",
           "judge", "plain_point", "state_table", "tensions", "variants"]

#: The states of a claim that decide it at a point.
DECIDED = ("holds", "fails")
#: State codes of the matrices: holds, fails, undecided, no state (not reached by the claim's runs).
_HOLDS, _FAILS, _UNDECIDED, _NONE = 1, 0, -1, -2
_CODES = {"holds": _HOLDS, "fails": _FAILS, "inconclusive": _UNDECIDED, "—": _NONE}
_NAMES = {v: k for k, v in _CODES.items()}


@dataclass(frozen=True)
class Unit:
    """What the joint readings count once: a claim with the rows implied by it (``members``, the lead
    first), and whether it votes in the choice."""

    lead: str
    members: tuple
    votes: bool


def _free_of(points: list[PointResult], depends: tuple, section: str) -> tuple:
    """The free axes along which a claim's evaluated points vary."""
    keys = [k for k in depends if len({p.reading[k] for p in points}) > 1] if points else []
    return readings.free_axes(keys, section)


def state_table(evaluated: Mapping[str, tuple[list[PointResult], tuple]], sections: Mapping[str, str],
                free: Iterable | None = None) -> dict:
    """Every claim's state at every point of the space over ``free`` (default: the free axes the claims
    vary along): ``{"free": [...], "space": [...], "table": {claim: array of state codes}, "coarse":
    {claim: bool}, "free_of": {claim: its free axes}}``.

    ``evaluated`` is ``{claim id: (points, depends_on)}``, ``sections`` ``{claim id: section key}``; a
    claim's state at a point is its state at the point's projection onto its free axes
    (:func:`passmd.ledger.readings.claim_reading`), ``—`` where its design does not reach or its tables
    hold no run.
    """
    free_of = {c: _free_of(points, depends, sections.get(c, ""))
               for c, (points, depends) in evaluated.items()}
    if free is None:  # the free axes the claims vary along, in the order of the axes, then of the sections
        order = list(readings.AXES)
        sections = ["", *readings.SECTIONS]
        used = {f for fs in free_of.values() for f in fs}
        free = sorted(used, key=lambda f: (order.index(f[0]),
                                           sections.index(f[1]) if f[1] in sections else len(sections)))
    free = list(free)
    space = readings.space(free)
    table, coarse = {}, {}
    for claim, (points, _) in evaluated.items():
        mine = free_of[claim]
        keys = [k for k, _ in mine]
        states = {tuple(p.reading[k] for k in keys): ("—" if p.no_run else p.state) for p in points}
        column = np.full(len(space), _NONE, dtype=np.int8)
        if points:
            for i, point in enumerate(space):
                column[i] = _CODES[states.get(tuple(point[f] for f in mine), "—")]
        table[claim] = column
        coarse[claim] = any(p.coarse for p in points)
    return {"free": free, "space": space, "table": table, "coarse": coarse, "free_of": free_of}


def _conjunction(columns: list[np.ndarray]) -> np.ndarray:
    """A family's state at each point: no state where a member has none, fails where one fails, holds
    where all hold, else undecided."""
    stack = np.vstack(columns)
    out = np.full(stack.shape[1], _UNDECIDED, dtype=np.int8)
    out[(stack == _HOLDS).all(axis=0)] = _HOLDS
    out[(stack == _FAILS).any(axis=0)] = _FAILS
    out[(stack == _NONE).any(axis=0)] = _NONE
    return out


def _choose(matrix: np.ndarray, changed: np.ndarray) -> int:
    """The chosen point of a (points × voting units) state matrix: among the covered points (no unit
    without a state; all points if none is), the most units holding, then the fewest changed axes, then
    the first."""
    covered = ~(matrix == _NONE).any(axis=1) if matrix.shape[1] else np.ones(matrix.shape[0], bool)
    pool = np.flatnonzero(covered) if covered.any() else np.arange(matrix.shape[0])
    holding = (matrix[pool] == _HOLDS).sum(axis=1)
    order = np.lexsort((pool, changed[pool], -holding))
    return int(pool[order[0]])


def _components(units: list[Unit], free_of: Mapping[str, tuple]) -> list[set]:
    """The voting units connected by shared free axes (a unit's held-out reading can depend on any unit
    of its component, and only on those)."""
    comps: list[tuple[set, set]] = []
    for u in units:
        axes = {f for m in u.members for f in free_of[m]}
        joined = [c for c in comps if c[1] & axes]
        names = {u.lead}.union(*(c[0] for c in joined))
        axes = axes.union(*(c[1] for c in joined))
        comps = [c for c in comps if c not in joined] + [(names, axes)]
    return [c[0] for c in comps]


def judge(evaluated: Mapping[str, tuple[list[PointResult], tuple]], sections: Mapping[str, str],
          families: Mapping[str, str], voters: Iterable[str], runner_ups: int = RUNNER_UPS) -> dict:
    """The in-sample joint reading and every unit's held-out reading (module docstring).

    ``evaluated``: ``{claim id: (points, depends_on)}`` of the counted claims; ``sections``: each claim's
    section; ``families``: each claim's family lead (itself for a claim implied by none); ``voters``: the
    claims that vote (informative, resting on computed evidence).

    Returns the in-sample reading's ``point``, ``described``, ``holding``, ``equivalent_points``,
    ``claims`` (units), ``points``, ``covered_points``, ``decided_points``, ``chosen_from``, ``ties`` (the
    first ``runner_ups`` of the ``tied_readings`` distinct readings with as many holding),
    ``runner_ups`` (each with ``margin``), and ``units`` (:class:`Unit` list), ``unit_states`` ({lead:
    codes}), ``held_out`` ({lead: point index}), ``best`` (the in-sample point's index),
    ``best_single_point`` (most voting units holding at one point), ``grid_bound`` ({lead: True where
    its held-out reading rests on a unit a coarse grid leaves undecided and its own state varies}),
    ``states`` (:func:`state_table`).
    """
    states = state_table(evaluated, sections)
    space, table = states["space"], states["table"]
    voters = set(voters)
    leads = list(dict.fromkeys(families.get(c, c) for c in evaluated))
    units = [Unit(lead, tuple([lead] + [c for c in evaluated if families.get(c, c) == lead and c != lead]),
                  lead in voters) for lead in leads]
    unit_states = {u.lead: _conjunction([table[m] for m in u.members]) for u in units}
    voting = [u for u in units if u.votes]
    matrix = (np.column_stack([unit_states[u.lead] for u in voting]) if voting
              else np.zeros((len(space), 0), dtype=np.int8))
    changed = np.array([readings.changed_axes(p) for p in space])
    # points where every voting unit has the same state are one reading: the member closest to the defaults
    rows = {}
    for i in sorted(range(len(space)), key=lambda i: (changed[i], i)):
        rows.setdefault(matrix[i].tobytes(), []).append(i)
    members = {group[0]: len(group) for group in rows.values()}
    best = _choose(matrix, changed)
    best = min(rows[matrix[best].tobytes()], key=lambda i: (changed[i], i))
    held_out = {}
    for k, u in enumerate(voting):
        held_out[u.lead] = _choose(np.delete(matrix, k, axis=1), changed)
    for u in units:
        held_out.setdefault(u.lead, best)
    holding = (matrix == _HOLDS).sum(axis=1)
    covered = ~(matrix == _NONE).any(axis=1) if voting else np.ones(len(space), bool)
    decided = covered & (np.isin(matrix, (_HOLDS, _FAILS)).all(axis=1) if voting else True)
    pool = [i for i in members if covered[i]] or list(members)
    order = sorted(pool, key=lambda i: (-holding[i], changed[i], i))
    coarse_units = {u.lead for u in units if any(states["coarse"][m] for m in u.members)}
    grid_bound = {}
    for component in _components(units, states["free_of"]):
        if not component & coarse_units:
            continue
        for lead in component:
            codes = unit_states[lead]
            grid_bound[lead] = bool(len(set(codes.tolist())) > 1 or codes[0] not in (_HOLDS, _FAILS))

    def entry(i):
        return {"point": space[i], "described": readings.describe_point(space[i]), "holding": int(holding[i]),
                "equivalent_points": members.get(i, 1)}

    return {
        **entry(best), "claims": len(voting), "points": len(space), "covered_points": int(covered.sum()),
        "decided_points": int(decided.sum()), "chosen_from": int(covered.sum()) or len(space),
        "ties": [entry(i) for i in order if i != best and holding[i] == holding[best]][:runner_ups],
        "tied_readings": sum(1 for i in order if i != best and holding[i] == holding[best]),
        "runner_ups": [{**entry(i), "margin": int(holding[best] - holding[i])}
                       for i in order if holding[i] < holding[best]][:runner_ups],
        "units": units, "unit_states": unit_states, "held_out": held_out, "best": best,
        "best_single_point": int(holding.max()) if len(holding) else 0, "grid_bound": grid_bound,
        "states": states,
    }


def state_name(code: int) -> str:
    """A state code as its name (``holds``, ``fails``, ``inconclusive``, ``—``)."""
    return _NAMES[int(code)]


def conflicting_pairs(states: Mapping, claims: Iterable[str] | None = None) -> list[dict]:
    """Every pair of claims that each hold somewhere in the space but never at the same point.

    ``states`` is :func:`state_table`'s; ``claims`` restricts the pairs to those claims (default: every
    claim of the table). Each pair: ``claims`` (the two ids), ``first_holds_at`` and ``second_holds_at``
    (how many points of the space each holds at), ``example`` (a point where the first holds, in words,
    and the second's state there).
    """
    space, table = states["space"], states["table"]
    names = [c for c in table if claims is None or c in set(claims)]
    holds = {c: table[c] == _HOLDS for c in names}
    out = []
    for a_index, a in enumerate(names):
        for b in names[a_index + 1:]:
            if not holds[a].any() or not holds[b].any() or (holds[a] & holds[b]).any():
                continue
            example = int(np.flatnonzero(holds[a])[0])
            out.append({"claims": [a, b], "first_holds_at": int(holds[a].sum()),
                        "second_holds_at": int(holds[b].sum()),
                        "example": f"{readings.describe_point(space[example])} "
                                   f"(the second {state_name(table[b][example])} there)"})
    return out


def _holding_values(holds: np.ndarray, space: list, key) -> frozenset:
    return frozenset(space[i][key] for i in np.flatnonzero(holds))


def _joint_split(first: np.ndarray, second: np.ndarray, space: list, free: list) -> tuple:
    """The fewest free axes (the first such set in the order of the space) on whose combined values the
    points where two claims hold are disjoint; all of them at worst, since they never hold together."""
    for size in range(2, len(free) + 1):
        for subset in itertools.combinations(free, size):
            if not ({tuple(space[i][k] for k in subset) for i in np.flatnonzero(first)}
                    & {tuple(space[i][k] for k in subset) for i in np.flatnonzero(second)}):
                return subset
    return tuple(free)


def tensions(states: Mapping, pairs: list[dict]) -> list[dict]:
    """The conflicting pairs grouped into tensions by the free axes that separate them.

    A pair is separated by a free axis when the values of that axis at which each claim holds are
    disjoint; pairs separated by the same axes, and sharing claims, form one tension. Within a
    tension the claims fall into sides by where they hold along those axes, and rows with the same
    holding points are linked as near-duplicates. Each tension: ``separated_by`` (free axes in words),
    ``jointly`` (True when no single one of them separates the pairs, only their combination),
    ``sides`` (``{"holds_only_at", "claims", "linked"}``: where each side holds along those axes,
    its claims, and its near-duplicate groups), ``pairs`` (how many pairs it stands for).
    """
    space, table, free = states["space"], states["table"], states["free"]
    names = {c for p in pairs for c in p["claims"]}
    holds = {c: table[c] == _HOLDS for c in names}
    keyed: dict[tuple, list[dict]] = {}
    for pair in pairs:
        a, b = pair["claims"]
        split = tuple(f for f in free
                      if not _holding_values(holds[a], space, f) & _holding_values(holds[b], space, f))
        jointly = not split
        if jointly:  # no single axis: the fewest axes whose combined values separate them
            split = _joint_split(holds[a], holds[b], space, free)
        keyed.setdefault((jointly, split), []).append(pair)

    def value(f, v):
        return readings.AXES[f[0]].show(v)

    out = []
    for (jointly, split), group in keyed.items():
        components: list[set] = []
        for pair in group:  # claims connected by the pairs of this split
            joined = [c for c in components if c & set(pair["claims"])]
            merged = set(pair["claims"]).union(*joined)
            components = [c for c in components if not c & set(pair["claims"])] + [merged]
        for component in components:
            sides: dict[tuple, list[str]] = {}
            for claim in sorted(component):
                if jointly:  # the combinations of the axes' values it holds at, not each axis alone
                    combos = {tuple(space[i][k] for k in split) for i in np.flatnonzero(holds[claim])}
                    signature = tuple(sorted(combos, key=str))
                else:
                    signature = tuple(tuple(sorted(_holding_values(holds[claim], space, k), key=str))
                                      for k in split)
                sides.setdefault(signature, []).append(claim)
            described = []
            for signature, claims_ in sides.items():
                linked: dict[bytes, list[str]] = {}
                for claim in claims_:
                    linked.setdefault(holds[claim].tobytes(), []).append(claim)
                if jointly:
                    where = " or ".join(
                        "(" + ", ".join(f"{readings.free_label(k)} = {value(k, v)}"
                                        for k, v in zip(split, combo, strict=True)) + ")"
                        for combo in signature)
                else:
                    where = "; ".join(f"{readings.free_label(k)} = "
                                      + " or ".join(value(k, v) for v in values)
                                      for k, values in zip(split, signature, strict=True))
                described.append({"holds_only_at": where, "claims": claims_,
                                  "linked": [g for g in linked.values() if len(g) > 1]})
            n = sum(1 for p in group if set(p["claims"]) <= component)
            out.append({"separated_by": [readings.free_label(k) for k in split], "jointly": jointly,
                        "sides": described, "pairs": n})
    return out


def elsewhere(claim: str, states: Mapping, at: int) -> str:
    """Where a claim that does not hold at point ``at`` holds instead (the point of the space with the
    most claims holding among those where it holds), and which claims holding at ``at`` fail there."""
    space, table = states["space"], states["table"]
    if claim not in table or table[claim][at] == _HOLDS:
        return ""
    candidates = np.flatnonzero(table[claim] == _HOLDS)
    if not candidates.size:
        return ""
    counts = sum((column == _HOLDS).astype(int) for column in table.values())
    pick = int(max(candidates, key=lambda i: (counts[i], -i)))
    broken = [c for c, column in table.items() if column[at] == _HOLDS and column[pick] == _FAILS]
    return (f"holds at {readings.describe_point(space[pick])}, which breaks "
            + (", ".join(broken) if broken else "no claim holding there"))


def held_out_judgements(joint: Mapping, studies: Iterable[str]) -> dict[str, Judgement]:
    """Where each claim is judged (``passmd.ledger.verdicts.Judgement``): a claim of the paper at
    its unit's held-out point of ``joint`` (:func:`judge`'s result), a study at the defaults."""
    states = joint["states"]
    space, free_of = states["space"], states["free_of"]
    runner_ups = [e["point"] for e in joint["runner_ups"]]
    out = {}
    for unit in joint["units"]:
        at = joint["held_out"][unit.lead]
        codes = joint["unit_states"][unit.lead]
        for claim in unit.members:
            mine = free_of[claim]
            lead = claim == unit.lead
            family = unit.members if len(unit.members) > 1 else ()
            out[claim] = Judgement(
                held_out=readings.claim_reading(space[at], mine),
                in_sample=readings.claim_reading(space[joint["best"]], mine),
                family_state=state_name(codes[at]) if lead and family else "",
                family_at_defaults=state_name(codes[0]) if lead and family else "",
                family=family, counted=lead, grid_bound=joint["grid_bound"].get(unit.lead, False),
                elsewhere=elsewhere(claim, states, at),
                runner_ups=tuple(readings.claim_reading(p, mine) for p in runner_ups))
    for claim in studies:
        out[claim] = Judgement(readings.default_reading(), readings.default_reading(), counted=False)
    return out


def variants(evaluated: Mapping, sections: Mapping, families: Mapping, voters: set, rows: list[dict],
             studies: Mapping) -> list[dict]:
    """How the in-sample joint reading changes when rows are left out (those decided only where a method
    they rest on is undefined, e.g. Eq. 15) or when the studies (the substitute and derived rows, never
    counted) are counted as claims.

    ``evaluated``, ``sections``, ``families``, ``voters`` as :func:`judge` takes them; ``rows``: the
    ledger rows of the claims of the paper (``claim``, ``outside``); ``studies``: ``{claim id: (points,
    depends_on)}`` of the studies.
    """
    out = []
    if studies:
        with_studies = {**evaluated, **studies}
        joint = judge(with_studies, sections, families, voters | set(studies))
        out.append({"left_out": "studies counted as claims", "claims_left_out": [],
                    "claims_added": sorted(studies), "reading": plain_point(joint["point"]),
                    "described": joint["described"], "holding": joint["holding"], "claims": joint["claims"]})
    leave = {r["claim"] for r in rows if r["outside"]}
    if leave:
        kept = {c: v for c, v in evaluated.items() if c not in leave}
        joint = judge(kept, sections, families, voters - leave)
        out.append({"left_out": "rows decided only where a method they rest on is undefined left out",
                    "claims_left_out": sorted(leave), "claims_added": [],
                    "reading": plain_point(joint["point"]), "described": joint["described"],
                    "holding": joint["holding"], "claims": joint["claims"]})
    return out


def plain_point(point: Mapping) -> dict:
    """A point of the space with its free axes as plain keys (``key@section``)."""
    return {readings.point_key(f): v for f, v in point.items()}


def map_columns(joint: Mapping) -> list[dict]:
    """The readings of the claims × readings map: the defaults, the joint reading, its ties and
    runner-ups (each once), with every claim's state there."""
    states = joint["states"]
    space, table = states["space"], states["table"]
    wanted = [0, joint["best"], *(space.index(e["point"]) for e in (*joint["ties"], *joint["runner_ups"]))]
    columns, seen = [], set()
    for i in wanted:
        key = tuple(int(column[i]) for column in table.values())
        if key in seen:
            continue
        seen.add(key)
        role = "joint reading" if i == joint["best"] else ("defaults" if i == 0 else "")
        column_states = {c: state_name(column[i]) for c, column in table.items()}
        columns.append({"reading": readings.describe_point(space[i]), "role": role,
                        "holding": sum(s == "holds" for s in column_states.values()),
                        "states": column_states})
    return columns


def joint_map(evaluated: pd.DataFrame) -> pd.DataFrame:
    """Claims × readings: every counted claim's state (``holds``, ``fails``, ``inconclusive``, ``—``
    not reached by its design) at the defaults, the in-sample joint reading, its ties and runner-ups.

    Columns are the readings in words, prefixed with their role (``defaults``, ``joint reading``);
    ``attrs["holding"]`` gives how many claims hold at each column.
    """
    columns = evaluated.attrs.get("joint_map", [])
    names = [(f"{c['role']}: {c['reading']}" if c["role"] and c["reading"] != c["role"] else c["reading"])
             for c in columns]
    claims = list(columns[0]["states"]) if columns else []
    table = pd.DataFrame({n: c["states"] for n, c in zip(names, columns, strict=True)}, index=claims)
    table.index.name = "claim"
    table.attrs["holding"] = {n: c["holding"] for n, c in zip(names, columns, strict=True)}
    return table


def joint_record(joint: Mapping) -> dict:
    """The joint reading as plain data (``passmd ledger --json``): its point (free axes as
    ``key@section``), how many claims hold there of how many, the points it stands for, the space's size,
    the covered points and the points it was chosen from, the tied points and the runner-ups with their
    counts and margins, the held-out counts and the in-sample gain over them, the largest number of
    claims holding at one point, and how it changes when rows are left out or studies counted
    (``variants``)."""
    out = {"reading": plain_point(joint["point"])}
    for k in ("described", "holding", "equivalent_points", "claims", "points", "covered_points",
              "decided_points", "chosen_from", "tied_readings", "best_single_point", "held_out_counts",
              "in_sample_gain", "variants"):
        if k in joint:
            out[k] = joint[k]
    for k in ("ties", "runner_ups"):
        out[k] = [{**{key: v for key, v in e.items() if key != "point"},
                   "reading": plain_point(e["point"])} for e in joint[k]]
    return out
