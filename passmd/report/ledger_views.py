"""The ledger in the book: headline, one-line table, per-claim details, assumption map, sources.

Presentation only: every function takes a table computed by :func:`passmd.ledger.evaluation.evaluate`
(or claims from :func:`passmd.ledger.claims.load_claims`) and returns text, MyST markdown or a pandas
``Styler``; nothing here computes a category.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

import numpy as np
import pandas as pd

from passmd.ledger.checks import format_number
from passmd.ledger.claims import STATUSES, tolerance_text
from passmd.ledger.evaluation import assumption_map
from passmd.report.assumptions import all_assumptions
from passmd.runtime.validation import check_choice

__all__ = [
    "STATUS_COLOURS",
    "assumption_map_styled",
    "assumptions_table",
    "category_anchor",
    "claim_anchor",
    "details_markdown",
    "headline_markdown",
    "sources_markdown",
    "styled",
    "summary",
]


def summary(evaluated: pd.DataFrame) -> str:
    """One line such as ``"11 of 40 claims reproduced (1 a closed-form identity); 3 inconclusive"``.

    Closed-form identities are counted apart: they are not simulation results.
    """
    counts = evaluated["status"].value_counts()
    closed = int(((evaluated["status"] == "reproduced") & (evaluated["basis"] == "closed form")).sum())
    text = f"{int(counts.get('reproduced', 0))} of {len(evaluated)} claims reproduced"
    if closed:
        text += f" ({closed} of them a closed-form identity, not a simulation)"
    others = [f"{int(counts[s])} {s}" for s in STATUSES[1:] if counts.get(s, 0)]
    return text + ("; " + ", ".join(others) if others else "")


def category_anchor(status: str) -> str:
    """The anchor of a category's list in the replication report, e.g. ``ledger-not-reproduced``."""
    check_choice("status", status, STATUSES)
    return "ledger-" + status.replace(" ", "-")


def claim_anchor(claim_id: str) -> str:
    """The anchor of a claim's details in the replication report."""
    return "claim-" + re.sub(r"[^a-z0-9-]", "-", claim_id)


def headline_markdown(evaluated: pd.DataFrame, page: str = "replication_report", *, ref: bool = False) -> str:
    """The per-category counts as MyST markdown, each linking to that category's claims.

    Links go to the targets :func:`details_markdown` writes: ``{ref}`` roles when ``ref`` is
    true (the book), markdown links to ``page.md#anchor`` otherwise.
    """
    counts = evaluated["status"].value_counts()
    parts = []
    for status in STATUSES:
        n = int(counts.get(status, 0))
        label = f"{n} {status}"
        if n and ref:
            label = f"{{ref}}`{label} <{category_anchor(status)}>`"
        elif n:
            label = f"[{label}]({page}.md#{category_anchor(status)})"
        parts.append(label)
    closed = int(((evaluated["status"] == "reproduced") & (evaluated["basis"] == "closed form")).sum())
    note = f" ({closed} of the reproduced a closed-form identity, not a simulation)" if closed else ""
    flags = (f"; {int(evaluated['fragile'].astype(bool).sum())} fragile (hold at the defaults but fail at "
             f"the joint reading or at most of their readings), "
             f"{int((~evaluated['informative'].astype(bool)).sum())} not informative "
             "(their check cannot fail)"
             if "fragile" in evaluated else "")
    return f"{len(evaluated)} claims: " + ", ".join(parts) + note + flags


#: Background colours of the categories in :func:`styled`.
STATUS_COLOURS = {
    "reproduced": "#d4edda",
    "reproduced under the joint reading": "#d1ecf1",
    "not reproduced": "#f8d7da",
    "inconclusive": "#e9ecef",
}


