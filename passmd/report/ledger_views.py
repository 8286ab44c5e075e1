"""The ledger in the book: headline, one-line table, per-claim details, assumption map, sources.

Presentation only: every function takes a table computed by :func:`passmd.report.evaluation.evaluate`
(or claims from :func:`passmd.ledger.claims.load_claims`) and returns text, MyST markdown or a pandas
``Styler``; nothing here computes a category.
"""

from __future__ import annotations

import html
import re
from collections.abc import Mapping

import pandas as pd

from passmd.ledger import readings
from passmd.ledger.claims import REPRODUCED, STATUSES, tolerance_text
from passmd.ledger.rules import FRAGILE_MARGIN
from passmd.ledger.verdicts import EXPERIMENT_BASIS
from passmd.report.assumptions import all_assumptions
from passmd.report.evaluation import assumption_map, counted
from passmd.runtime.validation import check_choice

__all__ = [
    "STATUS_COLOURS",
    "STUDIES_ANCHOR",
    "assumption_map_styled",
    "assumptions_table",
    "category_anchor",
    "claim_anchor",
    "details_markdown",
    "families_markdown",
    "held_out_sentences",
    "readings_count",
    "headline_markdown",
    "sources_markdown",
    "styled",
    "joint_sentences",
    "summary",
    "tension_sentences",
]


def summary(evaluated: pd.DataFrame) -> str:
    """One line such as ``"9 of 41 claims reproduced (2 under the joint reading); 4 hold by construction,
    20 not reproduced, 8 inconclusive (…)"``.

    Counts the claims of the paper, each family once, judged at their held-out readings (studies and
    rows implied by another are shown, never counted, :mod:`passmd.ledger.rules`); rows holding by
    construction are never counted as reproduced.
    """
    claims = counted(evaluated)
    counts = claims["status"].value_counts()
    reproduced = sum(int(counts.get(s, 0)) for s in REPRODUCED)
    text = f"{reproduced} of {len(claims)} claims reproduced"
    under = int(counts.get(REPRODUCED[1], 0))
    if under:
        text += f" ({under} under the joint reading)"
    others = [f"{int(counts[s])} {_plural(s, int(counts[s]))}" for s in STATUSES[2:] if counts.get(s, 0)]
    studies = int((evaluated["study_of"] != "").sum())
    implied = int(((evaluated["study_of"] == "") & ~evaluated["counted"].astype(bool)).sum()) \
        if "counted" in evaluated else 0
    shown = ([f"{implied} implied {'row' if implied == 1 else 'rows'} counted with their family"]
             if implied else [])
    shown += [f"{studies} {'study' if studies == 1 else 'studies'}"] if studies else []
    return (text + ("; " + ", ".join(others) if others else "")
            + (f" ({' and '.join(shown)} shown, not counted)" if shown else ""))


def _plain(point: Mapping) -> dict:
    """A point of the space with plain keys (``key@section``), as ``passmd ledger --json`` writes it."""
    return {(k if isinstance(k, str) else readings.point_key(k)): v for k, v in point.items()}


def _plural(status: str, n: int) -> str:
    """A category as a count reads it: ``"1 holds by construction"``, ``"4 hold by construction"``."""
    return status.replace("holds", "hold") if status.startswith("holds") and n != 1 else status


def held_out_sentences(evaluated: pd.DataFrame) -> list[str]:
    """How the counts are judged, in sentences: every claim at its held-out reading, the largest number
    of claims holding at one point, and the in-sample joint reading with its gain over held out."""
    joint = evaluated.attrs.get("joint", {})
    gain = joint.get("in_sample_gain", [])
    claims = counted(evaluated)
    reproduced = int(claims["status"].isin(REPRODUCED).sum())
    lines = [f"Each claim is judged at its held-out reading: the joint reading chosen, by the same rule, "
             f"from all the other claims. {reproduced} reproduced that way; at most "
             f"{joint.get('best_single_point', 0)} claims hold together at any one point of the space."]
    if joint:
        lines.append(f"In-sample (the joint reading chosen with every claim, {joint['described']}): "
                     f"{joint['holding']} of {joint['claims']} voting claims hold"
                     + (f"; +{len(gain)} in-sample {'pass' if len(gain) == 1 else 'passes'}: "
                        + ", ".join(gain)
                        if gain else "; no claim holds only in-sample") + ".")
    return lines


