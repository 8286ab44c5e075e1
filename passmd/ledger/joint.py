"""The joint reading of the ledger: the point of the assumption space where the most claims hold.

:func:`joint_reading` tabulates every claim's state (``holds``, ``fails``, ``inconclusive``, or
``—`` where its design does not reach) at every point of :func:`passmd.ledger.readings.space`,
merges points where all claims agree, and picks the one with the most claims holding (ties
broken towards the defaults), with its ties and runner-ups. :func:`conflicting_pairs` finds
claims that no reading makes hold together, :func:`joint_map` gives the claims × readings map
of an evaluated ledger, and :func:`joint_record` the joint reading as plain data.
:func:`passmd.ledger.evaluation.evaluate` calls them.
"""

from __future__ import annotations

from collections.abc import Mapping

import pandas as pd

from passmd.ledger import readings
from passmd.ledger.verdicts import PointResult, point_at

__all__ = ["conflicting_pairs", "joint_map", "joint_reading", "joint_record"]


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
    """Claims × readings: every claim's state (``holds``, ``fails``, ``inconclusive``, ``—`` not
    reached by its design) at the defaults, the joint reading, its ties and runner-ups.

    Columns are the readings in words, prefixed with their role (``defaults``, ``joint reading``);
    ``attrs["holding"]`` gives how many claims hold at each column.
    """
    columns = evaluated.attrs.get("joint_map", [])
    names = [(f"{c['role']}: {c['reading']}" if c["role"] and c["reading"] != c["role"] else c["reading"])
             for c in columns]
    table = pd.DataFrame({n: c["states"] for n, c in zip(names, columns, strict=True)},
                         index=list(evaluated["claim"]))
    table.index.name = "claim"
    table.attrs["holding"] = {n: c["holding"] for n, c in zip(names, columns, strict=True)}
    return table


def joint_reading(evaluated: Mapping[str, tuple[list[PointResult], tuple]], runner_ups: int = 5) -> dict:
    """The point of the whole declared assumption space where the most claims hold together.

    ``evaluated`` is ``{claim id: (points, depends_on)}`` (``passmd.ledger.verdicts.claim_points``).
    A claim's state at a point of :func:`passmd.ledger.readings.space` is its state at the projection of
    that point onto the axes it is evaluated along (it does not depend on the others); a point its
    design does not reach counts as not holding. Ties are broken towards the defaults (fewest
    changed axes, then the order of the space). Points at which every claim has the same state are
    one reading for the ledger: each is represented by its member closest to the defaults.

    Returns ``reading`` (the joint reading), ``described``, ``holding`` (how many claims hold
    there), ``equivalent_points`` (how many points of the space it stands for), ``claims``
    (total), ``ties`` (other distinct readings with as many), ``runner_ups`` (the next
    ``runner_ups`` distinct readings with their counts), ``points`` (the space's size) and
    ``states`` (``{point index: {claim: state}}`` with the space under ``"space"``).
    """
    space = readings.space()
    table = {}
    for i, point in enumerate(space):
        column = {}
        for claim, (points, depends) in evaluated.items():
            found = point_at(points, depends, point) if points else None
            column[claim] = "—" if found is None else found.state
        table[i] = column
    counts = [sum(state == "holds" for state in table[i].values()) for i in range(len(space))]
    base = readings.default_reading()

    def changed(i):
        return sum(space[i][k] != base[k] for k in base)

    # points where every claim has the same state are one reading for the ledger: keep the one
    # closest to the defaults, and how many it stands for
    classes: dict[tuple, list[int]] = {}
    for i in sorted(range(len(space)), key=lambda i: (changed(i), i)):
        classes.setdefault(tuple(table[i].values()), []).append(i)
    members = {group[0]: len(group) for group in classes.values()}
    order = sorted(members, key=lambda i: (-counts[i], changed(i), i))
    best = order[0]

    def entry(i):
        return {"reading": space[i], "described": readings.describe(space[i]), "holding": counts[i],
                "equivalent_points": members[i]}

    return {
        **entry(best), "claims": len(evaluated),
        "ties": [entry(i) for i in order[1:] if counts[i] == counts[best]],
        "runner_ups": [entry(i) for i in order if counts[i] < counts[best]][:runner_ups],
        "points": len(space),
        "states": {"space": space, "table": table, "best": best},
    }


def conflicting_pairs(states: Mapping) -> list[dict]:
    """Pairs of claims that each hold somewhere in the space but never at the same point, one
    failing wherever the other holds: no reading makes both hold.

    Each pair: ``claims`` (the two ids), ``first_holds_at`` and ``second_holds_at`` (how many
    points of the space each holds at), ``example`` (a point where the first holds and the
    second fails, in words).
    """
    space, table = states["space"], states["table"]
    claims = list(table[0]) if table else []
    holds = {c: {i for i in table if table[i][c] == "holds"} for c in claims}
    fails = {c: {i for i in table if table[i][c] == "fails"} for c in claims}
    out = []
    for a_index, a in enumerate(claims):
        for b in claims[a_index + 1:]:
            if not holds[a] or not holds[b] or holds[a] & holds[b]:
                continue
            if not (holds[a] <= fails[b] and holds[b] <= fails[a]):
                continue
            example = min(holds[a])
            out.append({"claims": [a, b], "first_holds_at": len(holds[a]), "second_holds_at": len(holds[b]),
                        "example": readings.describe(space[example])})
    return out


def _elsewhere(claim: str, states: Mapping, joint: Mapping) -> str:
    """Where a claim that does not hold at the joint reading holds instead (the point of the space
    with the most claims holding among those where it holds), and which claims holding at the joint
    reading fail there."""
    space, table, best = states["space"], states["table"], states["best"]
    if table[best][claim] == "holds":
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
    there of how many, the tied points and the runner-ups with their counts, the space's size."""
    return {k: joint[k] for k in ("reading", "described", "holding", "equivalent_points", "claims", "ties",
                                  "runner_ups", "points")}
