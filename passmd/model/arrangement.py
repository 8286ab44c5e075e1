"""How the runner is guided: contact groups, their contact angles, and the normal forces (Eq. 1).

The preload F_p presses the runner between two holders (Section 2, Fig. 2): one side of the
runner is pressed by the preload spring, the other rests on the fixed holder, so each side of the
runner carries the whole preload along the preload's line. A contact whose tangent plane makes
the *contact angle* α with that line carries F_N·sin α of it (a flat guide has α = 90°, the
paper's V-grooves α = 45°). With the paper's assumption that the contacts of one side carry the
same normal force, a side of n contacts at α has

    F_N = F_p / (n sin α)                                            (Eq. 1)

which is the paper's F_p/(2 sin 45°) for its two-contact side and F_p/(4 sin 45°) for its
four-contact side (:data:`PAPER_SIX`).

A :class:`ContactGroup` is contacts of one kind: how many, on which side, at which angle, with
which hemisphere radius; its normal force per contact is given (``normal_force``, or
``load_share`` × F_p) or follows from the side's balance (Eq. 1). Whatever is given, the
groups of each side must balance the preload, Σ n_g F_N,g sin α_g = F_p
(:func:`check_balance`); a drive whose groups do not is refused.

The guide's statics have a second, sideways component. A contact at α < 90° pushes the runner
sideways with F_N cos α, towards the flank of the groove it sits on; the paper's V-grooves put
half of each side's contacts on either flank, so their sideways forces cancel. A group's contacts
may sit on either flank, so a side is balanced sideways when some placement of its contacts on
the two flanks cancels Σ ± F_N cos α (:func:`side_lateral`: the least force any placement leaves);
one contact at 30° cannot be balanced, nor three at 60° with equal forces. Such a drive is refused
unless its guide has a rail that takes the sideways force (``guide_rail``, which the model assumes
adds no friction along the travel), and so is a drive whose contacts all press on one side (the
other side then carries nothing of the preload); the paper's one-contact model is the preset
``contacts = 1`` (:data:`ONE_CONTACT`), a reduced model of one side, not an arrangement.

Angles, looking along the travel (the runner ▭ between its two sides, the preload ↓ along
the line through them)::

        side 2 (preloaded holder)     ↓ F_p
      ──◣ α ───── ▭ ───── α ◢──        a contact's tangent plane makes α with the preload's line:
        side 1 (fixed holder)          90° a flat guide (no sideways force), 45° the paper's V-groove
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from passmd.model.tables import Assumption, _meta
from passmd.runtime.validation import InputError, check_positive, check_range, shown

__all__ = [
    "ASSUMPTIONS",
    "BALANCE_TOLERANCE",
    "FLAT",
    "ONE_CONTACT",
    "PAPER_SIX",
    "SIDES",
    "ContactGroup",
    "check_balance",
    "check_sides",
    "group_normal_forces",
    "group_sides",
    "preset_groups",
    "side_lateral",
    "side_loads",
]

#: Contact angle of a flat guide (the contact's normal along the preload), rad.
FLAT = math.pi / 2
#: The two sides of the runner: 1 the fixed holder's, 2 the preloaded holder's (Section 2).
SIDES = (1, 2)
#: Largest relative imbalance Σ n F_N sin α / F_p − 1 of a side accepted: a share typed to three
#: digits (0.333 for a third) is off by 1e-3; a side off by more is a different preload.
BALANCE_TOLERANCE = 5e-3

ASSUMPTIONS: tuple[Assumption, ...] = (
    Assumption(
        key="contact_group_geometry",
        symbol="α, side",
        value=("contact angle α = 90° (flat guide) unless given; one group: side 1; two groups: sides 1 "
               "and 2; the contacts of a side whose force is not given share what the given ones leave "
               "of F_p with equal normal force"),
        unit="",
        rationale=("Eq. 1 holds for the paper's arrangement (two contacts at 45° on one side, four at 45° "
                   "on the other). For another guide the same statics apply: each side of the runner "
                   "carries F_p along the preload's line, a contact at angle α carries F_N sin α of it, "
                   "and the paper's assumption that the contacts of one side carry equal normal forces "
                   "settles what statics alone leave open."),
        sensitivity=("A designer's arrangement only; the paper's (contacts = 1 or 6) is Eq. 1 exactly. "
                     "`passmd drive show` lists each group's side, angle and normal force."),
    ),
    Assumption(
        key="guide_rail",
        symbol="–",
        value=("contacts at α < 90° sit on the groove's two flanks as evenly as their sideways forces "
               "allow; a sideways force no placement cancels is refused unless guide_rail = true, whose "
               "rail adds no friction along the travel"),
        unit="–",
        rationale=("The paper's V-grooves hold half of each side's contacts on either flank, so the "
                   "sideways forces F_N cos α cancel and the runner needs no other guide. An arrangement "
                   "whose sideways forces cannot cancel needs something else to take them; the model is "
                   "one-dimensional along the travel and has no place for that force, so it is refused "
                   "unless the designer says a rail takes it."),
        sensitivity=("None for the paper's arrangements (balanced by symmetry). With guide_rail = true the "
                     "simulated motion ignores the rail's friction, which a sliding rail would add."),
    ),
)


@dataclass(frozen=True)
class ContactGroup:
    """Contacts of one kind in a drive's arrangement: how many, where, how loaded, how curved.

    Attributes
    ----------
    count : int
        Contacts in the group (n_g >= 1).
    load_share : float, optional
        Normal force per contact as a share of the preload, F_N / F_p.
    normal_force : float, optional
        Normal force per contact F_N (N). Give at most one of ``load_share`` and
        ``normal_force``; with neither, F_N follows from the side's balance (Eq. 1).
    radius : float, optional
        The hemispheres' radius R (m); default the drive's ``hemisphere_radius``.
    contact_angle : float
        α in rad, 0 < α <= π/2: the angle between the preload's line and the contact's tangent
        plane, so that a contact carries F_N sin α of the preload; π/2 (default) is a flat guide,
        π/4 the paper's 90° V-groove.
    side : int, optional
        The side of the runner the group presses on: 1 or 2 (default: one group, side 1; two
        groups, sides 1 and 2; more groups must say).

    Contacts of a group share one state in the simulation (they see the same actuator and
    runner motion).
    """

    count: int = field(metadata=_meta("n_g", "–", "arrangement"))
    load_share: float | None = field(default=None, metadata=_meta("F_N/F_p", "–", "arrangement"))
    normal_force: float | None = field(default=None, metadata=_meta("F_N", "N", "arrangement"))
    radius: float | None = field(default=None, metadata=_meta("R_g", "m", "arrangement"))
    contact_angle: float = field(default=FLAT, metadata=_meta("α", "rad", "arrangement"))
    side: int | None = field(default=None, metadata=_meta("side", "–", "arrangement"))

    def __post_init__(self):
        if isinstance(self.count, (bool, np.bool_)) or not isinstance(self.count, (int, np.integer)) \
                or self.count < 1:
            raise InputError(f"count = {shown(self.count)} is not allowed: must be an integer >= 1",
                             name="count", value=self.count)
        object.__setattr__(self, "count", int(self.count))
        if self.load_share is not None and self.normal_force is not None:
            raise InputError("load_share and normal_force: give at most one (the normal force per contact, "
                             "or its share of the preload; neither: from the side's balance, Eq. 1)",
                             name="load_share", value=self.load_share)
        if self.load_share is not None:
            object.__setattr__(self, "load_share", check_positive("load_share", self.load_share, "–"))
        if self.normal_force is not None:
            object.__setattr__(self, "normal_force", check_positive("normal_force", self.normal_force, "N"))
        if self.radius is not None:
            object.__setattr__(self, "radius", check_positive("radius", self.radius, "m"))
        angle = check_range("contact_angle", self.contact_angle, 0.0, FLAT, lower_open=True, unit="rad")
        object.__setattr__(self, "contact_angle", angle)
        if self.side is not None and (isinstance(self.side, (bool, np.bool_)) or not isinstance(
                self.side, (int, np.integer)) or self.side not in SIDES):
            raise InputError(f"side = {shown(self.side)} is not allowed: must be 1 or 2 (the side of the "
                             "runner the group presses on)", name="side", value=self.side)
        if self.side is not None:
            object.__setattr__(self, "side", int(self.side))

    @property
    def given(self) -> bool:
        """Whether the normal force is given (``load_share`` or ``normal_force``)."""
        return self.load_share is not None or self.normal_force is not None


#: The paper's one-contact model (Section 4.1): one contact carrying F_p.
ONE_CONTACT = (ContactGroup(1, side=1),)
#: The paper's six-contact arrangement (Section 2, Eq. 1) as contact groups: side 1, two contacts
#: at 45° (F_p/(2 sin 45°) each); side 2, four at 45° (F_p/(4 sin 45°) each).
PAPER_SIX = (ContactGroup(2, contact_angle=math.pi / 4, side=1),
             ContactGroup(4, contact_angle=math.pi / 4, side=2))


def _sin(angle: float) -> float:
    """sin α as numpy computes it (Eq. 1's sin 45° is ``numpy.sin(numpy.pi / 4)`` throughout)."""
    return float(np.sin(angle))


def preset_groups(contacts: int) -> tuple[ContactGroup, ...]:
    """The paper's arrangement ``contacts`` (1 or 6) as contact groups."""
    return {1: ONE_CONTACT, 6: PAPER_SIX}[contacts]


def _label(indices) -> str:
    return ", ".join(f"contact_groups[{i}]" for i in indices)


def group_sides(groups) -> tuple[int, ...]:
    """The side of each group (its ``side``, else the default: one group side 1, two groups 1 and 2).

    Raises
    ------
    InputError
        Three or more groups of which one gives no side.
    """
    sides = [g.side for g in groups]
    if all(s is not None for s in sides):
        return tuple(sides)
    if len(groups) <= 2 and all(s is None for s in sides):
        return tuple(range(1, len(groups) + 1))
    missing = [i for i, s in enumerate(sides) if s is None]
    raise InputError(f"{_label(missing)}: side is not given: with {len(groups)} groups each must say which "
                     "side of the runner it presses on (side = 1 or 2)", name="contact_groups",
                     value=None)


def group_normal_forces(preload, groups) -> tuple:
    """Normal force per contact of each group (N): given, or from its side's balance (Eq. 1).

    The groups of a side that give no force share what the given ones leave of F_p along the
    preload's line with equal normal force: F_N = (F_p − Σ_given n F_N sin α) / Σ n sin α, i.e.
    F_N = F_p / (n sin α) for a side of one such group (the paper's F_p/(2 sin 45°) exactly).
    Forces are returned as numpy values of ``preload``'s shape (``preload`` may be an array).
    """
    F = np.asarray(preload, dtype=float)
    sides = group_sides(groups)
    forces: list = [None] * len(groups)
    for i, g in enumerate(groups):
        if g.normal_force is not None:
            forces[i] = np.asarray(float(g.normal_force)) + 0.0 * F
        elif g.load_share is not None:
            forces[i] = g.load_share * F
    for side in SIDES:
        members = [i for i, s in enumerate(sides) if s == side]
        free = [i for i in members if forces[i] is None]
        if not free:
            continue
        left = F - sum(groups[i].count * forces[i] * _sin(groups[i].contact_angle)
                       for i in members if forces[i] is not None)
        if not np.all(left > 0):
            given = [i for i in members if forces[i] is not None]
            raise InputError(
                f"{_label(given)}: their normal forces carry all of the preload on side {side} "
                f"(Σ n F_N sin α >= F_p), leaving nothing for {_label(free)}: give those forces too, or "
                "lower the given ones",
                name="contact_groups", value=None)
        angles = {groups[i].contact_angle for i in free}
        if len(angles) == 1:  # F / n / sin α: the paper's F_p / 2 / sin 45° to the last bit
            n = sum(groups[i].count for i in free)
            value = left / n / _sin(angles.pop())
        else:
            value = left / sum(groups[i].count * _sin(groups[i].contact_angle) for i in free)
        for i in free:
            forces[i] = value
    return tuple(forces)


def side_loads(preload: float, groups) -> dict[int, float]:
    """Σ n_g F_N,g sin α_g of each side that has contacts (N): what each side carries along the
    preload's line; balanced, it is F_p on each."""
    forces = group_normal_forces(preload, groups)
    loads: dict[int, float] = {}
    for g, side, force in zip(groups, group_sides(groups), forces, strict=True):
        loads[side] = loads.get(side, 0.0) + g.count * float(force) * _sin(g.contact_angle)
    return dict(sorted(loads.items()))


def _placements(lateral: list[tuple[int, float]]) -> float:
    """The least |Σ ± L| over every placement of the contacts on the two flanks: ``lateral`` holds
    (count, sideways force per contact) of each group; k of a group's n contacts on one flank give
    (2k − n) L. Sums closer than 1e-12 of the largest force are one sum (the set stays small)."""
    quantum = 1e-12 * max((abs(L) for _, L in lateral), default=1.0) or 1.0
    sums = {0}
    for n, L in lateral:
        sums = {s + round((2 * k - n) * L / quantum) for s in sums for k in range(n + 1)}
    return min(abs(s) for s in sums) * quantum


def side_lateral(preload: float, groups) -> dict[int, float]:
    """The sideways force each side with contacts leaves unbalanced (N): the least |Σ ± n F_N cos α|
    over every placement of its contacts on the guide's two flanks (module docstring); 0 for a flat
    guide (α = 90°) and for the paper's V-grooves."""
    forces = group_normal_forces(preload, groups)
    sides = group_sides(groups)
    out = {}
    for side in sorted(set(sides)):
        lateral = [(g.count, float(f) * math.cos(g.contact_angle))
                   for g, s, f in zip(groups, sides, forces, strict=True)
                   if s == side and g.contact_angle < FLAT]
        out[side] = _placements(lateral) if lateral else 0.0
    return out


def check_sides(preload: float, groups, *, guide_rail: bool = False) -> None:
    """Refuse groups that press on one side only, or whose sideways forces no placement on the guide's
    flanks cancels (unless ``guide_rail``: a rail takes them).

    Raises
    ------
    InputError
        One line naming the groups, the side and the numbers (the sideways forces, what is left).
    """
    sides = group_sides(groups)
    empty = [side for side in SIDES if side not in sides]
    if empty:
        raise InputError(
            f"{_label(range(len(groups)))}: every group presses on side {sides[0]}, none on side {empty[0]}: "
            "each side of the runner carries the whole preload (Eq. 1), so each needs contacts; add a "
            f"group with side = {empty[0]} (the paper's one-contact model is contacts = \"one\")",
            name="contact_groups", value=None)
    if guide_rail:
        return
    forces = group_normal_forces(preload, groups)
    for side, left in side_lateral(preload, groups).items():
        if left <= BALANCE_TOLERANCE * preload:
            continue
        members = [i for i, s in enumerate(sides) if s == side and groups[i].contact_angle < FLAT]
        terms = " + ".join(f"{groups[i].count} × {float(forces[i]):.4g} N × cos "
                           f"{math.degrees(groups[i].contact_angle):.4g}°" for i in members)
        raise InputError(
            f"{_label(members)}: the contacts on side {side} push the runner sideways: of Σ n F_N cos α = "
            f"{terms}, {left:.4g} N is left unbalanced however they sit on the guide's two flanks, must be 0 "
            f"(within {BALANCE_TOLERANCE:.1%} of F_p = {preload:.4g} N); set guide_rail = true if a rail "
            "takes the sideways force, or balance the side (an even count per V-groove, or a flat guide, "
            "contact_angle = 90 deg)",
            name="contact_groups", value=left)


def check_balance(preload: float, groups) -> None:
    """Refuse groups whose normal forces do not balance the preload on each side (Eq. 1's statics).

    Raises
    ------
    InputError
        One line naming the side, its groups, the load they carry and F_p.
    """
    sides = group_sides(groups)
    for side, load in side_loads(preload, groups).items():
        if abs(load / preload - 1.0) <= BALANCE_TOLERANCE:
            continue
        members = [i for i, s in enumerate(sides) if s == side]
        terms = " + ".join(
            f"{g.count} × {float(f):.4g} N × sin {math.degrees(g.contact_angle):.4g}°"
            for i, (g, f) in enumerate(zip(groups, group_normal_forces(preload, groups), strict=True))
            if i in members)
        raise InputError(
            f"{_label(members)}: the normal forces on side {side} do not balance the preload: "
            f"Σ n F_N sin α = {terms} = {load:.4g} N, must be F_p = {preload:.4g} N (within "
            f"{BALANCE_TOLERANCE:.1%}); each side of the runner carries the whole preload (Eq. 1): correct "
            "load_share/normal_force, give a contact_angle, or leave the forces out to take them from the "
            "angles",
            name="contact_groups", value=load)