def joint_sentences(joint: Mapping) -> list[str]:
    """The in-sample joint reading in sentences: where it is, how many claims hold there, the points it
    was chosen from and stands for, its ties, its runner-ups with their margins, and how it changes when
    rows are left out. The replication report and ``passmd ledger`` print these same sentences."""
    lines = [
        f"Joint reading (in-sample): {joint['described']}, where {joint['holding']} of {joint['claims']} "
        "voting claims hold together.",
        f"It was chosen from {joint['chosen_from']} of the {joint['points']} points of the declared "
        f"assumption space ({joint['covered_points']} covered: every claim resting on computed evidence "
        f"evaluated there from its runs; {joint['decided_points']} decided: every such claim holds or fails "
        f"there); {joint['equivalent_points']} of them give every claim the same state as it does.",
        ("Tied with it: " + "; ".join(f"{t['described']} ({t['holding']})" for t in joint["ties"])
         + (f" and {joint['tied_readings'] - len(joint['ties'])} more readings"
            if joint.get("tied_readings", 0) > len(joint["ties"]) else "") + "."
         if joint["ties"] else "No other reading ties with it."),
        ("Runner-ups: " + "; ".join(f"{r['described']} ({r['holding']} hold, {r['margin']} fewer)"
                                    for r in joint["runner_ups"]) + "."
         if joint["runner_ups"] else "No runner-up: every other reading holds as many claims."),
    ]
    for variant in joint.get("variants", []):
        same = variant["reading"] == _plain(joint["reading"])
        changed = len(variant["claims_left_out"]) or len(variant.get("claims_added", []))
        lines.append(f"With the {variant['left_out']} ({changed}): "
                     + ("the same reading" if same else variant["described"])
                     + f", {variant['holding']} of {variant['claims']} holding.")
    return lines


def tension_sentences(evaluated: pd.DataFrame) -> list[str]:
    """One sentence per tension (:func:`passmd.ledger.joint.tensions`): the readings that separate its
    claims and where each side holds, near-duplicate rows linked with '='."""
    out = []
    for tension in evaluated.attrs.get("tensions", []):
        sides = []
        for side in tension["sides"]:
            linked = {c for group in side["linked"] for c in group}
            names = ([" = ".join(group) for group in side["linked"]]
                     + [c for c in side["claims"] if c not in linked])
            sides.append(f"{', '.join(names)} hold{'s' if len(names) == 1 and ' = ' not in names[0] else ''} "
                         f"only at {side['holds_only_at']}")
        how = "Separated jointly by" if tension.get("jointly") else "Separated by"
        out.append(f"{how} {' and '.join(tension['separated_by'])} ({tension['pairs']} pair"
                   f"{'s' if tension['pairs'] != 1 else ''}): " + "; ".join(sides) + ".")
    return out


def category_anchor(status: str) -> str:
    """The anchor of a category's list in the replication report, e.g. ``ledger-not-reproduced``."""
    check_choice("status", status, STATUSES)
    return "ledger-" + status.replace(" ", "-")


def claim_anchor(claim_id: str) -> str:
    """The anchor of a claim's details in the replication report."""
    return "claim-" + re.sub(r"[^a-z0-9-]", "-", claim_id)


#: The anchor of the studies in the replication report.
STUDIES_ANCHOR = "ledger-studies"


def headline_markdown(evaluated: pd.DataFrame, page: str = "replication_report", *, ref: bool = False) -> str:
    """The per-category counts of the claims of the paper (each family once, judged at its held-out
    reading) as MyST markdown, each linking to that category's claims, with the fragile, not-informative
    and experiment rows, the implied rows and the studies.

    Links go to the targets :func:`details_markdown` writes: ``{ref}`` roles when ``ref`` is
    true (the book), markdown links to ``page.md#anchor`` otherwise.
    """

    def link(label, anchor):
        return f"{{ref}}`{label} <{anchor}>`" if ref else f"[{label}]({page}.md#{anchor})"

    claims = counted(evaluated)
    counts = claims["status"].value_counts()
    parts = []
    for status in STATUSES:
        n = int(counts.get(status, 0))
        label = f"{n} {_plural(status, n)}"
        parts.append(link(label, category_anchor(status)) if n else label)
    flags = ""
    if "fragile" in claims:
        experiment = int((claims["basis"] == EXPERIMENT_BASIS).sum())
        flags = (f"; {int(claims['fragile'].astype(bool).sum())} fragile (the verdict flips at a runner-up "
                 f"reading or its margin is within {FRAGILE_MARGIN:.0%} of its tolerance), "
                 f"{experiment} about the experiment (no measured data in the text)")
    implied = int(((evaluated["study_of"] == "") & ~evaluated["counted"].astype(bool)).sum()) \
        if "counted" in evaluated else 0
    if implied:
        one = implied == 1
        flags += (f"; {implied} implied {'row' if one else 'rows'} counted with "
                  f"{'its' if one else 'their'} family")
    studies = int((evaluated["study_of"] != "").sum())
    if studies:
        flags += "; " + link(f"{studies} studies", STUDIES_ANCHOR) + " shown, not counted"
    return f"{len(claims)} claims, each judged at its held-out reading: " + ", ".join(parts) + flags


