"""Measurement files of a calibration: the columns they may hold, reading, checking and writing them.

A measurement CSV names its units in its column names: the conditions (:data:`CONDITIONS`), one
measured quantity per row (:data:`MEASURED`) with an optional standard deviation
``<quantity>_sd``, optional drive-model columns (:data:`MODELS`) and ignored text columns
(:data:`ANNOTATIONS`). :func:`read_measurements` and :func:`measurements_from_rows` check every
cell once and return :class:`Measurements` in SI units; a malformed file raises
:class:`MeasurementError` naming the file, the row and the column.
"""

from __future__ import annotations

import csv
import io
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from passmd.model.defaults import PROTOCOL
from passmd.runtime.inputs import RefusedFile, decode_text, read_bounded
from passmd.runtime.outputs import write_file
from passmd.runtime.validation import InputError

__all__ = ["ANNOTATIONS", "CONDITIONS", "MAX_ROWS", "MEASURED", "MODELS", "READINGS", "MeasurementError",
           "Measurements",
           "measurements_from_rows", "read_measurements", "write_measurements"]

#: Readings of the critical amplitude (:data:`passmd.protocols.critical_amplitude.PROTOCOLS`).
READINGS = ("steady", "first")

#: Measured columns: quantity kind, display unit (the column's), and whether it must be positive.
MEASURED: dict[str, tuple[str, str, bool]] = {
    "step_nm": ("step", "nm", False),
    "velocity_mm_per_s": ("velocity", "mm/s", False),
    "critical_amplitude_nm": ("critical_amplitude", "nm", True),
    "force_N": ("force", "N", False),
    "position_nm": ("position", "nm", False),
}
#: Columns that set a row's drive model, and the values each allows.
MODELS: dict[str, tuple[str, ...]] = {"contacts": ("1", "6"), "actuator_model": ("rigid", "flexible")}
#: Text columns that say where a row comes from; allowed and ignored.
ANNOTATIONS = ("id", "source_section", "source_quote", "notes")
#: Condition columns and their display units.
CONDITIONS: dict[str, str] = {"amplitude_nm": "nm", "preload_N": "N", "frequency_Hz": "Hz", "radius_mm": "mm"}
_SI = {"nm": 1e-9, "mm/s": 1e-3, "N": 1.0, "Hz": 1.0, "mm": 1e-3}
#: Most measurement rows a file may hold: every parameter set a fit tries simulates each distinct row
#: (identical conditions once), so the work grows with the rows. Repeated measurements of one condition
#: belong in one row, their mean with its standard deviation (``<quantity>_sd``).
MAX_ROWS = 1000


class MeasurementError(InputError):
    """A malformed measurement file: one line naming the file, the row and the column."""


@dataclass(frozen=True)
class Measurements:
    """Measurements in SI, one entry per row (NaN: not given)."""

    kind: tuple[str, ...]  # "step", "velocity", "critical_amplitude", "force"
    column: tuple[str, ...]  # the measured column of each row, as in the file
    value: np.ndarray  # measured value (m, m/s or N)
    sd: np.ndarray  # its standard deviation, NaN if not given
    amplitude: np.ndarray  # m
    frequency: np.ndarray  # Hz
    preload: np.ndarray  # N; NaN: the drive's
    radius: np.ndarray  # m; NaN: the drive's
    line: tuple[int, ...]  # line of each row in the file (header = 1)
    name: str = "data"  # how the caller named the file
    model: tuple[dict, ...] = ()  # per row: contacts / actuator_model given in the file (else empty)

    def __len__(self) -> int:
        return len(self.kind)

    @property
    def known_sd(self) -> bool:
        """Whether every row has a standard deviation (else none has: checked on reading)."""
        return bool(np.all(np.isfinite(self.sd)))

    def display(self, i: int) -> tuple[float, str]:
        """(scale, unit) of row i's measured column: value_SI / scale is in the column's unit."""
        unit = MEASURED[self.column[i]][1]
        return _SI[unit], unit


