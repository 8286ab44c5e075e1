"""Sphinx extension of the passmd book: provenance footer, run time and expectations per page.

* The footer (``html_theme_options["extra_footer"]``) gets the ``passmd`` version, git
  commit and profile of the build (:func:`passmd.runtime.provenance.summary`), the same line every
  figure caption carries.
* Before each page is read (and its notebook executed), ``$PASSMD_SWEEP_LOG`` is pointed at
  a file of that page in the build folder; :func:`passmd.runtime.sweep.run` appends every sweep's
  cached/computed counts to it from inside the chapter's kernel.
* The ``passmd-sweep-table`` directive is replaced, once every page has been read, by a
  table of those counts per page (so its own position in the reading order does not matter),
  after a first row for the ``passmd ledger`` run with which ``nox -s book`` computes every
  table a claim reads before the chapters (``$PASSMD_BOOK_PREFETCH_LOG``).
  The logs are cleared when a build starts: the counts are complete because ``nox -s book``
  builds with ``--all`` (every page read and executed).
* Each chapter page (one with figures in :data:`passmd.experiments.figure_table.FIGURES` or
  one that ran a sweep; not the root page) ends with a generated "Run time" section: the
  profile, myst-nb's execution time of the page and its sweep counts, the facts the execution
  statistics page tabulates for every page.
* Every page gets a ``passmd-expect`` meta tag for ``tools/check_rendered_book.py``
  (:func:`expectation`): the figures the figure table registers for the page, whether the
  ledger judges claims of them and whether it carries the partial-grid note.
* On a build coarser than the paper profile (``quick``), every page that states verdicts (the root
  page's headline, the replication report, each chapter with ledger rows) opens with a "Partial grid"
  note: how many of the paper profile's grid points the figures behind its verdicts lack, and for
  each figure how many it computes and lacks (:func:`passmd.report.publish.partial_grid_text`); a
  list of more than four figures is folded under the note's title.
* Docstrings write absolute values as ``|x|`` (plain text, as ``help()`` shows them); for
  the API page the bars are escaped outside inline literals and roles, where
  reStructuredText would read ``|x|`` as a substitution.
"""

from __future__ import annotations

import functools
import json
import os
import re
from pathlib import Path

from docutils import nodes
from sphinx.util.docutils import SphinxDirective

SWEEP_LOG_ENV = "PASSMD_SWEEP_LOG"
#: Set by ``nox -s book``: the sweep log of the ``passmd ledger`` run that computes every
#: table a claim reads before the chapters are executed (its counts are the table's first row), and a
#: JSON file with that run's wall time (``{"wall_seconds": ...}``).
PREFETCH_LOG_ENV = "PASSMD_BOOK_PREFETCH_LOG"
PREFETCH_TIME_ENV = "PASSMD_BOOK_PREFETCH_TIME"
#: The page that shows the whole ledger (every claim), where the ledger's links point.
LEDGER_PAGE = "replication_report"
#: The execution statistics page, which each chapter's Run time section links to.
STATISTICS_PAGE = "execution_statistics"
#: Extensions that work on merged build state only but do not declare it: Sphinx would read
#: (execute) the chapters one at a time because of them (``tools/build_book.py --jobs``).
UNDECLARED_PARALLEL_SAFE = (
    "sphinx-mathjax-offline",  # sets mathjax_path; copies its assets once the build finished
    "sphinx_multitoc_numbering",  # numbers sections from the merged environment, after reading
    "sphinx_jupyterbook_latex",  # transforms of the page being read (LaTeX structure) only
)


def _log_dir(app) -> Path:
    return Path(app.outdir).parent / "passmd-sweeps"


def _log_of(app, docname: str) -> Path:
    return _log_dir(app) / (docname.replace("/", "__") + ".jsonl")


@functools.cache
def chapter_figures(docname: str) -> tuple[str, ...]:
    """The figures the figure table registers for a page (its ``chapter``)."""
    from passmd.experiments.figure_table import FIGURES

    return tuple(spec.name for spec in FIGURES if spec.chapter == docname)


def _judges_claims(docname: str) -> bool:
    """Whether the page shows a ledger table: :data:`LEDGER_PAGE`, or claims need only its figures."""
    from passmd.report.evaluation import claims_for, load_claims

    figures = chapter_figures(docname)
    return docname == LEDGER_PAGE or bool(figures) and not claims_for(load_claims(), figures).empty


@functools.cache
def verdict_figures(docname: str, root_doc: str) -> tuple[str, ...] | None:
    """The figures behind the verdicts a page states, or None for a page that states none: every
    claim's on the root page (its headline) and :data:`LEDGER_PAGE`, the page's own claims' elsewhere
    (their ``requires``, reading tables resolved to their figures)."""
    from passmd.experiments.figure_table import figures_read
    from passmd.ledger.claims import required_keys
    from passmd.report.evaluation import claims_for, load_claims

    if docname in (root_doc, LEDGER_PAGE):
        claims = load_claims()
    elif _judges_claims(docname):
        claims = claims_for(load_claims(), chapter_figures(docname))
    else:
        return None
    return tuple(figures_read({key for _, claim in claims.iterrows() for key in required_keys(claim)}))


