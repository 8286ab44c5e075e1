"""Helpers the book's chapters use: profile switch, CSV data links, captions, units.

* :func:`current_profile` reads the build profile (``quick`` or ``paper``) from the
  environment variable ``PASSMD_PROFILE`` that ``nox -s book -- --profile quick`` sets.
* :func:`data_link` writes a figure's data as CSV into the book's ``_generated/data/``
  folder and returns MyST markdown linking to it (Sphinx copies the file into the HTML).
* :func:`caption` builds a figure caption naming the parameters the figure was run with,
  optionally with the data link.
* :func:`to_unit` and :func:`format_quantity` convert SI values to the units shown at the
  edges (nm, N, mN, mm, kHz, mm/s, ...); conversions are done by ``pint``.

Markdown is returned as :class:`Markdown`, a ``str`` that Jupyter displays as markdown
(myst-nb parses it as MyST because the book sets ``nb_render_markdown_format: myst``).
"""

from __future__ import annotations

import os
import re
from functools import lru_cache
from pathlib import Path

import numpy as np

from passmd._validation import check_choice

__all__ = [
    "PROFILES",
    "PROFILE_ENV",
    "Markdown",
    "book_root",
    "caption",
    "current_profile",
    "data_link",
    "drive_parameters",
    "format_quantity",
    "to_unit",
]

#: Build profiles: ``quick`` (coarse grids, for CI) and ``paper`` (the paper's grids).
PROFILES = ("quick", "paper")
#: Environment variable holding the profile; unset means ``paper``.
PROFILE_ENV = "PASSMD_PROFILE"

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
    df.to_csv(tmp, index=False)
    os.replace(tmp, target)  # atomic: a reader never sees a half-written file
    text = label if label is not None else target.name
    return Markdown(f"{{download}}`{text} </{_DATA_SUBDIR.as_posix()}/{target.name}>`")


@lru_cache(maxsize=1)
def _registry():
    import pint

    return pint.UnitRegistry()


@lru_cache(maxsize=64)
def _si_factor(unit: str) -> float:
    """Size of one ``unit`` in SI base units (e.g. 1e-9 for nm, 1e3 for kHz)."""
    try:
        quantity = _registry().Quantity(1.0, unit).to_base_units()
    except Exception as err:  # pint raises several error types for unknown units
        raise ValueError(f"unit = {unit!r} is not a unit pint understands") from err
    return float(quantity.magnitude)


def to_unit(value_si, unit: str):
    """Convert an SI value (scalar or array) to ``unit`` (e.g. m → ``"nm"``, Hz → ``"kHz"``).

    The caller must pass a value in the SI unit of the same dimension (m, kg, s, N, Hz, m/s,
    N/m, ...); only the scale is converted. Returns a float for a scalar, an array otherwise.
    """
    factor = _si_factor(unit)
    result = np.asarray(value_si, dtype=float) / factor
    return float(result) if result.ndim == 0 else result


def format_quantity(value_si, unit: str, digits: int = 3) -> str:
    """``value_si`` in ``unit`` with ``digits`` significant digits, e.g. ``"202 nm"``."""
    value = to_unit(value_si, unit)
    if np.ndim(value) != 0:
        raise ValueError(f"value_si = {value_si!r} is not allowed: must be a scalar")
    return f"{value:.{int(digits)}g} {unit}"


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
    drive : passmd.parameters.Drive, optional
        Its parameters are listed via :func:`drive_parameters`.
    data : pandas.DataFrame, optional
        Written with :func:`data_link` under ``name`` (required together with ``data``).
    **extra
        Further run parameters, shown as ``key = value`` (format values yourself,
        e.g. ``frequency="100 Hz"``).

    Returns
    -------
    Markdown
        ``**Figure.** text Run with: R = 1 mm, ...; profile: paper. Data: <link>``
    """
    if (data is None) != (name is None):
        raise ValueError("data and name must be given together (name is the CSV file stem)")
    params = drive_parameters(drive) if drive is not None else {}
    params.update({key: str(value) for key, value in extra.items()})
    parts = [f"**Figure.** {text.strip()}"]
    listed = [f"{key} = {value}" for key, value in params.items()]
    listed.append(f"profile: {current_profile()}")
    parts.append("Run with: " + ", ".join(listed) + ".")
    if data is not None:
        parts.append(f"Data: {data_link(data, name)}.")
    return Markdown(" ".join(parts))
