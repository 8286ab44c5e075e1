"""The assumption space of the ledger: what the paper leaves open, and the readings we evaluate.

The paper leaves some inputs of its claims unstated (the fly-back rule, how the critical
amplitude was read off the runs, the drive frequency of Section 4, the actuator damping lost
from Table 2, μ in Sections 4.1 and 5, what Eq. 15 does when t_s does not fit into a period).
Each is declared here once as an :class:`Axis`: its default (the value the rest of the book
uses), the values of its plausible range that we evaluate, the whole range in words, and the
source of that range.

A *reading* is one point of that space: ``{axis key: value}``. **A reading keeps the claim's
object**: an axis may change only what the paper left unstated (the fly-back, the damping, the
drive frequency, μ, how A_c is read off the runs, how t_s is fitted into a short period), never
the thing a claim is about. A value that would change the object is not a reading: it is listed
in ``Axis.not_readings`` with the reason and shown as a study in its chapter. Setting t_s = 0
wherever the settling time does not fit (``skip``) removes Eq. 15's settling phase from every
period from 10 kHz up, so that waveform is not Eq. 15 and ``skip`` is no reading of the Eq. 15
claims; the driving-waveform chapter keeps it as the study "what if the settling is dropped".

The ledger evaluates every claim on the full product of the axes it depends on
(:func:`design`: the defaults first), minus the axes declared open for it. An extractor
declares the axes it reads with ``passmd.ledger.checks.extractor(id, depends_on=(...))`` and receives
the reading as its ``reading`` argument; when the result tables hold no run at that reading it
raises :class:`passmd.ledger.checks.NotEvaluable`, and that point counts as not covered. A claim that
does not depend on an axis has the same state at every value of it, so every point of the whole
space (:func:`space`) has a state for every claim (:func:`project`): that is what the joint
reading of :mod:`passmd.ledger.evaluation` is chosen from.

Axes declared with no evaluated alternative are listed in the report as open: the ledger cannot
yet say whether a claim's verdict moves along them. An axis with alternatives can still be open for
some claims it applies to (``Axis.open_for``, with its reason): their result tables hold no run at
the alternatives, so they are evaluated at the default only.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import pandas as pd

from passmd.model.defaults import PROTOCOL

__all__ = ["AXES", "Axis", "axis", "default_reading", "design", "describe", "project", "space", "space_table"]


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
    assumption_key: str = ""  # the key of the matching passmd.model.tables assumption, if any
    open_for: tuple = ()  # claim ids the axis applies to but whose result tables lack its alternatives
    open_reason: str = ""  # why those claims are not evaluated along the axis
    not_readings: tuple = ()  # (value, reason): values that would change a claim's object (studies only)

    def values(self) -> tuple:
        return (self.default, *self.alternatives)

    def show(self, value) -> str:
        text = f"{value:g}" if isinstance(value, float) else str(value)
        return f"{text} {self.unit}".strip()


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
            "simulated saw-tooth; 'fixed' is the full-stroke 2 µs at every amplitude",
            assumption_key="flyback_duration",
            open_for=("sec4-2-other-preloads-same-trend",
                      "sec4-2-friction-and-actuator-dynamics-cause-discrepancy"),
            open_reason="the preload grid (fig7grid) and the stall cycle (fig7cycle) of Section 4.2 are "
            "computed with the slew-rate fly-back only; Figs. 7a and 7b are computed with both "
            "(fig7flyback), so the claims read from them are evaluated along the axis",
        ),
        Axis(
            key="ac_protocol",
            label="how A_c is read",
            default="steady",
            alternatives=("first",),
            unit="",
            plausible_range="steady state of continued operation (last step of a 10-period run) or the "
            "onset of full sliding in the first fly-back from virgin contacts",
            source="Section 1 defines A_c by 'no measurable step'; Section 4.1 compares it with "
            "quasi-static onsets (Eqs. 7–12) without saying how it was read off the runs",
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
            assumption_key="optimized_short_period",
            not_readings=(("skip", "t_s = 0 wherever the settling time does not fit removes Eq. 15's "
                           "settling phase from 10 kHz up: the waveform is no longer Eq. 15, so it is the "
                           "driving-waveform chapter's study 'what if the settling is dropped'"),),
        ),
        Axis(
            key="damping_ratio",
            label="actuator damping ratio ζ",
            default=0.05,
            alternatives=(0.005, 0.5),  # the ends of the plausible range
            unit="",
            plausible_range="0.005–0.5 (a decade either side of a lightly damped piezo stack, Q = 10)",
            source="Table 2's viscosity column c_p is lost in the available text",
            assumption_key="actuator_viscosity",
            open_for=("fig5a-no-step-below-50nm", "fig7a-force-difference-115mn",
                      "fig7a-discrepancy-grows-with-amplitude", "fig7b-discrepancy-grows-with-amplitude",
                      "fig7-critical-amplitude-both-models",
                      "sec4-2-friction-and-actuator-dynamics-cause-discrepancy",
                      "sec4-2-other-preloads-same-trend", "fig7-rigid-mu03-flexible-mu02-onsets-agree",
                      "fig7-force-grows-with-amplitude-above-onset", "fig7-force-grows-with-preload",
                      "fig7-flexible-covers-experiment", "abstract-agreement-with-experiment",
                      "fig6b-experiment-agreement"),
            open_reason="Fig. 5a's amplitude grid and the Section 4.2 force runs are computed at the "
            "default ζ only; the A_c searches of Figs. 5b, 6b and 6c run at both ends of the range",
        ),
        Axis(
            key="force_frequency",
            label="drive frequency, Section 4.2",
            default=PROTOCOL.drive_frequency,
            alternatives=(1000.0,),
            unit="Hz",
            plausible_range="90 Hz – 1.1 kHz",
            source="Section 4.2 does not state the saw-tooth frequency of the force runs",
            assumption_key="force_frequency",
        ),
        Axis(
            key="friction_coefficient",
            label="μ in Sections 4.1 and 5",
            default=0.2,
            alternatives=(0.3,),  # the value Section 4.2 says [12] used
            unit="",
            plausible_range="0.2–0.3 (Section 4.2's measured 0.2 and the earlier model's 0.3)",
            source="Sections 4.1 and 5 do not state μ; Section 4.2 uses 0.2 (Lübke [24]) and 0.3 ([12])",
            open_for=("fig5a-no-step-below-50nm", "fig5b-rigid-ac-matches-eq7",
                      "fig5b-flexible-ac-matches-eq8", "fig5b-flexible-above-rigid",
                      "fig6a-rigid-ac-matches-eq11", "fig6a-rigid-ac-not-eq10",
                      "fig6b-flexible-r1-ac-matches-eq12", "fig6c-flexible-r025-ac-matches-eq12",
                      "fig8a-back-step", "sec5-response-to-optimized-similar",
                      "fig9b-optimized-faster-below-110khz", "fig9b-max-gain-2.5mm_s",
                      "fig9b-optimized-decreases-above-110khz", "fig9b-standard-increases-above-110khz",
                      "fig9b-step-decreases-with-frequency", "fig9b-no-time-to-settle-above-110khz",
                      "abstract-velocity-gain-15pct", "fig10a-max-velocity-19mm_s",
                      "fig10a-max-velocity-at-110khz", "fig10a-1n-slower", "fig10a-1n-larger-back-step",
                      "fig10a-0.1n-smaller-back-step", "fig10a-0.1n-stick-lost-above-80khz",
                      "fig10a-0.1n-slightly-slower", "fig10b-r1-faster", "fig10b-r1-higher-max-frequency",
                      "fig10b-r1-smaller-back-step", "fig10c-youngs-modulus-negligible",
                      "conclusion-youngs-modulus-weaker-than-preload-and-radius",
                      "fig9b-sawtooth-velocity-16.5mm_s-at-110khz",
                      "fig10a-0.1n-maximum-at-or-below-80khz",
                      "sec5-1-acceleration-starts-at-velocity-maximum",
                      "sec5-1-stick-during-acceleration", "sec5-1-spring-deformed-to-ux-max-after-flyback",
                      "sec5-1-fastest-at-end-of-acceleration", "sec5-1-runner-overshoots-in-slip",
                      "fig8a-micro-vibration-damped-within-next-stick", "fig6b-flexible-r1-ac-not-eq13",
                      "fig6c-flexible-r025-ac-not-eq13", "sec4-1-interaction-changes-ac",
                      "fig6b-experiment-agreement"),
            open_reason="Section 4.1's closed forms (Eqs. 7–14) are committed as reference curves at "
            "μ = 0.2 only; the Fig. 8 traces and the resolved fly-back window are computed at μ = 0.2 "
            "only (not extended yet); the frequency sweeps of Figs. 9b and 10 would double in cost. "
            "Only the Fig. 9a runs are repeated at μ = 0.3",
        ),
    )
}


def axis(key: str) -> Axis:
    """The declared axis ``key``; ``ValueError`` naming the declared ones otherwise."""
    if key not in AXES:
        raise ValueError(f"assumption axis = {key!r} is not declared: must be one of {', '.join(AXES)}")
    return AXES[key]


def default_reading() -> dict:
    """``{axis key: default}`` for every declared axis."""
    return {key: a.default for key, a in AXES.items()}


def design(depends_on: Iterable[str], claim_id: str | None = None) -> list[dict]:
    """The readings a claim depending on ``depends_on`` is evaluated at.

    The full product of the values (default and evaluated alternatives) of every axis in
    ``depends_on``, except the axes declared open for ``claim_id`` (``Axis.open_for``), every
    other axis at its default; the defaults first. Each reading is a full ``{axis key: value}``
    dict.
    """
    base = default_reading()
    keys = [k for k in dict.fromkeys(depends_on) if claim_id is None or claim_id not in axis(k).open_for]
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
    """Every declared axis: default, evaluated alternatives, plausible range, its source, and the
    claims it applies to that are not evaluated along it (``open for``, with the reason)."""
    return pd.DataFrame([
        {"assumption": a.label, "key": a.key, "default": a.show(a.default),
         "evaluated alternatives": ", ".join(a.show(v) for v in a.alternatives) or "none yet",
         "plausible range": a.plausible_range, "source": a.source,
         "open for": (f"{len(a.open_for)} claims ({', '.join(a.open_for)}): {a.open_reason}"
                      if a.open_for else ""),
         "not a reading": "; ".join(f"{a.show(v)}: {why}" for v, why in a.not_readings)}
        for a in AXES.values()
    ])
