"""The joint reading of the ledger: the point of the assumption space where the most claims hold.

:func:`state_table` tabulates every counted claim's state (``holds``, ``fails``,
``inconclusive``, or ``—`` where its design does not reach) at every point of
:func:`passmd.ledger.readings.space`. :func:`joint_reading` picks, among the *covered* points
(every claim that rests on computed evidence evaluated there from its runs), the one with the
most claims holding (ties broken towards the defaults), with the number of points it was chosen from, its
ties and its runner-ups with their margins; points where all claims agree are one reading.
:func:`conflicting_pairs` lists every pair of claims that each hold somewhere but never together,
:func:`tensions` groups them by the readings that separate them, with near-duplicate rows (the
same holding points) linked. :func:`joint_map` gives the claims × readings map of an evaluated
ledger, :func:`joint_record` the joint reading as plain data.
:func:`passmd.report.evaluation.evaluate` calls them.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Mapping

import pandas as pd

from passmd.ledger import readings
from passmd.ledger.rules import RUNNER_UPS
from passmd.ledger.verdicts import PointResult

__all__ = ["conflicting_pairs", "joint_map", "joint_reading", "joint_record", "state_table", "tensions"]

#: The states of a claim that decide it at a point.
DECIDED = ("holds", "fails")


def _map_columns(joint: Mapping) -> list[dict]:
    """The readings of the claims × readings map: the defaults, the joint reading, its ties and
    runner-ups (each once), with every claim's state there."""
    space, table = joint["states"]["space"], joint["states"]["table"]
    wanted = [readings.default_reading(), joint["reading"],
              *(e["reading"] for e in (*joint["ties"], *joint["runner_ups"]))]
    columns, seen = [], set()
    for reading in wanted:
        i = space.index(reading)
        key = tuple(table[i].values())
        if key in seen:
            continue
        seen.add(key)
        role = ("defaults" if reading == readings.default_reading() else "")
        role = "joint reading" if reading == joint["reading"] else role
        columns.append({"reading": readings.describe(reading), "role": role,
                        "holding": sum(s == "holds" for s in table[i].values()), "states": dict(table[i])})
    return columns


