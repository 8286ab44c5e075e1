"""SI values as the book shows them: converted to the units shown at the edges (nm, N, mN, mm, kHz,
mm/s, ...) with the package's converter (:func:`passmd.runtime.units.from_si`), formatted, a profile's
grid named, a drive's parameters listed for a caption and a parameter record turned into a table (so
the book never retypes them). The chapters reach them through :mod:`passmd.report.publish`.
"""

from __future__ import annotations

import numpy as np

from passmd.runtime.units import from_si

__all__ = ["DISPLAY_UNITS", "drive_parameters", "format_quantity", "grid_text", "parameter_frame", "to_unit"]


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
        Dotted field name → display unit; default :data:`~passmd.report.quantities.DISPLAY_UNITS`.

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