def styled(evaluated: pd.DataFrame, *, links: bool = False):
    """A pandas ``Styler`` of the ledger for the book: one short line per claim.

    Columns: claim, figure, paper, ours, category (coloured badge), margin at the defaults,
    failing readings (of the decided ones) and flags (fragile, not informative). Details (quote, reason,
    evidence, readings) are in :func:`details_markdown`; with ``links=True`` each claim links
    to its details on the same page. The table carries the HTML class ``passmd-ledger`` (the
    rendered-book check looks for it) and wraps inside the content column.
    """
    shown = evaluated[["claim", "figure", "paper", "ours", "status"]].copy()
    shown["ours"] = [format_number(v) if isinstance(v, (float, np.floating)) else str(v)
                     for v in shown["ours"]]
    if "margin_text" in evaluated:
        shown["margin"] = evaluated["margin_text"].to_numpy()
        shown["fails at"] = [f"{int(f)} of {int(d)}" if d else "—"
                             for f, d in zip(evaluated["fails_at"], evaluated["decided_at"], strict=True)]
        shown["flags"] = [", ".join(([("fragile")] if fr else []) + ([] if inf else ["not informative"]))
                          for fr, inf in zip(evaluated["fragile"], evaluated["informative"], strict=True)]
    if links:
        shown["claim"] = [f'<a href="#{claim_anchor(c)}">{c}</a>' for c in evaluated["claim"]]
    shown["status"] = [s + (" (closed form)" if b == "closed form" else "")
                       for s, b in zip(evaluated["status"], evaluated["basis"], strict=True)]
    shown = shown.rename(columns={"status": "category"})
    statuses = evaluated["status"].to_numpy()

    def colour(column):
        return [f"background-color: {STATUS_COLOURS[s]}" for s in statuses]

    return (
        shown.style.hide(axis="index")
        .apply(colour, subset=["category"])
        .set_table_attributes('class="passmd-ledger"')
        .set_table_styles([
            {"selector": "", "props": "table-layout: fixed; width: 100%; max-width: 100%;"},
            {"selector": "td, th", "props": "font-size: 0.8em; vertical-align: top; overflow-wrap: anywhere; "
                                            "word-break: break-word; white-space: normal;"},
        ])
    )


def details_markdown(evaluated: pd.DataFrame, claims: pd.DataFrame) -> str:
    """Per claim, a collapsed block with an anchor: verdict, quote, evidence, reason and source.

    Claims are grouped by category; each group starts with the target of
    :func:`category_anchor` (so the intro's headline can link to it) and each claim with the
    target of :func:`claim_anchor` (the ledger table links to it). The blocks are dropdown
    admonitions: closed until the reader opens them.
    """
    by_id = claims.set_index("id")
    blocks = []
    for status in STATUSES:
        rows = evaluated[evaluated["status"] == status]
        blocks.append(f"({category_anchor(status)})=\n**{status.capitalize()}: {len(rows)}**\n")
        for row in rows.itertuples():
            claim = by_id.loc[row.claim]
            section, check = _section_text(claim), _check_text(claim)
            basis = " (closed form)" if row.basis == "closed form" else ""
            lines = [f"({claim_anchor(row.claim)})=",
                     "```{admonition} " + f"{_md_escape(row.claim)}: {status}{basis}",
                     ":class: dropdown",
                     "",
                     f"*Paper* ({_md_escape(section)}): “{_md_escape(claim['source_quote'])}”", "",
                     f"*Verdict (computed):* {_md_escape(row.verdict)}.", ""]
            if row.basis == "closed form":
                lines += ["*Basis:* a closed-form identity, not a simulation result.", ""]
            if row.evidence:
                lines.append("*Evidence (computed):*")
                lines.append("")
                lines += [f"- {_md_escape(item)}" for item in row.evidence.split(" | ")]
                lines.append("")
            if row.depends_on:
                lines += [f"*Readings:* holds at {row.holds_at} of {row.readings}; best: "
                          f"{_md_escape(row.best_reading)}.", ""]
            if row.reason and status != "reproduced":
                lines += [f"*Reason (our reading of the evidence):* {_md_escape(row.reason)}", ""]
            lines += [f"*Configuration:* {_md_escape(_config_text(claim))}. "
                      f"*Ours:* {_md_escape(claim['ours_definition'])}. "
                      f"*Check:* {_md_escape(check)}. {_md_escape(claim['tolerance_reason'])}"]
            if claim["notes"]:
                lines += ["", f"*Notes:* {_md_escape(claim['notes'])}"]
            lines.append("```")
            blocks.append("\n".join(lines) + "\n")
    return "\n".join(blocks)


