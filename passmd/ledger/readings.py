"""The assumption space of the ledger: what the paper leaves open, where, and the readings we evaluate.

The paper leaves some inputs of its claims unstated (the fly-back rule, how the critical
amplitude was read off the runs, the drive frequency of Sections 4.1 and 4.2, the actuator damping
lost from Table 2, μ in Sections 4.1 and 5, what Eq. 15 does when t_s does not fit into a period).
Each is declared here once as an :class:`Axis`: its default (the value the rest of the book uses),
the values of its plausible range that we evaluate, the whole range in words, the source of that
range, and the result tables whose runs it changes (``Axis.tables``).

A *reading* is one point of that space: ``{axis key: value}``. **A reading keeps the claim's
object**: an axis may change only what the paper left unstated, never the thing a claim is
about. A value that would change the object is not a reading: it is listed in
``Axis.not_readings`` with the reason and shown as a study in its chapter.

**Sections.** The paper states its simulation parameters section by section: Section 4.1 (Figs. 5–6,
the critical amplitude), Section 4.2 (Fig. 7, the force) and Section 5 (Figs. 8–10, the waveform)
are three sets of simulations, each with its own list of stated values (:data:`SECTIONS`). What a
section states is not free there (μ = 0.2 "was used for the simulations" of Section 4.2, so no
axis changes its runs' μ). What a section leaves unstated, each section chose on its own: nothing
in the text ties the μ of Fig. 5a to that of Fig. 10, so an axis of ``scope="section"`` is one
free input *per section whose tables it changes* (μ of Section 4.1 and μ of Section 5 are two
inputs, the fly-back of Section 4.1 and of Section 4.2 two more), and a Section 5 ordering cannot
choose Fig. 5a's μ. An axis of ``scope="paper"`` is a value the paper states once for every section
that uses it but that our copy of the text lost (Table 2's viscosity c_p, read as the damping ratio
ζ): one unknown shared by Sections 4.1 and 4.2. A *free axis* is the pair ``(axis key, section
key)`` (the section key empty for a paper-scoped axis); a *point* of the ledger's space is
``{free axis: value}``, and a claim's reading at a point is the point's values on the free axes of
the claim's section (:func:`claim_reading`).

**Declared = computed.** A claim depends on an axis when it reads a result table whose runs the
axis changes (:func:`applicable`): its extractor must declare exactly those axes
(``passmd.ledger.checks.extractor(id, depends_on=(...))``), and the ledger evaluates it on the
full product of their values (:func:`design`, the defaults first). Every table a claim reads
holds a run at every point of that product; an extractor that finds none raises
:class:`passmd.ledger.checks.NoRun`, which the ledger treats as a defect, never as "not
covered". A claim has the same state at every value of a free axis it does not depend on, so every
point of the space (:func:`space`) has a state for every claim: that is what the joint readings of
:mod:`passmd.ledger.joint` are chosen from.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import pandas as pd

from passmd.ledger.claims import required_keys
from passmd.model.defaults import PROTOCOL

__all__ = ["AC_TABLES", "AXES", "SECTIONS", "SECTION5_TABLES", "Axis", "FreeAxis", "Section", "applicable",
           "axis", "changed_axes", "claim_reading", "declared_free_axes", "default_point", "default_reading",
           "describe", "describe_point", "design", "free_axes", "free_label", "point_key", "project",
           "section_of", "section_table", "space", "space_table"]

#: The result tables of the ledger's readings (``passmd.report.evaluation.result_sources``): the
#: critical-amplitude searches of Figs. 5b and 6a–6c, the step against amplitude of Fig. 5a, this
#: paper's force runs of Fig. 7, and Section 5's runs (Fig. 9a holds both μ itself). Each holds a
#: run at every point of the axes that change it.
AC_TABLES = ("fig5b_readings", "fig6a_readings", "fig6b_readings", "fig6c_readings")
SECTION4_1_TABLES = ("fig5a_readings", *AC_TABLES)
FORCE_TABLES = ("fig7_readings", "fig7_dependence_readings")
SECTION5_TABLES = ("fig8a_readings", "fig8a_ringing_readings", "fig8b_readings", "fig8b_window_readings",
                   "fig9a", "fig9a_response", "fig9b_readings", "fig10a_readings", "fig10b_readings",
                   "fig10c_readings")
VELOCITY_TABLES = ("fig9b_readings", "fig10a_readings", "fig10b_readings", "fig10c_readings")


@dataclass(frozen=True)
class Section:
    """One set of simulations the paper describes with its own stated parameters."""

    key: str  # "4.1", "4.2", "5"
    label: str  # e.g. "Section 4.1"
    what: str  # the figures and subject, for tables
    tables: tuple  # the ledger's result tables of its runs
    stated: tuple = ()  # (axis key, value, quotation): a value the section states, so no free axis there


#: The paper's simulation sections, in the paper's order.
SECTIONS: dict[str, Section] = {
    s.key: s
    for s in (
        Section("4.1", "Section 4.1", "critical amplitude, Figs. 5–6", SECTION4_1_TABLES),
        Section("4.2", "Section 4.2", "force generation, Fig. 7", FORCE_TABLES,
                stated=(("friction_coefficient", 0.2, "it was found in the experiment work of Lübke [24] "
                         "that the friction coefficient is equal to 0.2. Thus, this value was used for the "
                         "simulations"),)),
        Section("5", "Section 5", "driving waveform, Figs. 8–10", SECTION5_TABLES),
    )
}


@dataclass(frozen=True)
class Axis:
    """One assumption the paper leaves open, as the ledger varies it."""

    key: str  # name used in readings, extractors and the book
    label: str  # short label for tables
    default: object  # the value every chapter uses (the documented default)
    alternatives: tuple  # other values the ledger evaluates (each must be in the result tables)
    unit: str  # display unit of the values ('' for words)
    plausible_range: str  # the whole plausible range, in words
    source: str  # where that range comes from
    tables: tuple = ()  # result keys whose runs the axis changes: a claim reading one depends on it
    only: tuple = ()  # (claims.csv column, value): only claims whose column lists the value
    assumption_key: str = ""  # the key of the matching passmd.model.tables assumption, if any
    not_readings: tuple = ()  # (value, reason): values that would change a claim's object (studies only)
    #: "section": unstated, each section chooses it on its own (one free axis per section whose tables
    #: it changes); "paper": a value the paper states once for every section (lost in our copy)
    scope: str = "section"

    def values(self) -> tuple:
        return (self.default, *self.alternatives)

    def show(self, value) -> str:
        text = f"{value:g}" if isinstance(value, float) else str(value)
        return f"{text} {self.unit}".strip()

    def applies_to(self, claim: Mapping) -> bool:
        """Whether a claims.csv row depends on this axis: it reads one of ``tables`` (its
        ``requires``) and, with ``only``, its column lists the value."""
        if not set(required_keys(claim)) & set(self.tables):
            return False
        column, value = self.only if self.only else (None, None)
        return column is None or value in str(claim[column]).split(";")


#: Every declared axis, in the order the report shows them.
AXES: dict[str, Axis] = {
    a.key: a
    for a in (
        Axis(
            key="flyback",
            label="fly-back rule",
            default="slew",
            alternatives=("fixed",),
            unit="",
            plausible_range="slew-rate limited (150 V/µs over 300 V_pp: 2 µs for the full stroke, less for "
            "smaller amplitudes) or a fixed fly-back of 1–2 µs at every amplitude",
            source="Section 2 states the amplifier's 150 V/µs and 300 V_pp but not the fly-back of the "
            "simulated saw-tooth; 'fixed' is the full-stroke 2 µs at every amplitude. It changes every run "
            "below the full stroke, rigid or flexible (Sections 4.1 and 4.2, each its own); Section 5 drives "
            "at the full stroke, where both rules give 2 µs",
            tables=(*SECTION4_1_TABLES, *FORCE_TABLES),
            assumption_key="flyback_duration",
        ),
        Axis(
            key="ac_protocol",
            label="how A_c is read",
            default="steady",
            alternatives=("first",),
            unit="",
            plausible_range="steady state of continued operation (last step of a 10-period run) or the "
            "onset of full sliding in the first fly-back from virgin contacts (Fig. 5a: the first step)",
            source="Section 1 defines A_c by 'no measurable step'; Section 4.1 compares it with "
            "quasi-static onsets (Eqs. 7–12) without saying how it was read off the runs",
            tables=SECTION4_1_TABLES,
            assumption_key="critical_amplitude_protocol",
        ),
        Axis(
            key="drive_frequency_s4",
            label="drive frequency",
            default=PROTOCOL.drive_frequency,
            alternatives=(50.0, 200.0),
            unit="Hz",
            plausible_range="a band around 100 Hz (50–200 Hz)",
            source="Section 4.1 does not state it; 100 Hz is Section 5.2's saw-tooth frequency (Fig. 9a)",
            tables=SECTION4_1_TABLES,
            assumption_key="critical_amplitude_protocol",
        ),
        Axis(
            key="short_period",
            label="Eq. 15 when t_s does not fit",
            default="cut",
            alternatives=("skip",),
            unit="",
            plausible_range="cut the settling time t_s to the time left in the period, or skip it (t_s = 0); "
            "neither is Eq. 15, whose t_s = 1/(2 f_s) does not fit the period of Tables 1–2's drive above a "
            "few kHz",
            source="Section 5.2 says only that above 110 kHz there is 'not enough time for settling'; a "
            "claim decided only where Eq. 15 does not fit says so",
            tables=VELOCITY_TABLES,
            only=("waveform", "optimized"),
            assumption_key="optimized_short_period",
        ),
        Axis(
            key="damping_ratio",
            label="actuator damping ratio ζ",
            default=0.05,
            alternatives=(0.005, 0.5),  # the ends of the plausible range
            unit="",
            plausible_range="0.005–0.5 (a decade either side of a lightly damped piezo stack, Q = 10)",
            source="Table 2's viscosity column c_p is lost in the available text; the paper states it once "
            "for every run of flexible actuators (Sections 4.1 and 4.2), so it is one unknown for both",
            tables=(*SECTION4_1_TABLES, *FORCE_TABLES),
            only=("actuator_model", "flexible"),
            assumption_key="actuator_viscosity",
            scope="paper",
        ),
        Axis(
            key="force_frequency",
            label="drive frequency",
            default=PROTOCOL.drive_frequency,
            alternatives=(1000.0,),
            unit="Hz",
            plausible_range="90 Hz – 1.1 kHz",
            source="Section 4.2 does not state the saw-tooth frequency of the force runs",
            tables=FORCE_TABLES,
            assumption_key="force_frequency",
        ),
        Axis(
            key="friction_coefficient",
            label="μ",
            default=0.2,
            alternatives=(0.3,),  # the value Section 4.2 says [12] used
            unit="",
            plausible_range="0.2–0.3 (Section 4.2's measured 0.2 and the earlier model's 0.3)",
            source="Sections 4.1 and 5 do not state μ, each its own; Section 4.2 states 0.2 for its runs "
            "(Lübke [24]) and 0.3 for those of [12]. The closed forms of Eqs. 7–14 are evaluated at the same "
            "μ as the runs they are compared with",
            tables=(*SECTION4_1_TABLES, *SECTION5_TABLES),
        ),
    )
}

#: A free input of the ledger's space: (axis key, section key), the section key empty for an axis of
#: ``scope="paper"`` (or a claim that reads no section's tables).
FreeAxis = tuple[str, str]


def applicable(claim: Mapping) -> tuple[str, ...]:
    """The axes a claims.csv row depends on (:meth:`Axis.applies_to`), in the order of :data:`AXES`:
    its extractor must declare exactly these."""
    return tuple(key for key, a in AXES.items() if a.applies_to(claim))


def axis(key: str) -> Axis:
    """The declared axis ``key``; ``ValueError`` naming the declared ones otherwise."""
    if key not in AXES:
        raise ValueError(f"assumption axis = {key!r} is not declared: must be one of {', '.join(AXES)}")
    return AXES[key]


def section_of(claim: Mapping) -> str:
    """The section whose simulations a claims.csv row reads (:data:`SECTIONS`), ``""`` when it reads no
    section's tables (closed forms, the contact model, claims about the experiment). ``ValueError`` when
    it reads the tables of two sections: a reading would then need two values of one input."""
    keys = set(required_keys(claim))
    found = [s.key for s in SECTIONS.values() if keys & set(s.tables)]
    if len(found) > 1:
        raise ValueError(f"claim {claim['id']!r} reads the tables of {' and '.join(found)}: a claim reads "
                         "the runs of one section")
    return found[0] if found else ""


def free_axes(keys: Iterable[str], section: str) -> tuple[FreeAxis, ...]:
    """The free axes a claim of ``section`` varies along ``keys``: ``(key, section)`` for an axis of
    ``scope="section"``, ``(key, "")`` for one of ``scope="paper"``."""
    return tuple((k, "" if axis(k).scope == "paper" else section) for k in keys)


def declared_free_axes() -> tuple[FreeAxis, ...]:
    """Every free axis of the declared space: a section-scoped axis once per section whose tables it
    changes, a paper-scoped one once; in the order of :data:`AXES`, then of :data:`SECTIONS`."""
    out = []
    for key, a in AXES.items():
        if not a.alternatives:
            continue
        if a.scope == "paper":
            out.append((key, ""))
        else:
            out.extend((key, s.key) for s in SECTIONS.values() if set(a.tables) & set(s.tables))
    return tuple(out)


def point_key(free: FreeAxis) -> str:
    """A free axis as a plain key (JSON, tables): ``"friction_coefficient@5"``, ``"damping_ratio"``."""
    key, section = free
    return f"{key}@{section}" if section else key


def free_label(free: FreeAxis) -> str:
    """A free axis in words: ``"μ (Section 5)"``, ``"actuator damping ratio ζ"``."""
    key, section = free
    label = AXES[key].label
    return f"{label} ({SECTIONS[section].label})" if section in SECTIONS else label


def default_reading() -> dict:
    """``{axis key: default}`` for every declared axis."""
    return {key: a.default for key, a in AXES.items()}


def default_point(free: Iterable[FreeAxis]) -> dict:
    """The point of the space over ``free`` where every free axis has its default."""
    return {f: AXES[f[0]].default for f in free}


def design(depends_on: Iterable[str]) -> list[dict]:
    """The readings a claim depending on ``depends_on`` is evaluated at.

    The full product of the values (default and evaluated alternatives) of every axis in
    ``depends_on``, every other axis at its default; the defaults first. Each reading is a full
    ``{axis key: value}`` dict.
    """
    base = default_reading()
    keys = list(dict.fromkeys(depends_on))
    for key in keys:
        axis(key)
    return [{**base, **dict(zip(keys, values, strict=True))}
            for values in itertools.product(*(axis(k).values() for k in keys))]


def space(free: Iterable[FreeAxis] | None = None) -> list[dict]:
    """Every point of the space over the free axes ``free`` (default: :func:`declared_free_axes`), the
    product of their values, defaults first; each point ``{free axis: value}``."""
    free = list(dict.fromkeys(declared_free_axes() if free is None else free))
    return [dict(zip(free, values, strict=True))
            for values in itertools.product(*(AXES[k].values() for k, _ in free))]


def claim_reading(point: Mapping, free: Iterable[FreeAxis]) -> dict:
    """A claim's reading at a point of the space: the point's values on the claim's free axes ``free``
    (as ``{axis key: value}``), every other axis at its default."""
    out = default_reading()
    for f in free:
        if f in point:
            out[f[0]] = point[f]
    return out


def project(reading: Mapping, keys: Iterable[str]) -> dict:
    """``reading`` (``{axis key: value}``) with every axis not in ``keys`` at its default: the point of
    a claim's :func:`design` that gives its state at ``reading``."""
    keys = set(keys)
    return {k: (reading[k] if k in keys else a.default) for k, a in AXES.items()}