#: Background colours of the categories in :func:`styled`.
STATUS_COLOURS = {
    "reproduced": "#d4edda",
    "reproduced under the joint reading": "#d1ecf1",
    "holds by construction": "#fff3cd",
    "not reproduced": "#f8d7da",
    "inconclusive": "#e9ecef",
}


def _ours_vs_paper(row) -> str:
    """Our value at the held-out reading against the paper's, in one cell."""
    if "the paper's" in row.ours_text:  # a value check names the paper's number itself
        return row.ours_text
    return f"{row.ours_text}; paper: {row.paper}"


def _short(text: str, limit: int = 160) -> str:
    """A reason cut to about ``limit`` characters at a word boundary."""
    return text if len(text) <= limit else text[:limit].rsplit(" ", 1)[0] + " …"


def _category_text(row) -> str:
    """A row's category with what it is counted as: with its family's lead, as a study, a closed form."""
    text = row.status
    if not row.counted and not row.study_of:
        text += f" (counted with {row.family})"
    if row.study_of:
        text += f" (study of {row.study_of}, not counted)"
    return text + (" (closed form)" if row.basis == "closed form" else "")


def readings_count(row) -> str:
    """How a claim fares over all its readings: ``"holds 3, fails 20, undecided 1 of 24"``."""
    if not row.readings:
        return "—"
    return (f"holds {int(row.holds_at)}, fails {int(row.fails_at)}, undecided {int(row.undecided_at)} "
            f"of {int(row.readings)}")


def styled(evaluated: pd.DataFrame, *, links: bool = False, grid: str = ""):
    """A pandas ``Styler`` of the ledger for the book: one line per claim.

    Columns: claim, category (coloured; "counted with <lead>" for a row implied by another, "study of …"
    for a study), ours against the paper (at the held-out reading, with units), the one reason (the
    check's finding there), and its readings (holds, fails, undecided of all evaluated). Details
    (quote, verdict, evidence at every reading) are in :func:`details_markdown`; with ``links=True``
    each claim links to its details on the same page; ``grid`` (e.g. "quick: a partial grid") is
    added to the caption. The table carries the HTML class ``passmd-ledger`` (the rendered-book check
    looks for it) and wraps inside the content column.
    """
    rows = list(_rows_only(evaluated).itertuples())
    shown = pd.DataFrame({  # the cells are HTML: text is escaped ('<' of a relation), the links are not
        "claim": [f'<a href="#{claim_anchor(r.claim)}">{r.claim}</a>' if links else r.claim for r in rows],
        "category": [html.escape(_category_text(r), quote=False) for r in rows],
        "ours vs paper": [html.escape(_ours_vs_paper(r), quote=False) for r in rows],
        "why": [html.escape(_short(r.why), quote=False) for r in rows],
        "readings": [readings_count(r) for r in rows],
    })
    statuses = evaluated["status"].to_numpy()

    def colour(column):
        return [f"background-color: {STATUS_COLOURS[s]}" for s in statuses]

    styler = (
        shown.style.hide(axis="index")
        .apply(colour, subset=["category"])
        .set_table_attributes('class="passmd-ledger"')
        .set_table_styles([
            {"selector": "", "props": "table-layout: fixed; width: 100%; max-width: 100%;"},
            {"selector": "td, th", "props": "font-size: 0.8em; vertical-align: top; overflow-wrap: anywhere; "
                                            "word-break: break-word; white-space: normal;"},
        ])
    )
    return styler.set_caption(grid) if grid else styler


def _state_verb(state: str) -> str:
    """A state as a verb phrase: ``holds``, ``fails``, ``is undecided``."""
    return {"holds": "holds", "fails": "fails", "inconclusive": "is undecided"}.get(state, "is not evaluated")