def joint_map(evaluated: pd.DataFrame) -> pd.DataFrame:
    """Claims × readings: every counted claim's state (``holds``, ``fails``, ``inconclusive``, ``—``
    not reached by its design) at the defaults, the joint reading, its ties and runner-ups.

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


def state_table(evaluated: Mapping[str, tuple[list[PointResult], tuple]]) -> dict:
    """Every claim's state at every point of the space: ``{"space": [...], "table": {i: {claim: state}}}``.

    ``evaluated`` is ``{claim id: (points, depends_on)}`` (``passmd.ledger.verdicts.claim_points``); a
    claim's state at a point is its state at the projection of that point onto its axes, ``—``
    where its design does not reach or its tables hold no run.
    """
    space = readings.space()
    index = {}
    for claim, (points, depends) in evaluated.items():
        keys = [k for k in depends if len({p.reading[k] for p in points}) > 1] if points else []
        index[claim] = (keys, {tuple(p.reading[k] for k in keys): "—" if p.no_run else p.state
                               for p in points})
    table = {}
    for i, point in enumerate(space):
        table[i] = {claim: (states.get(tuple(point[k] for k in keys), "—") if states else "—")
                    for claim, (keys, states) in index.items()}
    return {"space": space, "table": table}


def _changed(reading: Mapping) -> int:
    base = readings.default_reading()
    return sum(reading[k] != base[k] for k in base)


def joint_reading(evaluated: Mapping[str, tuple[list[PointResult], tuple]],
                  computed: Iterable[str] | None = None, runner_ups: int = RUNNER_UPS,
                  states: Mapping | None = None) -> dict:
    """The point of the declared assumption space where the most claims hold together.

    ``evaluated`` is ``{claim id: (points, depends_on)}`` of the counted claims; ``computed`` the
    ones that rest on computed evidence (default: all). A point is *covered* when every one of them
    was evaluated there from its runs (a state, never a missing run: the strict ledger stops on one,
    so every point is), *decided* when every one of them holds or fails there (an undecided state is
    the data's own answer, e.g. two back-steps that are both zero cannot be ordered). The joint
    reading is chosen among the covered points (among all if none is), an undecided claim counting
    as not holding; ties are broken towards the defaults (fewest changed axes, then the order of the
    space). Points at which every claim has the same state are one reading for the ledger: each is
    represented by its member closest to the defaults.

    Returns ``reading``, ``described``, ``holding`` (claims holding there), ``equivalent_points``
    (points of the space it stands for), ``claims`` (total), ``points`` (the space's size),
    ``covered_points``, ``decided_points``, ``chosen_from`` (points it was chosen among), ``ties``
    (other distinct readings with as many), ``runner_ups`` (the next ``runner_ups`` distinct
    readings, each with ``holding`` and ``margin``: how many fewer claims hold there) and ``states``
    (:func:`state_table`, with the index of the joint reading under ``"best"``).
    """
    states = state_table(evaluated) if states is None else states
    space, table = states["space"], states["table"]
    computed = set(evaluated) if computed is None else set(computed) & set(evaluated)
    counts = {i: sum(state == "holds" for state in table[i].values()) for i in table}
    covered = [i for i in table if all(table[i][c] != "—" for c in computed)]
    decided = [i for i in covered if all(table[i][c] in DECIDED for c in computed)]
    pool = covered or list(table)
    # points where every claim has the same state are one reading for the ledger: keep the one
    # closest to the defaults, and how many it stands for
    classes: dict[tuple, list[int]] = {}
    for i in sorted(pool, key=lambda i: (_changed(space[i]), i)):
        classes.setdefault(tuple(table[i].values()), []).append(i)
    members = {group[0]: len(group) for group in classes.values()}
    order = sorted(members, key=lambda i: (-counts[i], _changed(space[i]), i))
    best = order[0]

    def entry(i):
        return {"reading": space[i], "described": readings.describe(space[i]), "holding": counts[i],
                "equivalent_points": members[i]}

    return {
        **entry(best), "claims": len(evaluated), "points": len(space), "covered_points": len(covered),
        "decided_points": len(decided), "chosen_from": len(pool),
        "ties": [entry(i) for i in order[1:] if counts[i] == counts[best]],
        "runner_ups": [{**entry(i), "margin": counts[best] - counts[i]}
                       for i in order if counts[i] < counts[best]][:runner_ups],
        "states": {**states, "best": best},
    }


def conflicting_pairs(states: Mapping, claims: Iterable[str] | None = None) -> list[dict]:
    """Every pair of claims that each hold somewhere in the space but never at the same point.

    ``claims`` restricts the pairs to those claims (default: every claim of the table). Each pair:
    ``claims`` (the two ids), ``first_holds_at`` and ``second_holds_at`` (how many points of the
    space each holds at), ``example`` (a point where the first holds, in words, and the second's
    state there).
    """
    space, table = states["space"], states["table"]
    names = list(table[0]) if table else []
    names = [c for c in names if claims is None or c in set(claims)]
    holds = {c: {i for i in table if table[i][c] == "holds"} for c in names}
    out = []
    for a_index, a in enumerate(names):
        for b in names[a_index + 1:]:
            if not holds[a] or not holds[b] or holds[a] & holds[b]:
                continue
            example = min(holds[a])
            out.append({"claims": [a, b], "first_holds_at": len(holds[a]), "second_holds_at": len(holds[b]),
                        "example": f"{readings.describe(space[example])} "
                                   f"(the second {table[example][b]} there)"})
    return out


def _holding_values(holds: set, space: list, key: str) -> frozenset:
    return frozenset(space[i][key] for i in holds)


def _joint_split(first: set, second: set, space: list) -> tuple[str, ...]:
    """The fewest axes (the first such set in the order of the axes) on whose combined values the
    points where two claims hold are disjoint; all axes at worst, since they never hold together."""
    keys = tuple(readings.AXES)
    for size in range(2, len(keys) + 1):
        for subset in itertools.combinations(keys, size):
            if not ({tuple(space[i][k] for k in subset) for i in first}
                    & {tuple(space[i][k] for k in subset) for i in second}):
                return subset
    return keys


def tensions(states: Mapping, pairs: list[dict]) -> list[dict]:
    """The conflicting pairs grouped into tensions by the readings that separate them.

    A pair is separated by an axis when the values of that axis at which each claim holds are
    disjoint; pairs separated by the same axes, and sharing claims, form one tension. Within a
    tension the claims fall into sides by where they hold along those axes, and rows with the same
    holding points are linked as near-duplicates. Each tension: ``separated_by`` (axis labels),
    ``jointly`` (True when no single one of them separates the pairs, only their combination),
    ``sides`` (``{"holds_only_at", "claims", "linked"}``: where each side holds along those axes,
    its claims, and its near-duplicate groups), ``pairs`` (how many pairs it stands for).
    """
    space, table = states["space"], states["table"]
    names = {c for p in pairs for c in p["claims"]}
    holds = {c: {i for i in table if table[i][c] == "holds"} for c in names}
    keyed: dict[tuple, list[dict]] = {}
    for pair in pairs:
        a, b = pair["claims"]
        split = tuple(k for k in readings.AXES
                      if not _holding_values(holds[a], space, k) & _holding_values(holds[b], space, k))
        jointly = not split
        if jointly:  # no single axis: the fewest axes whose combined values separate them
            split = _joint_split(holds[a], holds[b], space)
        keyed.setdefault((jointly, split), []).append(pair)
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
                    combos = {tuple(space[i][k] for k in split) for i in holds[claim]}
                    signature = tuple(sorted(combos, key=str))
                else:
                    signature = tuple(tuple(sorted(_holding_values(holds[claim], space, k), key=str))
                                      for k in split)
                sides.setdefault(signature, []).append(claim)
            described = []
            for signature, claims_ in sides.items():
                linked: dict[frozenset, list[str]] = {}
                for claim in claims_:
                    linked.setdefault(frozenset(holds[claim]), []).append(claim)
                if jointly:
                    where = " or ".join(
                        "(" + ", ".join(f"{readings.AXES[k].label} = {readings.AXES[k].show(v)}"
                                        for k, v in zip(split, combo, strict=True)) + ")"
                        for combo in signature)
                else:
                    where = "; ".join(f"{readings.AXES[k].label} = "
                                      + " or ".join(readings.AXES[k].show(v) for v in values)
                                      for k, values in zip(split, signature, strict=True))
                described.append({"holds_only_at": where, "claims": claims_,
                                  "linked": [g for g in linked.values() if len(g) > 1]})
            n = sum(1 for p in group if set(p["claims"]) <= component)
            out.append({"separated_by": [readings.AXES[k].label for k in split], "jointly": jointly,
                        "sides": described, "pairs": n})
    return out


def _elsewhere(claim: str, states: Mapping, joint: Mapping) -> str:
    """Where a claim that does not hold at the joint reading holds instead (the point of the space
    with the most claims holding among those where it holds), and which claims holding at the joint
    reading fail there."""
    space, table, best = states["space"], states["table"], states["best"]
    if claim not in table[best] or table[best][claim] == "holds":
        return ""
    candidates = [i for i in table if table[i][claim] == "holds"]
    if not candidates:
        return ""
    pick = max(candidates, key=lambda i: (sum(s == "holds" for s in table[i].values()), -i))
    broken = [c for c in table[best] if table[best][c] == "holds" and table[pick][c] == "fails"]
    return (f"holds at {readings.describe(space[pick])}, which breaks "
            + (", ".join(broken) if broken else "no claim holding at the joint reading"))


def joint_record(joint: Mapping) -> dict:
    """The joint reading as plain data (``passmd ledger --json``): its point, how many claims hold
    there of how many, the points it stands for, the space's size, the covered points and the points
    it was chosen from, the tied points and the runner-ups with their counts and margins, and how it
    changes when rows are left out or studies counted (``variants``)."""
    keys = ("reading", "described", "holding", "equivalent_points", "claims", "points", "covered_points",
            "decided_points", "chosen_from", "ties", "runner_ups", "variants")
    return {k: joint[k] for k in keys if k in joint}