def changed_axes(point: Mapping) -> int:
    """How many free axes of a point are away from their default."""
    return sum(value != AXES[f[0]].default for f, value in point.items())


def describe(reading: Mapping, *, only_changed: bool = True) -> str:
    """A claim's reading in words, e.g. ``"fly-back rule = fixed"``; ``"defaults"`` when nothing changed."""
    parts = [f"{AXES[k].label} = {AXES[k].show(v)}" for k, v in reading.items()
             if k in AXES and (not only_changed or v != AXES[k].default)]
    return "; ".join(parts) if parts else "defaults"


def describe_point(point: Mapping) -> str:
    """A point of the space in words, each free axis with its section, e.g. ``"μ (Section 5) = 0.3;
    fly-back rule (Section 4.1) = fixed"``; ``"defaults"`` when every free axis has its default."""
    parts = [f"{free_label(f)} = {AXES[f[0]].show(v)}" for f, v in point.items() if v != AXES[f[0]].default]
    return "; ".join(parts) if parts else "defaults"


def space_table() -> pd.DataFrame:
    """Every declared axis: default, evaluated alternatives, plausible range, its source, whether each
    section chooses it on its own, the result tables whose runs it changes, and the values that are not
    readings (with the reason)."""
    return pd.DataFrame([
        {"assumption": a.label, "key": a.key, "default": a.show(a.default),
         "evaluated alternatives": ", ".join(a.show(v) for v in a.alternatives) or "none (open)",
         "free in": (", ".join(s.label for s in SECTIONS.values() if set(a.tables) & set(s.tables))
                     + (" (each its own)" if a.scope == "section" else " (one value for all: stated, lost)")),
         "plausible range": a.plausible_range, "source": a.source,
         "changes": ", ".join(a.tables) + (f" ({a.only[0]} {a.only[1]} only)" if a.only else ""),
         "not a reading": "; ".join(f"{a.show(v)}: {why}" for v, why in a.not_readings)}
        for a in AXES.values()
    ])


def section_table() -> pd.DataFrame:
    """The paper's simulation sections: their figures, the values each states (not free there) and the
    inputs it leaves open (free there)."""
    rows = []
    for s in SECTIONS.values():
        open_ = [free_label(f) for f in declared_free_axes() if f[1] in (s.key, "")
                 and set(AXES[f[0]].tables) & set(s.tables)]
        rows.append({"section": s.label, "simulations": s.what,
                     "states": "; ".join(f"{AXES[k].label} = {AXES[k].show(v)} (“{q}”)"
                                         for k, v, q in s.stated)
                     or "—",
                     "free inputs": ", ".join(open_)})
    return pd.DataFrame(rows)