def _details_block(row, claim, heading: str, members: tuple = ()) -> str:
    """One claim's (or study's) collapsed block: quote, verdict, flags, evidence, reason, configuration."""
    section, check = _section_text(claim), _check_text(claim)
    basis = " (closed form)" if row.basis == "closed form" else ""
    lines = [f"({claim_anchor(row.claim)})=",
             "```{admonition} " + f"{_md_escape(row.claim)}: {heading}{basis}",
             ":class: dropdown",
             ""]
    if claim["source_quote"]:
        lines += [f"*Paper* ({_md_escape(section)}): “{_md_escape(claim['source_quote'])}”", ""]
    else:
        lines += [f"*Study* (not a sentence of the paper, not counted) of {_md_escape(row.study_of)} "
                  f"({_md_escape(section)}).", ""]
    lines += [f"*Verdict (computed):* {_md_escape(row.verdict)}.", ""]
    if row.readings:
        lines += [f"*Judged at:* {_md_escape(row.held_out_reading)} (its held-out reading), where it "
                  f"{_state_verb(row.held_out_state)}; at the in-sample joint reading it "
                  f"{_state_verb(row.joint_state)}. *Readings:* {readings_count(row)}.", ""]
    if members:
        lines += [f"*Family:* counted once with the rows implied by it, as one claim that holds only if "
                  f"every member holds: {_md_escape(', '.join(members))}.", ""]
    elif row.family:
        lines += [f"*Implied by* {_md_escape(row.family)}: counted with it, once.", ""]
    if row.basis == "closed form":
        lines += ["*Basis:* a closed-form identity, not a simulation result.", ""]
    if row.fragile:
        lines += [f"*Fragile:* {_md_escape(row.fragile_reason)}.", ""]
    if not row.informative:
        lines += [f"*Not informative:* {_md_escape(row.not_informative)}.", ""]
    if row.evidence:
        lines += ["*Evidence (computed):*", ""]
        lines += [f"- {_md_escape(item)}" for item in row.evidence.split(" | ")]
        lines.append("")
    if row.depends_on:
        lines += [f"*Best reading:* {_md_escape(row.best_reading)}.", ""]
    if row.reason and row.status != "reproduced":
        lines += [f"*Reason (our reading of the evidence):* {_md_escape(row.reason)}", ""]
    lines += [f"*Configuration:* {_md_escape(_config_text(claim))}. "
              f"*Ours:* {_md_escape(claim['ours_definition'])}. "
              f"*Check:* {_md_escape(check)}. {_md_escape(claim['tolerance_reason'])}"]
    if claim["notes"]:
        lines += ["", f"*Notes:* {_md_escape(claim['notes'])}"]
    lines.append("```")
    return "\n".join(lines) + "\n"


def _rows_only(evaluated: pd.DataFrame) -> pd.DataFrame:
    """The table without its ``attrs``: pandas deep-copies ``attrs`` (every claim's points) into the
    result of each selection and row access, which costs seconds over a report's hundreds of them."""
    rows = evaluated.copy(deep=False)
    rows.attrs = {}
    return rows


def details_markdown(evaluated: pd.DataFrame, claims: pd.DataFrame) -> str:
    """Per claim, a collapsed block with an anchor: verdict, quote, evidence, reason and source.

    Claims are grouped by category, the studies after them (shown, not counted); each group starts
    with the target of :func:`category_anchor` (or :data:`STUDIES_ANCHOR`, so the intro's headline
    can link to it) and each row with the target of :func:`claim_anchor` (the ledger table links to
    it). The blocks are dropdown admonitions: closed until the reader opens them.
    """
    evaluated, by_id = _rows_only(evaluated), _rows_only(claims).set_index("id")
    blocks = []
    claims_of_paper, studies = counted(evaluated), evaluated[evaluated["study_of"] != ""]
    implied = evaluated[(evaluated["study_of"] == "") & ~evaluated["counted"].astype(bool)]
    for status in STATUSES:
        rows = claims_of_paper[claims_of_paper["status"] == status]
        blocks.append(f"({category_anchor(status)})=\n**{status.capitalize()}: {len(rows)}**\n")
        for row in rows.itertuples():
            mine = implied[implied["family"] == row.claim]
            blocks.append(_details_block(row, by_id.loc[row.claim], status, tuple(mine["claim"])))
            blocks.extend(_details_block(member, by_id.loc[member.claim],
                                         f"implied by {member.family}, {member.status}")
                          for member in mine.itertuples())
    if len(studies):
        blocks.append(f"({STUDIES_ANCHOR})=\n**Studies (not counted): {len(studies)}**\n")
        blocks.extend(_details_block(row, by_id.loc[row.claim], f"study, {row.status}")
                      for row in studies.itertuples())
    return "\n".join(blocks)


def families_markdown(evaluated: pd.DataFrame) -> str:
    """Every family of claims as MyST markdown: its lead, its category (the conjunction of its members,
    judged at its held-out reading) and each implied row with its own state there."""
    evaluated = _rows_only(evaluated)
    members = evaluated[(evaluated["study_of"] == "") & ~evaluated["counted"].astype(bool)]
    if members.empty:
        return "No row is implied by another: every claim is counted on its own.\n"
    by_id = evaluated.set_index("claim")
    lines = ["A row the paper's stronger statement implies is counted once with it: the family holds only if "
             "every member holds, and votes once in the joint reading.", ""]
    for lead, group in members.groupby("family", sort=False):
        implied = ", ".join(f"`{r.claim}` ({r.held_out_state})" for r in group.itertuples())
        lines.append(f"* `{lead}`: {by_id.at[lead, 'status']}; implies {implied}.")
    return "\n".join(lines) + "\n"


def assumption_map_styled(evaluated: pd.DataFrame):
    """:func:`passmd.report.evaluation.assumption_map` as a compact coloured table (✓ holds, ✗ fails, ?
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