def _number(text: str, where: str, column: str) -> float:
    try:
        if "_" in text:  # Python's float reads 1_20 as 120: a file's cell is refused, never misread
            raise ValueError(text)
        value = float(text)
    except ValueError:
        raise MeasurementError(f"{where}, column {column}: {text!r} is not a number",
                               name=column, value=text) from None
    if not math.isfinite(value):
        raise MeasurementError(f"{where}, column {column}: {text!r} is not a finite "
                               "number", name=column, value=text)
    return value


def measurements_from_rows(header: Sequence[str], rows: Sequence[Sequence[str]], *, name: str = "data",
                           lines: Sequence[int] | None = None) -> Measurements:
    """Measurements from a CSV's header and rows of text (checked; see the module docstring).

    ``lines``: each row's line in the file (default: the header on line 1, rows below it).

    Raises
    ------
    MeasurementError
        One line naming ``name``, the row (1 = the first below the header), its line and the column.
    """
    lines = list(range(2, len(rows) + 2)) if lines is None else list(lines)
    header = [h.strip() for h in header]
    allowed = [*CONDITIONS, *MEASURED, *(f"{m}_sd" for m in MEASURED), *MODELS, *ANNOTATIONS]
    for j, column in enumerate(header):
        if column not in allowed:
            raise _unknown_column(name, j, column, allowed)
        if column in header[:j]:
            raise MeasurementError(f"{name} header, column {column}: given twice", name=column, value=column)
        if column.endswith("_sd") and column[:-3] not in header:
            raise MeasurementError(f"{name} header, column {column}: a standard deviation without its "
                                   f"measurement column {column[:-3]}", name=column, value=column)
    measured = [c for c in header if c in MEASURED]
    if not measured:
        raise MeasurementError(f"{name} header: no measured column; give one of " + ", ".join(MEASURED),
                               name="header", value=",".join(header))
    if not rows:
        raise MeasurementError(f"{name}: no measurement rows below the header", name="rows", value=0)
    if len(rows) > MAX_ROWS:
        raise MeasurementError(f"{name}: {len(rows)} measurement rows is out of range: must be at most "
                               f"{MAX_ROWS} "
                               "(a fit simulates every distinct row for each parameter set it tries; give "
                               "repeated measurements of one condition as one row, their mean with its _sd)",
                               name="rows", value=len(rows))
    out: dict[str, list] = {k: [] for k in ("kind", "column", "value", "sd", "amplitude", "frequency",
                                            "preload", "radius", "line", "model")}
    for k, row in enumerate(rows):
        line = lines[k]
        where = f"{name} row {k + 1} (line {line})"
        if len(row) != len(header):
            raise MeasurementError(f"{where}: {len(row)} fields, the header has "
                                   f"{len(header)}", name="row", value=len(row))
        cells = {c: v.strip() for c, v in zip(header, row, strict=True)}
        given = [c for c in measured if cells[c]]
        if len(given) != 1:
            what = ("no measured value" if not given
                    else "more than one measured value (" + ", ".join(given) + ")")
            raise MeasurementError(f"{where}, column {given[1] if given else measured[0]}"
                                   f": {what}; each row is one measurement", name="row", value=line)
        column = given[0]
        kind, unit, positive = MEASURED[column]
        value = _number(cells[column], where, column)
        if positive and value <= 0:
            raise MeasurementError(f"{where}, column {column}: {value:g} is out of range: "
                                   "must be > 0", name=column, value=value)
        sd_text = cells.get(column + "_sd", "")
        sd = math.nan
        if sd_text:
            sd = _number(sd_text, where, column + "_sd")
            if sd <= 0:
                raise MeasurementError(f"{where}, column {column}_sd: {sd:g} is out of "
                                       "range: must be > 0", name=column + "_sd", value=sd)
        cond = {}
        for c in CONDITIONS:
            text = cells.get(c, "")
            cond[c] = math.nan
            if text:
                cond[c] = _number(text, where, c)
                if cond[c] <= 0:
                    raise MeasurementError(f"{where}, column {c}: {cond[c]:g} is out "
                                           "of range: must be > 0", name=c, value=cond[c])
        need = ["frequency_Hz"] + ([] if kind == "critical_amplitude" else ["amplitude_nm"])
        for c in need:
            if math.isnan(cond[c]) and kind != "critical_amplitude":
                raise MeasurementError(f"{where}, column {c}: missing; a {column} "
                                       f"measurement needs {' and '.join(need)}", name=c, value="")
        model = {}
        for c, choices in MODELS.items():
            text = cells.get(c, "")
            if text and text not in choices:
                raise MeasurementError(f"{where}, column {c}: {text!r} is not allowed: must be one of "
                                       + ", ".join(choices), name=c, value=text)
            if text:
                model[c] = int(text) if c == "contacts" else text
        out["model"].append(model)
        if kind == "critical_amplitude" and math.isnan(cond["frequency_Hz"]):
            cond["frequency_Hz"] = PROTOCOL.drive_frequency
        out["kind"].append(kind)
        out["column"].append(column)
        out["value"].append(value * _SI[unit])
        out["sd"].append(sd * _SI[unit])
        out["amplitude"].append(cond["amplitude_nm"] * 1e-9)
        out["frequency"].append(cond["frequency_Hz"])
        out["preload"].append(cond["preload_N"])
        out["radius"].append(cond["radius_mm"] * 1e-3)
        out["line"].append(line)
    sd = np.array(out["sd"])
    if np.any(np.isfinite(sd)) and not np.all(np.isfinite(sd)):
        k = int(np.flatnonzero(~np.isfinite(sd))[0])
        raise MeasurementError(f"{name} row {k + 1} (line {out['line'][k]}), column "
                               f"{out['column'][k]}_sd: missing; give a standard deviation for every row or "
                               "for none", name=out["column"][k] + "_sd", value="")
    text = ("kind", "column", "line", "model")
    arrays = {k: np.array(v, dtype=float) for k, v in out.items() if k not in text}
    return Measurements(kind=tuple(out["kind"]), column=tuple(out["column"]), line=tuple(out["line"]),
                        name=name, model=tuple(out["model"]), **arrays)