@functools.cache
def partial_grid_note(docname: str, root_doc: str) -> tuple[str, str, list[str]] | None:
    """The note (title, text, one item per figure) a verdict-bearing page gets on a profile coarser
    than the paper's (:func:`passmd.report.publish.partial_grid_text`), None elsewhere."""
    from passmd.report.publish import current_profile, partial_grid_text

    figures = verdict_figures(docname, root_doc)
    return None if figures is None else partial_grid_text(figures, current_profile())


@functools.cache
def expectation(docname: str, root_doc: str = "intro") -> str:
    """The ``passmd-expect`` value of a page, e.g. ``"figures=3 ledger=1 partial=0"``.

    ``figures``: the page's rows of the figure table (:func:`chapter_figures`); ``ledger``: 1 on
    :data:`LEDGER_PAGE` and where the ledger judges claims that need only those figures'
    results (:func:`passmd.report.evaluation.claims_for`), else 0; ``partial``: 1 where the page
    carries the partial-grid note (:func:`partial_grid_note`).
    """
    partial = partial_grid_note(docname, root_doc) is not None
    return (f"figures={len(chapter_figures(docname))} ledger={int(_judges_claims(docname))} "
            f"partial={int(partial)}")


def _expect_every_page(app, env) -> None:
    """Compute every page's expectation once, before the writers (forked when parallel) need it."""
    for docname in env.found_docs:
        expectation(docname, app.config.root_doc)


def _add_expectation(app, pagename: str, templatename, context: dict, doctree) -> None:
    if doctree is not None:
        context["metatags"] = context.get("metatags", "") + (
            f'<meta name="passmd-expect" content="{expectation(pagename, app.config.root_doc)}" />\n')


def _add_partial_grid(app, doctree) -> None:
    """On a build coarser than the paper profile, open every verdict-bearing page with the note of what
    it lacks of the paper's grids (:func:`partial_grid_note`)."""
    found = partial_grid_note(app.env.docname, app.config.root_doc)
    page = doctree.next_node(nodes.section)
    if found is None or page is None:
        return
    heading, text, items = found
    # a long list folds under its title (which says how much is missing), so the page's own first
    # screen stays the page's
    folded = ["dropdown"] if len(items) > 4 else []
    note = nodes.admonition(classes=["warning", "passmd-partial-grid", *folded])
    note += nodes.title(text=heading)
    note += nodes.paragraph(text=text)
    if items:
        listed = nodes.bullet_list()
        for item in items:
            listed += nodes.list_item("", nodes.paragraph(text=item))
        note += listed
    title = page.next_node(nodes.title)
    page.insert(page.index(title) + 1 if title is not None and title.parent is page else 0, note)


def _add_footer(app, config) -> None:
    from passmd.report.publish import current_profile
    from passmd.runtime import provenance

    options = dict(config.html_theme_options or {})
    footer = options.get("extra_footer", "")
    stamp = provenance.summary(current_profile())
    options["extra_footer"] = f"{footer}<br/>Made by {stamp}." if footer else f"Made by {stamp}."
    config.html_theme_options = options


def _clear_logs(app) -> None:
    folder = _log_dir(app)
    folder.mkdir(parents=True, exist_ok=True)
    for old in folder.glob("*.jsonl"):
        old.unlink()


def _point_log_at_page(app, docname: str, source: list[str]) -> None:
    os.environ[SWEEP_LOG_ENV] = str(_log_of(app, docname))


class sweep_table_placeholder(nodes.General, nodes.Element):
    """Replaced by the sweep-statistics table at ``doctree-resolved``."""


class SweepTable(SphinxDirective):
    """``passmd-sweep-table``: per page, the sweeps run and the points cached or computed."""

    def run(self):
        return [sweep_table_placeholder()]


def _table(rows: list[list[str]], header: list[str]) -> nodes.table:
    table = nodes.table(classes=["passmd-sweep-table"])
    group = nodes.tgroup(cols=len(header))
    table += group
    group.extend(nodes.colspec(colwidth=1) for _ in header)
    head, body = nodes.thead(), nodes.tbody()
    for cells, parent in [(header, head)] + [(row, body) for row in rows]:
        line = nodes.row()
        for cell in cells:
            entry = nodes.entry()
            entry += nodes.paragraph(text=cell)
            line += entry
        parent += line
    group += head
    group += body
    return table


def _counts(path: Path) -> list[int]:
    """Sweeps, points from the cache and points computed in one sweep log."""
    records = [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines() if line]
    return [len(records), sum(r["cached"] for r in records), sum(r["computed"] for r in records)]