def assumption_map_styled(evaluated: pd.DataFrame):
    """:func:`passmd.ledger.evaluation.assumption_map` as a compact coloured table (✓ holds, ✗ fails, ?
    inconclusive).

    The columns are numbered readings; the caption lists what each number means, so the table
    stays inside the content column.
    """
    table = assumption_map(evaluated)
    readings_ = [c for c in table.columns if c not in ("claim", "holds at", "best reading")]
    symbols = {"holds": "✓", "fails": "✗", "inconclusive": "?", "": ""}
    shown = table.rename(columns={r: f"R{i}" for i, r in enumerate(readings_)})
    for i in range(len(readings_)):
        shown[f"R{i}"] = shown[f"R{i}"].map(symbols)
    colours = {"✓": STATUS_COLOURS["reproduced"], "✗": STATUS_COLOURS["not reproduced"],
               "?": STATUS_COLOURS["inconclusive"], "": ""}
    caption = "; ".join(f"R{i}: {r}" for i, r in enumerate(readings_))
    return (shown.style.hide(axis="index")
            .map(lambda v: f"background-color: {colours[v]}" if colours.get(v) else "",
                 subset=[f"R{i}" for i in range(len(readings_))])
            .set_caption("✓ holds, ✗ fails, ? inconclusive, blank: the claim does not depend on it. "
                         f"{caption}.")
            .set_table_attributes('class="passmd-assumption-map"')
            .set_table_styles([
                {"selector": "", "props": "table-layout: fixed; width: 100%; max-width: 100%;"},
                {"selector": "td, th, caption", "props": "font-size: 0.8em; overflow-wrap: anywhere; "
                                                         "white-space: normal;"},
            ]))


_CONFIG_LABELS = {
    "contacts": ("contacts", ""), "actuator_model": ("actuators", ""), "radius_mm": ("R", "mm"),
    "preload_N": ("F_p", "N"), "friction_coefficient": ("μ", ""), "amplitude_nm": ("A", "nm"),
    "frequency_Hz": ("f", "Hz"), "waveform": ("waveform", ""),
}


def _md_escape(text: str) -> str:
    """Escape the characters MyST would read as markup (u*_x,max must not turn italic)."""
    return re.sub(r"([\\`*_\[\]<>$|#])", r"\\\1", text)


def _config_text(claim: Mapping) -> str:
    assumed = {c for c in claim["assumed"].split(";") if c}
    parts = []
    for column, (label, unit) in _CONFIG_LABELS.items():
        value = claim[column]
        if not value:
            continue
        if ":" in value:
            start, stop, *step = value.split(":")
            value = f"{start}–{stop}" + (f" in steps of {step[0]}" if step else "")
        value = value.replace(";", ", ")
        if value == "grid":
            shown = f"{label} on the preload grid"
        else:
            shown = f"{label} = {value}" + (f" {unit}" if unit else "")
        parts.append(shown + (" (assumed)" if column in assumed else ""))
    return "; ".join(parts) if parts else "—"


def _section_text(claim: Mapping) -> str:
    """The claim's source section as shown: ``Section 4.1``, or the source as written (``Abstract``)."""
    section = claim["source_section"]
    return f"Section {section}" if section[:1].isdigit() else section


def _check_text(claim: Mapping) -> str:
    """The claim's check as shown, e.g. ``ordering (<)`` or ``value, tolerance 5 %``."""
    check = claim["check"] + (f" ({claim['relation']})" if claim["relation"] else "")
    if claim["tolerance"]:
        check += f", tolerance {tolerance_text(claim)}"
    return check


def sources_markdown(claims: pd.DataFrame) -> str:
    """Each claim's source as MyST markdown: quotation, configuration, tolerance reason, notes.

    Configuration values the paper does not state are marked *(assumed)*.
    """
    items = []
    for _, claim in claims.iterrows():
        section, check = _section_text(claim), _check_text(claim)
        lines = [
            f"* **{_md_escape(claim['id'])}** (Fig. {_md_escape(claim['figure'])}, {_md_escape(section)}): "
            f"“{_md_escape(claim['source_quote'])}”",
            f"  *Configuration:* {_md_escape(_config_text(claim))}.",
            f"  *Ours:* {_md_escape(claim['ours_definition'])}.",
            f"  *Check:* {_md_escape(check)}. {_md_escape(claim['tolerance_reason'])}",
        ]
        if claim["notes"]:
            lines.append(f"  *Notes:* {_md_escape(claim['notes'])}")
        items.append("\n".join(line + "  " if i < len(lines) - 1 else line for i, line in enumerate(lines)))
    return "\n".join(items) + "\n"


def assumptions_table() -> pd.DataFrame:
    """Every assumption where the paper is silent, as the book's table.

    The assumptions are those of :func:`passmd.report.assumptions.all_assumptions`, in its order.
    """
    return pd.DataFrame(
        [{"key": a.key, "symbol": a.symbol, "value": a.value, "unit": a.unit, "rationale": a.rationale,
          "effect on the results": a.sensitivity} for a in all_assumptions().values()]
    )