def _unknown_column(name: str, j: int, column: str, allowed: Sequence[str]) -> MeasurementError:
    """An unknown header cell refused, with the known column it most likely means: the same name
    in another case or punctuation (``Amplitude (nm)``), or the same quantity in another unit
    (``amplitude_m``: ``amplitude_nm``); else the allowed columns are listed."""
    where = f"{name} header, column {j + 1} {column!r}: not a known column"

    def norm(text: str) -> str:
        return re.sub(r"[^0-9a-zµ]+", "_", text.lower()).strip("_")

    target = norm(column)
    same = [known for known in allowed if norm(known) == target]
    if same:
        return MeasurementError(f"{where}; did you mean {same[0]}? (column names are written exactly so)",
                                name=column, value=column)
    sd = target.endswith("_sd")
    base = target[:-3] if sd else target
    units = {**CONDITIONS, **{c: unit for c, (_, unit, _) in MEASURED.items()}}
    stems = {norm(c)[:-len(u.replace("/", "_per_")) - 1]: (c, u) for c, u in units.items()
             if norm(c).endswith("_" + norm(u.replace("/", "_per_")))}
    matches = [stem for stem in stems if base == stem or base.startswith(stem + "_")]
    if matches:
        known, unit = stems[max(matches, key=len)]
        known = known + "_sd" if sd and known + "_sd" in allowed else known
        return MeasurementError(f"{where}; the column of this quantity is {known}, in {unit} (a column name "
                                "carries its unit: convert the values)", name=column, value=column)
    return MeasurementError(f"{where}; allowed: " + ", ".join(allowed), name=column, value=column)


#: Field separators a measurement file may use, recognised from its header line: the comma, and
#: the semicolon or tab that spreadsheets write where the comma is the decimal separator.
DELIMITERS = {",": "comma", ";": "semicolon", "\t": "tab"}
_NAME = re.compile(r"\s*\"?\s*[A-Za-z_][\w ()\[\]/.µ-]*\"?\s*")
_DECIMAL_COMMA = re.compile(r"\s*[+-]?\d*,\d+(?:[eE][+-]?\d+)?\s*")


