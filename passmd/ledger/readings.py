"""The assumption space of the ledger: what the paper leaves open, and the readings we evaluate.

The paper leaves some inputs of its claims unstated (the fly-back rule, how the critical
amplitude was read off the runs, the drive frequency of Section 4.1, the actuator damping lost
from Table 2, μ in Sections 4.1 and 5, the drive frequency of the force runs, what Eq. 15 does
when t_s does not fit into a period). Each is declared here once as an :class:`Axis`: its
default (the value the rest of the book uses), the values of its plausible range that we
evaluate, the whole range in words, the source of that range, and the result tables whose runs
it changes (``Axis.tables``).

A *reading* is one point of that space: ``{axis key: value}``. **A reading keeps the claim's
object**: an axis may change only what the paper left unstated, never the thing a claim is
about. A value that would change the object is not a reading: it is listed in
``Axis.not_readings`` with the reason and shown as a study in its chapter. Setting t_s = 0
wherever the settling time does not fit (``skip``) removes Eq. 15's settling phase from every
period from 10 kHz up, so that waveform is not Eq. 15 and ``skip`` is no reading of the Eq. 15
claims; the velocity chapter keeps it as the study "what if the settling is dropped".

**Declared = computed.** A claim depends on an axis when it reads a result table whose runs the
axis changes (:func:`applicable`): its extractor must declare exactly those axes
(``passmd.ledger.checks.extractor(id, depends_on=(...))``), and the ledger evaluates it on the
full product of their values (:func:`design`, the defaults first). Every table a claim reads
holds a run at every point of that product; an extractor that finds none raises
:class:`passmd.ledger.checks.NoRun`, which the ledger treats as a defect, never as "not
covered". A claim has the same state at every value of an axis it does not depend on, so every
point of the whole space (:func:`space`) has a state for every claim (:func:`project`): that is
what the joint reading of :mod:`passmd.ledger.joint` is chosen from. An axis declared with no
evaluated alternative (``short_period``) is listed in the report as open.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import pandas as pd

from passmd.ledger.claims import required_keys
from passmd.model.defaults import PROTOCOL

__all__ = ["AC_TABLES", "AXES", "Axis", "SECTION5_TABLES", "applicable", "axis", "default_reading", "design",
           "describe", "project", "space", "space_table"]

#: The result tables of the ledger's readings (``passmd.report.evaluation.result_sources``): the
#: critical-amplitude searches of Figs. 5b and 6a–6c, the step against amplitude of Fig. 5a, this
#: paper's force runs of Fig. 7, and Section 5's runs (Fig. 9a holds both μ itself). Each holds a
#: run at every point of the axes that change it.
AC_TABLES = ("fig5b_readings", "fig6a_readings", "fig6b_readings", "fig6c_readings")
SECTION4_1_TABLES = ("fig5a_readings", *AC_TABLES)
FORCE_TABLES = ("fig7_readings",)
SECTION5_TABLES = ("fig8a_readings", "fig8b_readings", "fig8b_window_readings", "fig9a", "fig9a_response",
                   "fig9b_readings", "fig10a_readings", "fig10b_readings", "fig10c_readings")
VELOCITY_TABLES = ("fig9b_readings", "fig10a_readings", "fig10b_readings", "fig10c_readings")


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
            "below the full stroke, rigid or flexible (Section 4); Section 5 drives at the full stroke, "
            "where both rules give 2 µs",
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
            label="drive frequency, Section 4.1",
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
            alternatives=(),
            unit="",
            plausible_range="cut the settling time t_s to the time left in the period (t_s > 0 keeps "
            "Eq. 15's settling phase)",
            source="Section 5.2 says only that above 110 kHz there is 'not enough time for settling'",
            tables=VELOCITY_TABLES,
            only=("waveform", "optimized"),
            assumption_key="optimized_short_period",
            not_readings=(("skip", "t_s = 0 wherever the settling time does not fit removes Eq. 15's "
                           "settling phase from 10 kHz up: the waveform is no longer Eq. 15, so it is the "
                           "velocity chapter's study 'what if the settling is dropped'"),),
        ),
        Axis(
            key="damping_ratio",
            label="actuator damping ratio ζ",
            default=0.05,
            alternatives=(0.005, 0.5),  # the ends of the plausible range
            unit="",
            plausible_range="0.005–0.5 (a decade either side of a lightly damped piezo stack, Q = 10)",
            source="Table 2's viscosity column c_p is lost in the available text; it changes every run of "
            "flexible actuators",
            tables=(*SECTION4_1_TABLES, *FORCE_TABLES),
            only=("actuator_model", "flexible"),
            assumption_key="actuator_viscosity",
        ),
        Axis(
            key="force_frequency",
            label="drive frequency, Section 4.2",
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
            label="μ in Sections 4.1 and 5",
            default=0.2,
            alternatives=(0.3,),  # the value Section 4.2 says [12] used
            unit="",
            plausible_range="0.2–0.3 (Section 4.2's measured 0.2 and the earlier model's 0.3)",
            source="Sections 4.1 and 5 do not state μ; Section 4.2 uses 0.2 (Lübke [24]) and 0.3 ([12]). The "
            "closed forms of Eqs. 7–14 are evaluated at the same μ as the runs they are compared with",
            tables=(*SECTION4_1_TABLES, *SECTION5_TABLES),
        ),
    )
}


def applicable(claim: Mapping) -> tuple[str, ...]:
    """The axes a claims.csv row depends on (:meth:`Axis.applies_to`), in the order of :data:`AXES`:
    its extractor must declare exactly these."""
    return tuple(key for key, a in AXES.items() if a.applies_to(claim))


def axis(key: str) -> Axis:
    """The declared axis ``key``; ``ValueError`` naming the declared ones otherwise."""
    if key not in AXES:
        raise ValueError(f"assumption axis = {key!r} is not declared: must be one of {', '.join(AXES)}")
    return AXES[key]


def default_reading() -> dict:
    """``{axis key: default}`` for every declared axis."""
    return {key: a.default for key, a in AXES.items()}


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


def space() -> list[dict]:
    """Every point of the declared assumption space (the product of all axes' values), defaults first."""
    return design(AXES)


def project(reading: Mapping, keys: Iterable[str]) -> dict:
    """``reading`` with every axis not in ``keys`` at its default: the point of a claim's
    :func:`design` that gives its state at ``reading`` (a claim has the same state at every value
    of an axis it does not depend on)."""
    keys = set(keys)
    return {k: (reading[k] if k in keys else a.default) for k, a in AXES.items()}


def describe(reading: Mapping, *, only_changed: bool = True) -> str:
    """A reading in words, e.g. ``"fly-back rule = fixed"``; ``"defaults"`` when nothing changed."""
    parts = [f"{AXES[k].label} = {AXES[k].show(v)}" for k, v in reading.items()
             if k in AXES and (not only_changed or v != AXES[k].default)]
    return "; ".join(parts) if parts else "defaults"


def space_table() -> pd.DataFrame:
    """Every declared axis: default, evaluated alternatives, plausible range, its source, the result
    tables whose runs it changes, and the values that are not readings (with the reason)."""
    return pd.DataFrame([
        {"assumption": a.label, "key": a.key, "default": a.show(a.default),
         "evaluated alternatives": ", ".join(a.show(v) for v in a.alternatives) or "none (open)",
         "plausible range": a.plausible_range, "source": a.source,
         "changes": ", ".join(a.tables) + (f" ({a.only[0]} {a.only[1]} only)" if a.only else ""),
         "not a reading": "; ".join(f"{a.show(v)}: {why}" for v, why in a.not_readings)}
        for a in AXES.values()
    ])
