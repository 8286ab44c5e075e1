"""Helpers the book's chapters use: profile switch, CSV data links, captions, units.

* :func:`current_profile` reads the build profile (``quick`` or ``paper``) from the
  environment variable ``PASSMD_PROFILE`` that ``nox -s book -- --profile quick`` sets;
  :func:`book_evaluation` reads the build's one evaluation of the ledger (``PASSMD_BOOK_LEDGER``).
* :func:`data_link` writes a figure's data as CSV into the book's ``_generated/data/``
  folder and returns MyST markdown linking to it (Sphinx copies the file into the HTML).
* :func:`caption` builds a figure caption naming the parameters the figure was run with,
  the ``passmd`` version, git commit and profile (:mod:`passmd.runtime.provenance`), optionally
  with the data link. The CSV files carry the same three facts as ``#`` header lines.
* :func:`to_unit` and :func:`format_quantity` convert SI values to the units shown at the
  edges (nm, N, mN, mm, kHz, mm/s, ...) with the package's converter,
  :func:`passmd.runtime.units.from_si` (they, :func:`grid_text`, :func:`drive_parameters` and
  :func:`parameter_frame` live in :mod:`passmd.report.quantities`).
* :func:`parameter_frame`, :func:`assumptions_frame` and :func:`implementations` turn the
  package's own records (parameter sets, the assumptions registry, the functions that
  implement each equation) into tables, so the book never retypes them.

Markdown is returned as :class:`Markdown`, a ``str`` that Jupyter displays as markdown
(myst-nb parses it as MyST because the book sets ``nb_render_markdown_format: myst``).
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import os
import re
from pathlib import Path

import numpy as np

from passmd.report.quantities import DISPLAY_UNITS as DISPLAY_UNITS
from passmd.report.quantities import drive_parameters as drive_parameters
from passmd.report.quantities import format_quantity as format_quantity
from passmd.report.quantities import grid_text as grid_text
from passmd.report.quantities import parameter_frame as parameter_frame
from passmd.report.quantities import to_unit as to_unit
from passmd.runtime import provenance
from passmd.runtime.validation import check_choice

__all__ = [
    "DISPLAY_UNITS",
    "LEDGER_ENV",
    "NUMBER_WORDS",
    "PROFILES",
    "PROFILE_ENV",
    "Markdown",
    "assumption_value",
    "assumptions_frame",
    "book_config",
    "book_evaluation",
    "book_root",
    "caption",
    "current_profile",
    "data_link",
    "drive_parameters",
    "figure_png",
    "format_quantity",
    "grid_text",
    "implementations",
    "parameter_frame",
    "partial_grid_text",
    "put",
    "put_text",
    "show_figure",
    "show_table",
    "text_link",
    "to_unit",
]

#: Build profiles: ``quick`` (coarse grids, for CI) and ``paper`` (the paper's grids).
PROFILES = ("quick", "paper")
#: Environment variable holding the profile; unset means ``paper``.
PROFILE_ENV = "PASSMD_PROFILE"
#: Small counts as the prose spells them (``NUMBER_WORDS[3]`` is "three"), so a chapter glues a
#: count it reads from a record without changing its wording.
NUMBER_WORDS = ("zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten")

_DATA_SUBDIR = Path("_generated") / "data"
_NAME_PATTERN = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")


class Markdown(str):
    """Markdown text that Jupyter renders as markdown (and prints as plain text)."""

    def _repr_markdown_(self) -> str:
        return str(self)


def current_profile(default: str = "paper") -> str:
    """The build profile, from ``$PASSMD_PROFILE`` (``quick`` or ``paper``).

    Parameters
    ----------
    default : str
        Profile used when the variable is unset or empty.

    Raises
    ------
    ValueError
        If the variable (or ``default``) is not one of :data:`PROFILES`.
    """
    value = os.environ.get(PROFILE_ENV, "").strip() or default
    return check_choice(PROFILE_ENV, value, PROFILES)


def book_root(start: str | os.PathLike | None = None) -> Path:
    """The book's source folder: the nearest folder at or above ``start`` holding ``_config.yml``
    and ``_toc.yml``. Falls back to ``start`` itself (default: the working directory).

    During a book build cells run in the page's folder, so this finds ``book/``.
    """
    here = Path(start if start is not None else Path.cwd()).resolve()
    for folder in (here, *here.parents):
        if (folder / "_config.yml").is_file() and (folder / "_toc.yml").is_file():
            return folder
    return here


def data_link(df, name: str, *, label: str | None = None, root=None) -> Markdown:
    """Write ``df`` as ``<book>/_generated/data/<name>.csv`` and return a MyST download link.

    The file starts with ``#`` lines naming the ``passmd`` version, git commit and profile
    (:func:`passmd.runtime.provenance.csv_header`); read it with ``pandas.read_csv(path, comment="#")``.

    Parameters
    ----------
    df : pandas.DataFrame
        The figure's data, in the units the figure shows (say so in the column names,
        e.g. ``amplitude_nm``). Written without the index.
    name : str
        File stem: letters, digits, ``_``, ``-``, ``.``; e.g. ``"fig5a"``.
    label : str, optional
        Link text; default ``"<name>.csv"``.
    root : path-like, optional
        Book source folder; default :func:`book_root` of the working directory.

    Returns
    -------
    Markdown
        ``{download}`label </_generated/data/name.csv>``` — Sphinx copies the file into
        the HTML output and links it; the build warns (fails with ``-W``) if it is missing.
    """
    if not isinstance(name, str) or not _NAME_PATTERN.match(name) or name.endswith(".csv"):
        raise ValueError(
            f"name = {name!r} is not allowed: must be a file stem of letters, digits, '_', '-', '.' "
            "(without '.csv')"
        )
    if not hasattr(df, "to_csv"):
        raise ValueError(f"df = {type(df).__name__} is not allowed: must be a pandas DataFrame")

    def write(path: Path) -> None:
        with open(path, "w", encoding="utf-8", newline="") as fh:
            fh.write(provenance.csv_header(current_profile()))
            df.to_csv(fh, index=False, lineterminator="\n")

    return _generated_link(f"{name}.csv", write, label, root)


def text_link(text: str, filename: str, *, label: str | None = None, root=None) -> Markdown:
    """Write ``text`` as ``<book>/_generated/data/<filename>`` and return a MyST download link.

    For files a reader feeds back to ``passmd`` as they are (a drive file, a measurement CSV),
    so no provenance lines are added. ``filename``: letters, digits, ``_``, ``-``, ``.``.
    """
    if not isinstance(filename, str) or not _NAME_PATTERN.match(filename):
        raise ValueError(f"filename = {filename!r} is not allowed: must be a file name of letters, digits, "
                         "'_', '-', '.'")
    if not isinstance(text, str):
        raise ValueError(f"text = {type(text).__name__} is not allowed: must be a str")
    return _generated_link(filename, lambda path: path.write_text(text, encoding="utf-8"), label, root)


def _generated_link(filename: str, write, label: str | None, root) -> Markdown:
    """Write ``<book>/_generated/data/<filename>`` by ``write(path)`` and return its MyST download link
    (``label``, default the file name)."""
    folder = book_root(root) / _DATA_SUBDIR
    folder.mkdir(parents=True, exist_ok=True)
    target = folder / filename
    tmp = target.with_name(f".{target.name}.{os.getpid()}.tmp")
    write(tmp)
    os.replace(tmp, target)  # atomic: a reader never sees a half-written file
    shown = label if label is not None else filename
    return Markdown(f"{{download}}`{shown} </{_DATA_SUBDIR.as_posix()}/{filename}>`")


def partial_grid_text(names, profile: str) -> tuple[str, str, list[str]] | None:
    """What a page built on ``profile`` lacks of the paper profile's grids for the figures ``names``
    (:func:`passmd.experiments.figure_table.grid_shortfall`): a title with the points missing, one
    sentence with the points computed and one item per figure that lacks points (``"fig5a: 18 of the
    paper profile's 203 points (amplitudes), 185 missing"``); None on the paper profile."""
    from passmd.experiments.figure_table import grid_shortfall

    check_choice("profile", profile, PROFILES)
    if profile == "paper":
        return None
    short = grid_shortfall(names, profile)
    short = short[short["missing"] > 0]
    if short.empty:
        return (f"{profile.capitalize()} profile",
                f"Built on the {profile} profile. None of the grids of points this page's figures and "
                "verdicts read is coarser than the paper profile's (a profile may still record or integrate "
                "the same runs more coarsely).", [])
    items = [f"{row.figure}: {row.points} of the paper profile's {row.reference_points} points "
             f"({row.axes}), {row.missing} missing" for row in short.itertuples()]
    total, computed, missing = (int(short[c].sum()) for c in ("reference_points", "points", "missing"))
    return (f"Partial grid: {missing} of the paper profile's {total} grid points missing",
            f"Built on the {profile} profile: the figures behind this page's verdicts compute {computed} of "
            f"the paper profile's {total} grid points, so a verdict may differ on the paper's grids "
            "(python3 -m nox -s book builds them). By figure:", items)


def caption(text: str, *, drive=None, data=None, name: str | None = None, **extra) -> Markdown:
    """A figure caption naming the parameters it was run with, with a link to its CSV data.

    Parameters
    ----------
    text : str
        What the figure shows (markdown), e.g. ``"Step size against amplitude (Fig. 5a)."``
    drive : passmd.model.parameters.Drive, optional
        Its parameters are listed via :func:`drive_parameters`.
    data : pandas.DataFrame, optional
        Written with :func:`data_link` under ``name`` (required together with ``data``).
    **extra
        Further run parameters, shown as ``key = value`` (format values yourself,
        e.g. ``frequency="100 Hz"``).

    Returns
    -------
    Markdown
        ``**Figure.** text Run with: R = 1 mm, .... Made by passmd 0.1.0, commit <hash>,
        profile paper. Data: <link>``
    """
    if (data is None) != (name is None):
        raise ValueError("data and name must be given together (name is the CSV file stem)")
    params = drive_parameters(drive) if drive is not None else {}
    params.update({key: str(value) for key, value in extra.items()})
    parts = [f"**Figure.** {text.strip()}"]
    listed = [f"{key} = {value}" for key, value in params.items()]
    if listed:
        parts.append("Run with: " + ", ".join(listed) + ".")
    parts.append(f"Made by {provenance.summary(current_profile())}.")
    if data is not None:
        parts.append(f"Data: {data_link(data, name)}.")
    return Markdown(" ".join(parts))


def assumptions_frame():
    """Every assumption of :func:`passmd.report.assumptions.all_assumptions` as a table, in its order."""
    import pandas as pd

    from passmd.report.assumptions import all_assumptions

    return pd.DataFrame([dataclasses.asdict(a) for a in all_assumptions().values()])


#: Characters MyST would read as markup in plain text.
_MARKUP = "\\`*_[]$<>|#"


def escape_markdown(text: str) -> str:
    """``text`` with every character MyST reads as markup escaped by a backslash."""
    for char in _MARKUP:
        text = text.replace(char, "\\" + char)
    return text


def assumption_list(frame=None) -> Markdown:
    """The assumptions (:func:`assumptions_frame`, or ``frame``) as a markdown list.

    One item per assumption: key, its value (:func:`assumption_value`), rationale and where its
    effect is shown; text escaped.
    """
    frame = assumptions_frame() if frame is None else frame
    e = escape_markdown
    return Markdown("\n".join(
        f"- **{e(row.key)}** ({e(assumption_value(row.symbol, row.value, row.unit))}). {e(row.rationale)} "
        f"*Where its effect is shown:* {e(row.sensitivity)}"
        for row in frame.itertuples()
    ))


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def assumption_value(symbol: str, value: str, unit: str) -> str:
    """An assumption's value as one phrase: ``δ = 0.5 nm`` for a number, ``c_p [kg/s] = 2·ζ·√(k_p m_a) …``
    for a description (the unit belongs to the symbol, not to the description's last word); symbol and
    unit left out when empty or a dash."""
    has_symbol, has_unit = symbol not in ("", "–", "-"), unit not in ("", "–", "-")
    if _is_number(value):
        return (f"{symbol} = " if has_symbol else "") + value + (f" {unit}" if has_unit else "")
    unit_part = f"[{unit}]" if has_unit else ""
    named = f"{symbol} {unit_part}".strip() if has_symbol else unit_part
    return f"{named} = {value}" if named else value


def implementations(mapping: dict[str, str | list[str]]):
    """Table of the code implementing each equation, checked against the package.

    Parameters
    ----------
    mapping : dict
        Equation label (e.g. ``"Eq. (1)"``) → dotted name(s) of the implementing function,
        class or method (e.g. ``"passmd.model.theory.normal_forces"``). Every name is imported,
        so a renamed function fails the book build instead of leaving a stale reference.

    Returns
    -------
    pandas.DataFrame
        Columns ``equation``, ``implemented by`` (the dotted name) and ``summary`` (first
        paragraph of its docstring).
    """
    import pandas as pd

    rows = []
    for equation, names in mapping.items():
        for dotted in [names] if isinstance(names, str) else names:
            doc = inspect.getdoc(_resolve(dotted)) or ""
            rows.append(
                {
                    "equation": equation,
                    "implemented by": dotted,
                    "summary": doc.split("\n\n")[0].replace("\n", " "),
                }
            )
    return pd.DataFrame(rows)


def _resolve(dotted: str):
    """The object a dotted name such as ``passmd.model.theory.normal_forces`` refers to."""
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ModuleNotFoundError:
            continue
        for attr in parts[cut:]:
            if not hasattr(obj, attr):
                raise ValueError(f"name = {dotted!r} is not defined: {attr!r} not found")
            obj = getattr(obj, attr)
        return obj
    raise ValueError(f"name = {dotted!r} is not defined: no such module")


# --------------------------------------------------------------------------------------
# Glue for the chapters (one definition instead of one per chapter)
# --------------------------------------------------------------------------------------


def book_config():
    """The book's run configuration: the environment read once, at the book's edge.

    ``nox -s book -- --profile quick`` sets ``PASSMD_PROFILE``; the cache directory,
    executor and workers come from their variables too (:data:`passmd.runtime.config.ENVIRONMENT`).
    """
    from passmd.runtime.config import RunConfig

    return RunConfig.from_environment()


#: Set by ``nox -s book``: the file holding the build's one evaluation of the whole ledger.
LEDGER_ENV = "PASSMD_BOOK_LEDGER"


def book_evaluation(config):
    """The whole ledger evaluated on ``config``'s results (:func:`passmd.report.evaluation.evaluate`).

    Read from the file ``nox -s book`` wrote once for the build (``$PASSMD_BOOK_LEDGER``,
    :mod:`passmd.report.stored_evaluation`) when it holds the evaluation of this profile by this
    package's code and data; evaluated here otherwise.
    """
    from passmd.report import evaluation, stored_evaluation

    path = os.environ.get(LEDGER_ENV, "").strip()
    stored = stored_evaluation.read(path, config.profile) if path else None
    return stored if stored is not None else evaluation.evaluate(config=config)


def put(name: str, value) -> None:
    """Glue a number for the text as a plain Python number (so format specs apply)."""
    from myst_nb import glue

    glue(name, np.asarray(value).item(), display=False)


def put_text(name: str, text: str) -> None:
    """Glue a short markdown text for the ``{glue:md}`` role."""
    from myst_nb import glue

    glue(name, Markdown(text), display=False)


def put_all(facts: dict) -> None:
    """Glue every entry of ``facts``: text with :func:`put_text`, numbers with :func:`put`."""
    for name, value in facts.items():
        if isinstance(value, str):
            put_text(name, value)
        else:
            put(name, value)


def figure_png(fig) -> bytes:
    """A matplotlib ``Figure`` as PNG bytes, with the tight bounding box the inline backend uses."""
    import io

    from matplotlib.figure import Figure

    if not isinstance(fig, Figure):
        raise ValueError(f"fig = {type(fig).__name__} is not allowed: must be a matplotlib Figure")
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", bbox_inches="tight")
    return buffer.getvalue()


def show_figure(fig) -> None:
    """Display a matplotlib ``Figure`` made outside pyplot (e.g. ``passmd.plots.sweep_map.map_figure``)
    as a PNG image (:func:`figure_png`), as the notebook's inline backend shows a pyplot figure."""
    from IPython.display import Image, display

    display(Image(data=figure_png(fig), format="png"))


def show_table(df, formats: dict | None = None) -> None:
    """Display a table without its index; numbers with 4 significant digits unless ``formats`` says."""
    from IPython.display import display

    style = df.style.hide(axis="index").format("{:.4g}", subset=list(df.select_dtypes("number").columns))
    for column, spec in (formats or {}).items():
        style = style.format(spec, subset=[column])
    display(style)