def _delimiter(header: str) -> str:
    """The separator of a file whose first line is ``header``: the one that splits it into the
    most column names (the comma when none splits it)."""
    def names(delimiter: str) -> int:
        cells = next(csv.reader([header], delimiter=delimiter), [])
        return sum(1 for cell in cells if _NAME.fullmatch(cell)) if len(cells) > 1 else 0

    return max(DELIMITERS, key=names)  # (max keeps the first of equals: the comma)


def read_measurements(path, *, name: str | None = None) -> Measurements:
    """Measurements from a CSV file (see the module docstring); ``name``: how to call it in errors.

    The file is read as UTF-8 (a byte-order mark is dropped) from a regular file of at most
    ``LIMITS["measurement file"]`` bytes (:func:`passmd.runtime.inputs.read_bounded`); its
    separator, a comma, semicolon or tab (``DELIMITERS``), is recognised from the header.
    A number written with a decimal comma is refused (its row and column named), never read
    as another number.
    """
    label = str(path) if name is None else name
    try:
        text = decode_text(read_bounded(path, "measurement file", label=label), label, "measurement file")
    except RefusedFile as exc:
        raise MeasurementError(str(exc), name="file", value=label) from None
    first = next((line for line in text.splitlines() if line.strip()), "")
    delimiter = _delimiter(first)
    try:
        lines = list(csv.reader(io.StringIO(text, newline=""), delimiter=delimiter))
    except csv.Error as exc:
        raise MeasurementError(f"{label}: not a CSV file ({exc})", name="file", value=label) from None
    numbered = [(k + 1, row) for k, row in enumerate(lines) if any(cell.strip() for cell in row)]
    if not numbered:
        raise MeasurementError(f"{label}: empty file; the first line must name the columns", name="file",
                               value=label)
    (_, header), body = numbered[0], numbered[1:]
    if delimiter != ",":
        _refuse_decimal_commas(label, header, body, DELIMITERS[delimiter])
    return measurements_from_rows(header, [row for _, row in body], name=label, lines=[k for k, _ in body])


def _refuse_decimal_commas(label: str, header, body, separator: str) -> None:
    """A cell such as ``5,2`` in a file separated by semicolons or tabs: refused, not misread."""
    for k, (line, row) in enumerate(body):
        for column, cell in zip(header, row, strict=False):
            if _DECIMAL_COMMA.fullmatch(cell):
                point = cell.strip().replace(",", ".")
                where = f"{label} row {k + 1} (line {line}), column {column.strip()}"
                raise MeasurementError(f"{where}: {cell!r} has a decimal comma: write {point} (the file is "
                                       f"separated by {separator}s; passmd reads a point as the decimal "
                                       "separator)", name=column.strip(), value=cell)


def write_measurements(path, data: Measurements, values: np.ndarray | None = None, *,
                       overwrite: bool = False) -> None:
    """Write measurements (or ``values`` in their place) as a CSV :func:`read_measurements` reads,
    completely or not at all (:func:`passmd.runtime.outputs.write_file`); a regular file already at
    ``path`` is replaced only with ``overwrite`` (else :class:`~passmd.runtime.outputs.OutputExists`,
    a ``FileExistsError``, and the file is kept)."""
    columns = list(dict.fromkeys(data.column))
    header = ["amplitude_nm", "preload_N", "frequency_Hz", "radius_mm", *columns]
    if data.known_sd:
        header += [c + "_sd" for c in columns]
    values = data.value if values is None else values

    def write(tmp):
        with open(tmp, "w", newline="", encoding="utf-8") as handle:
            out = csv.writer(handle)
            out.writerow(header)
            for i in range(len(data)):
                scale = data.display(i)[0]
                cell = {"amplitude_nm": data.amplitude[i] * 1e9, "preload_N": data.preload[i],
                        "frequency_Hz": data.frequency[i], "radius_mm": data.radius[i] * 1e3,
                        data.column[i]: values[i] / scale, data.column[i] + "_sd": data.sd[i] / scale}
                out.writerow(["" if c not in cell or not math.isfinite(cell[c]) else repr(float(cell[c]))
                              for c in header])

    write_file(path, write, overwrite=overwrite)