def _prefetch_label() -> str:
    label = "before the chapters: passmd ledger (nox -s book)"
    timing = os.environ.get(PREFETCH_TIME_ENV)
    if timing and Path(timing).is_file():
        seconds = json.loads(Path(timing).read_text(encoding="utf-8"))["wall_seconds"]
        label += f", {seconds:.0f} s wall time"
    return label


def _fill_tables(app, doctree, docname: str) -> None:
    placeholders = list(doctree.findall(sweep_table_placeholder))
    if not placeholders:
        return
    logs = []
    prefetch = os.environ.get(PREFETCH_LOG_ENV)
    if prefetch and Path(prefetch).is_file():
        logs.append((_prefetch_label(), Path(prefetch)))
    for docname_of_page in sorted(app.env.found_docs):
        path = _log_of(app, docname_of_page)
        if path.is_file():
            title = app.env.titles.get(docname_of_page)
            logs.append((title.astext() if title is not None else docname_of_page, path))
    rows, totals = [], [0, 0, 0]
    for label, path in logs:
        counts = _counts(path)
        totals = [a + b for a, b in zip(totals, counts, strict=True)]
        rows.append([label, *map(str, counts)])
    rows.append(["all", *map(str, totals)])
    header = ["run", "sweeps", "points from the cache", "points computed"]
    for placeholder in placeholders:
        placeholder.replace_self(_table(rows, header))


def run_time_text(seconds: float, counts: list[int]) -> str:
    """What a chapter's Run time section says after its profile: execution time and sweeps."""
    sweeps, cached, computed = counts
    text = f"executing this chapter took {seconds:.1f} s of wall time in this build (kernel start included). "
    if not sweeps:
        return text + "It ran no simulation sweep."
    return text + (f"Its {sweeps} simulation sweep(s) needed {cached + computed} points: {computed} "
                   f"computed, {cached} taken from the simulation cache (filled by passmd ledger earlier in "
                   "this build, or by an earlier build); a build from a cold cache computes every point.")


def _add_run_time(app, doctree) -> None:
    """Append the "Run time" section to an executed chapter page (figures or sweeps; not the root)."""
    from myst_nb.sphinx_ import NbMetadataCollector
    from sphinx.addnodes import pending_xref

    from passmd.report.publish import current_profile

    docname = app.env.docname
    executed = NbMetadataCollector.get_exec_data(app.env, docname)
    log = _log_of(app, docname)
    counts = _counts(log) if log.is_file() else [0, 0, 0]
    page = doctree.next_node(nodes.section)
    if (not executed or executed.get("runtime") is None or docname == app.config.root_doc or page is None
            or not (chapter_figures(docname) or counts[0])):
        return
    text = nodes.paragraph()
    text += [nodes.Text("Profile "), nodes.literal(text=current_profile()),
             nodes.Text(": " + run_time_text(executed["runtime"], counts))]
    if STATISTICS_PAGE in app.env.found_docs:
        link = pending_xref(refdomain="std", reftype="doc", reftarget=f"/{STATISTICS_PAGE}",
                            refexplicit=False, refdoc=docname, refwarn=True)
        link += nodes.inline(text=STATISTICS_PAGE)
        text += [nodes.Text(" The page "), link,
                 nodes.Text(" tabulates every chapter's run time and what a build from a cold cache costs.")]
    section = nodes.section(names=["run time"])
    section += nodes.title(text="Run time")
    section += text
    page += section
    doctree.note_implicit_target(section, section)


_BACKTICK_SPAN = re.compile(r"(`[^`]*`)")


def _escape_bars(app, what, name, obj, options, lines: list[str]) -> None:
    for i, line in enumerate(lines):
        if "|" not in line:
            continue
        parts = _BACKTICK_SPAN.split(line)  # odd items: `...` spans (literals, roles, math)
        lines[i] = "".join(part if k % 2 else part.replace("|", "\\|") for k, part in enumerate(parts))


def setup(app):
    app.connect("autodoc-process-docstring", _escape_bars)
    app.connect("config-inited", _add_footer)
    app.connect("builder-inited", _clear_logs)
    app.connect("source-read", _point_log_at_page)
    app.connect("doctree-resolved", _fill_tables)
    app.connect("doctree-read", _add_run_time, priority=400)  # before the page's table of contents
    app.connect("doctree-read", _add_partial_grid, priority=400)
    app.connect("env-updated", _expect_every_page)
    app.connect("html-page-context", _add_expectation)
    app.add_node(sweep_table_placeholder)
    app.add_directive("passmd-sweep-table", SweepTable)
    for name in UNDECLARED_PARALLEL_SAFE:
        app.setup_extension(name)
        app.extensions[name].parallel_read_safe = True
        app.extensions[name].parallel_write_safe = True
    # Parallel reading is safe here: each page's sweep log is chosen in the process that
    # reads (executes) the page, and the tables are filled after every page was read.
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
