"""Helpers the book's chapters use: profile switch, CSV data links, captions, units.

* :func:`current_profile` reads the build profile (``quick`` or ``paper``) from the
  environment variable ``PASSMD_PROFILE`` that ``nox -s book -- --profile quick`` sets.
* :func:`data_link` writes a figure's data as CSV into the book's ``_generated/data/``
  folder and returns MyST markdown linking to it (Sphinx copies the file into the HTML).
* :func:`caption` builds a figure caption naming the parameters the figure was run with,
  the ``passmd`` version, git commit and profile (:mod:`passmd.runtime.provenance`), optionally
  with the data link. The CSV files carry the same three facts as ``#`` header lines.
* :func:`to_unit` and :func:`format_quantity` convert SI values to the units shown at the
  edges (nm, N, mN, mm, kHz, mm/s, ...) with the package's converter,
  :func:`passmd.runtime.units.from_si`.
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

from passmd.runtime import provenance
from passmd.runtime.units import from_si
from passmd.runtime.validation import check_choice

__all__ = [
    "DISPLAY_UNITS",
    "NUMBER_WORDS",
    "PROFILES",
    "PROFILE_ENV",
    "Markdown",
    "assumption_value",
    "assumptions_frame",
    "book_config",
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
    folder = book_root(root) / _DATA_SUBDIR
    folder.mkdir(parents=True, exist_ok=True)
    target = folder / f"{name}.csv"
    tmp = target.with_name(f".{target.name}.{os.getpid()}.tmp")
    with open(tmp, "w", encoding="utf-8", newline="") as fh:
        fh.write(provenance.csv_header(current_profile()))
        df.to_csv(fh, index=False, lineterminator="\n")
    os.replace(tmp, target)  # atomic: a reader never sees a half-written file
    text = label if label is not None else target.name
    return Markdown(f"{{download}}`{text} </{_DATA_SUBDIR.as_posix()}/{target.name}>`")


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
    folder = book_root(root) / _DATA_SUBDIR
    folder.mkdir(parents=True, exist_ok=True)
    target = folder / filename
    tmp = target.with_name(f".{target.name}.{os.getpid()}.tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, target)  # atomic: a reader never sees a half-written file
    shown = label if label is not None else filename
    return Markdown(f"{{download}}`{shown} </{_DATA_SUBDIR.as_posix()}/{filename}>`")


def to_unit(value_si, unit: str):
    """Convert an SI value (scalar or array) to ``unit`` (e.g. m → ``"nm"``, Hz → ``"kHz"``).

    The caller must pass a value in the SI unit of the same dimension (m, kg, s, N, Hz, m/s,
    N/m, ...); only the scale is converted (:func:`passmd.runtime.units.from_si`). Returns a
    float for a scalar, an array otherwise.
    """
    result = from_si(np.asarray(value_si, dtype=float), unit)
    return float(result) if result.ndim == 0 else result


def format_quantity(value_si, unit: str, digits: int = 3) -> str:
    """``value_si`` in ``unit`` with ``digits`` significant digits, e.g. ``"202 nm"``."""
    value = to_unit(value_si, unit)
    if np.ndim(value) != 0:
        raise ValueError(f"value_si = {value_si!r} is not allowed: must be a scalar")
    return f"{value:.{int(digits)}g} {unit}"


def grid_text(values_si, unit: str, limit: int = 8) -> str:
    """A profile's grid as a caption names it, in ``unit``: every value when there are at most
    ``limit`` (``"1, 20, 60, 100 kHz"``), else the first three, the last and how many
    (``"1, 5, 10, …, 130 kHz (27 values)"``)."""
    shown = [f"{v:g}" for v in np.atleast_1d(to_unit(np.asarray(values_si, dtype=float), unit))]
    if not shown:
        raise ValueError("values_si is empty: a grid has at least one value")
    if len(shown) <= limit:
        return f"{', '.join(shown)} {unit}"
    return f"{', '.join(shown[:3])}, …, {shown[-1]} {unit} ({len(shown)} values)"


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


def drive_parameters(drive) -> dict[str, str]:
    """The parameters a drive simulation is run with, formatted for captions.

    Keys are the paper's symbols; values carry display units (mm, N, g, N/m).
    """
    actuator = drive.actuator
    params = {
        "R": format_quantity(drive.hemisphere_radius, "mm"),
        "F_p": format_quantity(drive.preload, "N"),
        "μ": f"{drive.friction_coefficient:g}",
        "contacts": f"{drive.contacts}",
        "actuators": drive.actuator_model,
        "m_r": format_quantity(drive.runner_mass, "g"),
        "runner": drive.runner_material.name or "custom",
    }
    if drive.actuator_model == "flexible":
        params["k_p"] = f"{actuator.stiffness:.3g} N/m"
        params["m_a"] = format_quantity(actuator.mass, "g")
        params["ζ_p"] = f"{actuator.damping_ratio:.3g}"
    if drive.load_cell:
        params["k"] = f"{drive.load_cell_stiffness:.3g} N/m"
    return params


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


#: Display units of parameter-table rows whose SI value reads badly (by dotted field name).
DISPLAY_UNITS = {
    "hemisphere_radius": "mm",
    "runner_mass": "g",
    "hemisphere_material.youngs_modulus": "GPa",
    "runner_material.youngs_modulus": "GPa",
    "youngs_modulus": "GPa",
    "actuator.mass": "g",
    "mass": "g",
    "actuator.full_stroke_amplitude": "nm",
    "full_stroke_amplitude": "nm",
    "amplifier.slew_rate": "V/µs",
    "slew_rate": "V/µs",
}


def parameter_frame(*records, labels=None, units=None):
    """A parameter record (or several side by side) as a table in display units.

    Parameters
    ----------
    *records
        Parameter dataclasses (e.g. two :class:`passmd.model.parameters.Drive`), read with
        :func:`passmd.model.tables.parameter_table`.
    labels : list of str, optional
        Column titles of the records' values; default ``value`` (one record) or
        ``value 1``, ``value 2``, ...
    units : dict, optional
        Dotted field name → display unit; default :data:`DISPLAY_UNITS`.

    Returns
    -------
    pandas.DataFrame
        Columns ``parameter``, ``symbol``, the value column(s), ``unit``, ``source``.
    """
    import pandas as pd

    from passmd.model.tables import parameter_table

    if not records:
        raise ValueError("records is empty: give at least one parameter record")
    units = DISPLAY_UNITS if units is None else units
    if labels is None:
        labels = ["value"] if len(records) == 1 else [f"value {i + 1}" for i in range(len(records))]
    if len(labels) != len(records):
        raise ValueError(f"labels = {labels!r} is not allowed: must have one label per record")
    tables = [parameter_table(record) for record in records]
    names = [row["name"] for row in tables[0]]
    if any([row["name"] for row in table] != names for table in tables[1:]):
        raise ValueError("records are not allowed: they must be of the same type")
    rows = []
    for i, name in enumerate(names):
        first = tables[0][i]
        unit = units.get(name, first["unit"])
        row = {"parameter": name, "symbol": first["symbol"]}
        for label, table in zip(labels, tables, strict=True):
            value = table[i]["value"]
            if isinstance(value, (int, float, np.floating)) and not isinstance(value, bool):
                value = f"{to_unit(value, unit) if unit != first['unit'] else value:.4g}"
            row[label] = value
        row["unit"] = unit
        row["source"] = first["source"]
        rows.append(row)
    return pd.DataFrame(rows)


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
