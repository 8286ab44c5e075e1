"""Calibration: the drive parameters that make the simulator reproduce measurements.

Measurements (:func:`read_measurements`) are rows of a CSV whose column names carry their
units: the conditions ``amplitude_nm``, ``preload_N``, ``frequency_Hz``, ``radius_mm`` and
one measured quantity per row, each with an optional standard deviation ``<quantity>_sd``:

``step_nm``
    Steady step of a saw-tooth (below :data:`passmd.protocols.velocity.STEP_PROTOCOL_BELOW`:
    mean step of a run of three periods from rest, Fig. 9a; above: the steady-velocity
    protocol's step, Figs. 9b/10).
``velocity_mm_per_s``
    The same protocols' velocity (step × f).
``critical_amplitude_nm``
    Critical amplitude A_c of Section 4.1 (:func:`passmd.protocols.critical_amplitude.critical_amplitude`,
    with the reading ``"steady"`` or ``"first"``; no A_c up to the full stroke reads as A_max).
``force_N``
    Generated force at stall against the load cell (Section 4.2, :mod:`passmd.protocols.stall`).
``position_nm``
    Runner position after three saw-tooth periods from rest (Fig. 9a's protocol).

Optional columns ``contacts`` (1 or 6) and ``actuator_model`` (``rigid`` or ``flexible``) set a
row's drive like ``preload_N`` and ``radius_mm``; the text columns ``id``, ``source_section``,
``source_quote`` and ``notes`` (where a row comes from) are allowed and ignored.

Estimator (:func:`fit`): weighted least squares, ``scipy.optimize.least_squares`` (trust-region
reflective, bounded, optional robust loss) over the logarithms of the free parameters, so that
parameters spanning decades are scaled alike. Every model evaluation runs through
:func:`passmd.runtime.sweep.run` (parallel and cached); the residual Jacobian is a forward difference of
relative step :data:`JACOBIAN_STEP`, evaluated in the same sweep as its base point. A coarse
global pass (a scrambled Sobol design of :data:`GLOBAL_STARTS` points over the bounds, one sweep)
picks the starts, so that a kink of the stick–slip response does not trap the local search. A
free parameter whose residuals oscillate on the Jacobian's scale (:data:`ROUGHNESS_LIMIT`; the
step of a flexible drive against k_p) is then scanned around the estimate, the others re-minimised,
and a lower point restarts the local search. When a profile still meets a lower cost than the
estimate, the fit says it has not converged to the global minimum and claims no intervals.

Uncertainty: standard errors from the Jacobian at the optimum (``s² (JᵀJ)⁻¹``, with ``s²`` the
residual variance when no standard deviations are given, else 1), the correlation matrix, and a
95 % interval per parameter from its profile likelihood: the parameter is moved from the
estimate until the least-squares cost, re-minimised over the other free parameters, has risen by
the 95 % quantile of χ²₁ (known standard deviations) or of F(1, n − p) (residual variance
estimated). A parameter is *not identifiable* when its profile stays below that rise up to a
bound (a flat profile), when the Jacobian is rank deficient, or when its correlation with
another parameter exceeds :data:`CORRELATION_LIMIT` in magnitude.
"""

from __future__ import annotations

import concurrent.futures as cf
import csv
import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import PLAUSIBLE_RANGES, Drive, actuator_for_radius, check_drive
from passmd.runtime import sweep
from passmd.runtime.config import RunConfig
from passmd.runtime.validation import InputError, check_choice

__all__ = [
    "CONDITIONS",
    "CORRELATION_LIMIT",
    "FREE_PARAMETERS",
    "GLOBAL_STARTS",
    "JACOBIAN_STEP",
    "LOSSES",
    "MEASURED",
    "FitResult",
    "FreeParameter",
    "Measurements",
    "MeasurementError",
    "ROUGHNESS_LIMIT",
    "default_bounds",
    "fit",
    "fitted_drive_file",
    "measurements_from_rows",
    "predict",
    "predict_point",
    "read_measurements",
    "write_measurements",
]

#: The absolute correlation above which two free parameters are reported as not separable by the data.
#: 0.95: their joint confidence region is then a ridge at least (1+0.95)/(1−0.95) ≈ 6 times
#: longer than wide (eigenvalue ratio of the 2×2 correlation matrix; its axes √39 ≈ 6.2).
CORRELATION_LIMIT = 0.95
#: Relative step of the forward-difference Jacobian (in log-parameter space). 1 % stays well
#: above the critical-amplitude bisection's resolution (0.1 nm of A_c ≈ 50 nm is 0.2 %) and below
#: the curvature scale of the steady step as a function of μ, k_p, c_p (tens of %). The simulated
#: step also wiggles by fractions of a nanometre on this scale, so a local search can stop in a
#: shallow local minimum: a rough parameter is scanned (``ROUGHNESS_LIMIT``), and the profiles
#: look for lower costs and restart it (``REFITS``).
JACOBIAN_STEP = 0.01
#: Points of the global pass's Sobol design (a power of two; the start values are added).
GLOBAL_STARTS = 16
#: A profile's end is accepted where its cost rise is within this fraction of the threshold (a
#: quadratic profile then puts the end within 5 % of the interval's half-width).
PROFILE_TOLERANCE = 0.1
#: Function evaluations of each inner minimisation of a profile over the other free parameters. It
#: starts on the linearised conditional path (the covariance's regression of the others on the
#: profiled one), a few Gauss–Newton steps from the conditional minimum.
PROFILE_STEPS = 4
#: New local searches when a profile meets a lower cost than the estimate (by more than
#: REFIT_MARGIN in units of s²: a third of a 95 % profile rise, so not a rounding effect): the
#: profiles then act as further starts, and the estimate, errors and intervals are computed again.
REFITS = 2
REFIT_MARGIN = 0.5
#: Local least-squares searches started from the best points of the global pass.
LOCAL_STARTS = 2
#: Function evaluations of one local least-squares search.
LOCAL_EVALUATIONS = 60
#: A free parameter is *rough* where the forward and backward differences of the residuals at the
#: estimate (step JACOBIAN_STEP) differ by more than this fraction of their mean: the response
#: oscillates on the Jacobian's scale. The step of the six-contact flexible drive does so in k_p
#: (by ±1–2 nm with a period of about 5–9 % of k_p at 0.2–0.6 N, also in the steady state), and
#: its least-squares cost is then a comb of minima a local search cannot cross. A smooth response
#: (the step against μ or ζ) gives h·|f''/f'| ≈ 0.01–0.03.
ROUGHNESS_LIMIT = 0.25
#: Scan of a rough parameter: offsets from the estimate in log space (±SCAN_HALF_WIDTH in steps
#: of SCAN_SPACING), each with one batched Gauss–Newton step of the other free parameters, whose
#: conditional minima then spread the comb's basins to about ±2 % in k_p. The lowest point, if
#: below the estimate by REFIT_MARGIN, starts a new local search (SCAN_ROUNDS times at most: the
#: new estimate lies inside the range just scanned, and the profiles still look for lower costs).
SCAN_SPACING = 0.015
SCAN_HALF_WIDTH = 0.18
SCAN_ROUNDS = 1
#: Robust losses of ``scipy.optimize.least_squares`` (the intervals use the plain sum of squares).
LOSSES = ("linear", "soft_l1", "huber", "cauchy", "arctan")
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


class MeasurementError(InputError):
    """A malformed measurement file: one line naming the file, the row and the column."""


# --------------------------------------------------------------------------------------
# Measurements
# --------------------------------------------------------------------------------------


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
            raise MeasurementError(f"{name} header, column {j + 1} {column!r}: not a known column; allowed: "
                                   + ", ".join(allowed), name=column, value=column)
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
        raise MeasurementError(f"{name} row {out['line'][k] - 1} (line {out['line'][k]}), column "
                               f"{out['column'][k]}_sd: missing; give a standard deviation for every row or "
                               "for none", name=out["column"][k] + "_sd", value="")
    text = ("kind", "column", "line", "model")
    arrays = {k: np.array(v, dtype=float) for k, v in out.items() if k not in text}
    return Measurements(kind=tuple(out["kind"]), column=tuple(out["column"]), line=tuple(out["line"]),
                        name=name, model=tuple(out["model"]), **arrays)


def read_measurements(path, *, name: str | None = None) -> Measurements:
    """Measurements from a CSV file (see the module docstring); ``name``: how to call it in errors."""
    label = str(path) if name is None else name
    try:
        with open(path, newline="", encoding="utf-8") as handle:
            lines = [row for row in csv.reader(handle)]
    except UnicodeDecodeError as exc:
        raise MeasurementError(f"{label}: not a UTF-8 text file ({exc.reason})", name="file",
                               value=label) from None
    except csv.Error as exc:
        raise MeasurementError(f"{label}: not a CSV file ({exc})", name="file", value=label) from None
    numbered = [(k + 1, row) for k, row in enumerate(lines) if any(cell.strip() for cell in row)]
    if not numbered:
        raise MeasurementError(f"{label}: empty file; the first line must name the columns", name="file",
                               value=label)
    (_, header), body = numbered[0], numbered[1:]
    return measurements_from_rows(header, [row for _, row in body], name=label, lines=[k for k, _ in body])


# --------------------------------------------------------------------------------------
# Free parameters
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class FreeParameter:
    """A drive parameter the fit may vary: how to read and set it, its unit and default range."""

    name: str
    symbol: str
    unit: str  # SI
    description: str
    get: Callable[[Drive], float]
    set: Callable[[Drive, float, Drive], Drive]  # (drive, value, base drive) -> drive
    bounds: Callable[[Drive, float], tuple[float, float]]  # (base drive, highest frequency) -> range
    order: int = 0  # applied in this order (the damping ratio after k_p and m_a)


def _soft(key: str) -> Callable[[Drive, float], tuple[float, float]]:
    r = PLAUSIBLE_RANGES[key]
    return lambda drive, f_max: (r.soft_low, r.soft_high)


def _actuator(**changes) -> Callable[[Drive, float, Drive], Drive]:
    (key,) = changes
    return lambda drive, value, base: replace(drive, actuator=replace(drive.actuator, **{key: value}))


def _with_zeta(drive: Drive, zeta: float, base: Drive) -> Drive:
    act = drive.actuator
    return replace(drive, actuator=replace(act, viscosity=2.0 * zeta * math.sqrt(act.stiffness * act.mass)))


_ZETA_LOW = 1e-3  # lower end of the damping ratio's default range (log scale needs > 0; Q = 500)


def _viscosity_bounds(drive: Drive, f_max: float) -> tuple[float, float]:
    scale = 2.0 * math.sqrt(drive.actuator.stiffness * drive.actuator.mass)
    return _ZETA_LOW * scale, PLAUSIBLE_RANGES["actuator.damping_ratio"].soft_high * scale


def _flyback_bounds(drive: Drive, f_max: float) -> tuple[float, float]:
    sr = PLAUSIBLE_RANGES["amplifier.slew_rate"]
    v = drive.amplifier.peak_to_peak_voltage
    return v / sr.soft_high, min(v / sr.soft_low, 0.25 / f_max)  # a fly-back within a quarter period


def _slew_bounds(drive: Drive, f_max: float) -> tuple[float, float]:
    low, high = _flyback_bounds(drive, f_max)
    v = drive.amplifier.peak_to_peak_voltage
    return v / high, v / low


def _scale_bounds(drive: Drive, f_max: float) -> tuple[float, float]:
    r = PLAUSIBLE_RANGES["material.youngs_modulus"]
    moduli = (drive.hemisphere_material.youngs_modulus, drive.runner_material.youngs_modulus)
    return max(r.soft_low / e for e in moduli), min(r.soft_high / e for e in moduli)


def _scaled(drive: Drive, s: float, base: Drive) -> Drive:
    h, r = base.hemisphere_material, base.runner_material
    return replace(drive, hemisphere_material=replace(h, youngs_modulus=s * h.youngs_modulus),
                   runner_material=replace(r, youngs_modulus=s * r.youngs_modulus))


def _with_slew(drive: Drive, value: float, base: Drive) -> Drive:
    return replace(drive, amplifier=replace(drive.amplifier, slew_rate=value))


#: The parameters a fit may free, by name (the drive's field, dotted for a part; or a derived one).
FREE_PARAMETERS: dict[str, FreeParameter] = {p.name: p for p in (
    FreeParameter("friction_coefficient", "μ", "", "friction coefficient (Table 1)",
                  lambda d: d.friction_coefficient,
                  lambda d, v, b: replace(d, friction_coefficient=v), _soft("friction_coefficient")),
    FreeParameter("actuator.stiffness", "k_p", "N/m", "actuator stiffness (Table 2)",
                  lambda d: d.actuator.stiffness, _actuator(stiffness=None), _soft("actuator.stiffness")),
    FreeParameter("actuator.mass", "m_a", "kg", "actuator mass (Table 2)",
                  lambda d: d.actuator.mass, _actuator(mass=None), _soft("actuator.mass")),
    FreeParameter("actuator.viscosity", "c_p", "kg/s", "actuator viscosity (Eq. 3; Table 2's column lost)",
                  lambda d: d.actuator.viscosity, _actuator(viscosity=None), _viscosity_bounds, order=1),
    FreeParameter("actuator.damping_ratio", "ζ", "", "damping ratio c_p / (2√(k_p m_a)) of the bare actuator",
                  lambda d: d.actuator.damping_ratio, _with_zeta,
                  lambda d, f: (_ZETA_LOW, PLAUSIBLE_RANGES["actuator.damping_ratio"].soft_high), order=1),
    FreeParameter("runner_mass", "m_r", "kg", "runner mass (Table 1)", lambda d: d.runner_mass,
                  lambda d, v, b: replace(d, runner_mass=v), _soft("runner_mass")),
    FreeParameter("amplifier.slew_rate", "SR", "V/s", "amplifier slew rate (Section 2): sets the fly-back",
                  lambda d: d.amplifier.slew_rate, _with_slew, _slew_bounds),
    FreeParameter("flyback_time", "t_fb", "s", "fly-back time of a full stroke, V_pp / SR (Section 2)",
                  lambda d: d.amplifier.full_stroke_time,
                  lambda d, v, b: _with_slew(d, d.amplifier.peak_to_peak_voltage / v, b), _flyback_bounds),
    FreeParameter("contact_stiffness_scale", "s_E", "",
                  "factor on both Young's moduli (contact stiffness ∝ E*), relative to the drive's",
                  lambda d: 1.0, _scaled, _scale_bounds),
)}
#: Free parameters that set the same drive field: at most one of each group.
_SAME_FIELD = (("actuator.viscosity", "actuator.damping_ratio"), ("amplifier.slew_rate", "flyback_time"))


def _check_free(drive: Drive, free: Sequence[str]) -> list[str]:
    if isinstance(free, str) or not isinstance(free, Sequence) or not free:
        raise InputError(f"free = {free!r} is not allowed: must be a non-empty list of names from "
                         + ", ".join(FREE_PARAMETERS), name="free", value=free)
    names = list(free)
    for name in names:
        if name not in FREE_PARAMETERS:
            raise InputError(f"free = {name!r} is not a parameter the fit can free: must be one of "
                             + ", ".join(FREE_PARAMETERS), name="free", value=name)
        if names.count(name) > 1:
            raise InputError(f"free = {name!r} is given twice", name="free", value=name)
        if drive.actuator_model == "rigid" and name.startswith("actuator."):
            raise InputError(f"free = {name!r} has no effect on ideally rigid actuators (actuator_model = "
                             "'rigid'): free it with flexible actuators", name="free", value=name)
    for group in _SAME_FIELD:
        if all(g in names for g in group):
            raise InputError(f"free = {group[0]!r} and {group[1]!r} set the same drive field: free one of "
                             "them",
                             name="free", value=group[1])
    return names


def default_bounds(drive: Drive, name: str,
                   max_frequency: float = PROTOCOL.drive_frequency) -> tuple[float, float]:
    """Default (low, high) of a free parameter: its plausible range
    (:data:`~passmd.model.parameters.PLAUSIBLE_RANGES`).

    The damping ratio's range starts at 1e-3 (the logarithmic scale needs a positive lower end);
    the fly-back is limited to a quarter of the shortest driving period.
    """
    check_drive(drive)
    if name not in FREE_PARAMETERS:
        raise InputError(f"name = {name!r} is not a parameter the fit can free: must be one of "
                         + ", ".join(FREE_PARAMETERS), name="name", value=name)
    low, high = FREE_PARAMETERS[name].bounds(drive, max_frequency)
    return float(low), float(high)


# --------------------------------------------------------------------------------------
# Model evaluation (one point of a sweep)
# --------------------------------------------------------------------------------------


def predict_point(drive: Drive, kind: str, amplitude: float, frequency: float, reading: str) -> dict:
    """The model's value of one measurement (SI): ``{"prediction": value}`` (a sweep function)."""
    from passmd.protocols import velocity

    if kind == "position":
        run = velocity.step_run(drive, amplitude, frequency, "sawtooth")
        return {"prediction": float(run["final_position_m"])}
    if kind in ("step", "velocity"):
        if frequency < velocity.STEP_PROTOCOL_BELOW:
            step = velocity.step_run(drive, amplitude, frequency, "sawtooth")["mean_step_m"]
        else:
            step = velocity.steady_run(drive, amplitude, frequency, "sawtooth", "cut")["step_m"]
        return {"prediction": float(step if kind == "step" else step * frequency)}
    if kind == "critical_amplitude":
        from passmd.protocols import critical_amplitude as ca

        found = ca.critical_amplitude(drive, protocol=reading, frequency=frequency, progress=False)
        value = found["critical_amplitude_m"]
        return {"prediction": float(found["bracket_low_m"] if math.isnan(value) else value)}
    from passmd.protocols import stall

    found = stall.generated_force(replace(drive, load_cell=True), amplitude, frequency, progress=False)
    return {"prediction": float(found["generated_force_N"])}


def _row_drives(drive: Drive, data: Measurements) -> list[Drive]:
    """Each row's drive: ``drive`` at the row's preload, radius (Table 2 actuator for another radius),
    number of contacts and actuator model, where the row gives them."""
    out = []
    for i in range(len(data)):
        changes = dict(data.model[i]) if data.model else {}
        if math.isfinite(data.preload[i]):
            changes["preload"] = float(data.preload[i])
        if math.isfinite(data.radius[i]) and not math.isclose(data.radius[i], drive.hemisphere_radius,
                                                               rel_tol=1e-12):
            changes["hemisphere_radius"] = float(data.radius[i])
            changes["actuator"] = actuator_for_radius(float(data.radius[i]))
        out.append(replace(drive, **changes) if changes else drive)
    return out


class _Model:
    """Predictions of all rows at parameter vectors (log space), through the sweep engine."""

    def __init__(self, drive, data, names, reading, *, executor, cache, config):
        self.drive, self.data, self.names, self.reading = drive, data, names, reading
        self.executor, self.cache, self.config = executor, cache, config
        self.params = sorted((FREE_PARAMETERS[n] for n in names), key=lambda p: p.order)
        self.index = {n: k for k, n in enumerate(names)}
        self.rows = _row_drives(replace(drive, allow_extrapolation=True), data)
        self.memo: dict[bytes, np.ndarray] = {}
        self.simulations = 0
        self.evaluations = 0

    def drive_at(self, x, base: Drive) -> Drive:
        d = base
        for p in self.params:
            d = p.set(d, float(np.exp(x[self.index[p.name]])), base)
        return d

    def evaluate(self, xs: Sequence[np.ndarray]) -> list[np.ndarray]:
        """Predictions (SI, one array per vector); vectors already computed come from memory."""
        keys = [np.asarray(x, float).tobytes() for x in xs]
        todo = list(dict.fromkeys(k for k in keys if k not in self.memo))
        if todo:
            points = []
            for k in todo:
                x = np.frombuffer(k)
                for i, base in enumerate(self.rows):
                    points.append({"drive": self.drive_at(x, base), "kind": self.data.kind[i],
                                   "amplitude": float(np.nan_to_num(self.data.amplitude[i])),
                                   "frequency": float(self.data.frequency[i]),
                                   "reading": (self.reading if self.data.kind[i] == "critical_amplitude"
                                               else "")})
            frame = sweep.run(predict_point, points, executor=self.executor, cache=self.cache, progress=False,
                              config=self.config)
            values = frame["prediction"].to_numpy(float).reshape(len(todo), len(self.rows))
            for k, v in zip(todo, values, strict=True):
                self.memo[k] = v
            self.simulations += frame.attrs["sweep"]["computed"]
            self.evaluations += len(todo)
        return [self.memo[k] for k in keys]


# --------------------------------------------------------------------------------------
# The fit
# --------------------------------------------------------------------------------------


@dataclass
class FitResult:
    """The fitted drive, the estimates with their uncertainties and the identifiability verdict."""

    drive: Drive  # the fitted drive (the given drive with the estimates)
    base: Drive  # the drive the fit started from
    names: list[str]  # free parameters, in the order given
    estimates: dict[str, dict]  # name -> value, stderr, interval [low, high], unit (SI), bounds, flat
    correlation: np.ndarray
    data: Measurements
    predicted: np.ndarray  # SI, per row
    weights: np.ndarray  # σ per row (SI) the residuals are divided by
    cost: float  # Σ r² at the estimate
    scale: float  # s: residual standard deviation in units of σ (1 when σ is known)
    dof: int
    identifiable: bool
    verdict: str
    reading: str
    loss: str
    simulations: int
    evaluations: int
    wall_time_s: float
    notes: list[str] = field(default_factory=list)
    converged: bool = True  # False: a profile met a lower cost than the estimate (a local minimum)

    @property
    def residuals(self) -> np.ndarray:
        """(measured − predicted) / σ per row."""
        return (self.data.value - self.predicted) / self.weights

    def report(self) -> dict:
        """The JSON report (SI units; keys as the command line's --json)."""
        rows = []
        for i in range(len(self.data)):
            scale, unit = self.data.display(i)
            rows.append({"line": self.data.line[i], "quantity": self.data.column[i],
                         "measured": self.data.value[i] / scale, "predicted": self.predicted[i] / scale,
                         "unit": unit, "normalized_residual": float(self.residuals[i])})
        return {
            "estimates": {n: {k: v for k, v in self.estimates[n].items()} for n in self.names},
            "residuals": rows,
            "correlation": {"parameters": list(self.names), "matrix": self.correlation.tolist(),
                            "limit": CORRELATION_LIMIT},
            "identifiable": self.identifiable,
            "converged": self.converged,
            "verdict": self.verdict,
            "cost": self.cost,
            "residual_scale": self.scale,
            "degrees_of_freedom": self.dof,
            "sd_known": self.data.known_sd,
            "reading": self.reading,
            "loss": self.loss,
            "measurements": len(self.data),
            "simulations": self.simulations,
            "model_evaluations": self.evaluations,
            "wall_time_s": self.wall_time_s,
            "notes": list(self.notes),
        }


def _weights(data: Measurements) -> np.ndarray:
    if data.known_sd:
        return data.sd.copy()
    return np.array([data.display(i)[0] for i in range(len(data))])  # one display unit


def _check_bounds(drive, names, bounds, f_max) -> dict[str, tuple[float, float]]:
    bounds = {} if bounds is None else dict(bounds)
    for name in bounds:
        if name not in names:
            raise InputError(f"bounds names {name!r}, which is not a free parameter ({', '.join(names)})",
                             name="bounds", value=name)
    out = {}
    for name in names:
        low, high = bounds.get(name, default_bounds(drive, name, f_max))
        if not (math.isfinite(low) and math.isfinite(high) and 0 < low < high):
            raise InputError(f"bounds of {name} = {low!r}..{high!r} are not allowed: must be 0 < low < high",
                             name=name, value=(low, high))
        out[name] = (float(low), float(high))
    return out


def fit(
    drive: Drive,
    data: Measurements,
    free: Sequence[str],
    *,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    reading: str = "steady",
    loss: str = "linear",
    starts: int = GLOBAL_STARTS,
    seed: int = 0,
    executor: str | cf.Executor | None = None,
    cache=True,
    config: RunConfig | None = None,
    progress: Callable[[str], None] | None = None,
) -> FitResult:
    """Fit the free parameters of ``drive`` to ``data`` (module docstring).

    Parameters
    ----------
    drive : Drive
        The drive whose other parameters are known; its values of the free ones are a start.
    data : Measurements
        From :func:`read_measurements` or :func:`measurements_from_rows`.
    free : list of str
        Names from :data:`FREE_PARAMETERS`.
    bounds : dict, optional
        name -> (low, high) in SI; default :func:`default_bounds`.
    reading : {"steady", "first"}
        How the simulator reads a critical amplitude (Section 4.1's two protocols).
    loss : str
        Loss of the estimate (:data:`LOSSES`); the intervals use the sum of squares.
    starts : int
        Points of the global pass (a power of two >= 2; 0: start from the drive's values only).
    seed : int
        Seed of the scrambled Sobol design (the fit is deterministic for a seed).
    executor, cache, config
        How the model evaluations run (:func:`passmd.runtime.sweep.run`); a process pool is kept for the
        whole fit.
    progress : callable, optional
        Receives one line per stage (global pass, each local search, each profile).

    Raises
    ------
    InputError
        Bad arguments; also when there are no more measurements than free parameters.
    """
    from scipy import optimize, stats
    from scipy.stats import qmc

    t0 = time.perf_counter()
    check_drive(drive)
    if not isinstance(data, Measurements):
        raise InputError(f"data = {data!r} is not Measurements (read_measurements)", name="data", value=data)
    names = _check_free(drive, free)
    check_choice("reading", reading, READINGS)
    check_choice("loss", loss, LOSSES)
    if isinstance(starts, bool) or not isinstance(starts, int) or starts < 0 or (starts & (starts - 1)):
        raise InputError(f"starts = {starts!r} is out of range: must be 0 or a power of two", name="starts",
                         value=starts)
    n, p = len(data), len(names)
    if n <= p:
        raise InputError(f"{n} measurements cannot determine {p} free parameters: give more measurements "
                         "than "
                         "free parameters", name="data", value=n)
    f_max = float(np.max(data.frequency))
    box = _check_bounds(drive, names, bounds, f_max)
    say = progress or (lambda line: None)
    lo = np.log([box[k][0] for k in names])
    hi = np.log([box[k][1] for k in names])
    x_start = np.clip(np.log([max(FREE_PARAMETERS[k].get(drive), 1e-300) for k in names]), lo, hi)
    sigma = _weights(data)
    config = RunConfig() if config is None else config
    pool = None
    chosen = executor if executor is not None else config.executor or "process"
    if chosen == "process":
        pool = cf.ProcessPoolExecutor(max_workers=config.workers, initializer=sweep._ignore_sigint)
        chosen = pool
    model = _Model(drive, data, names, reading, executor=chosen, cache=cache, config=config)
    try:
        return _fit(model, drive, data, names, box, lo, hi, x_start, sigma, reading, loss, starts, seed,
                    say, t0, optimize, stats, qmc)
    finally:
        if pool is not None:
            pool.shutdown(wait=True, cancel_futures=True)


def _fit(model, drive, data, names, box, lo, hi, x_start, sigma, reading, loss, starts, seed, say, t0,
         optimize, stats, qmc) -> FitResult:
    n, p = len(data), len(names)
    h = JACOBIAN_STEP

    def residual(pred):
        return (pred - data.value) / sigma

    def perturbed(x, cols):
        out = []
        for j in cols:
            e = np.zeros(p)
            e[j] = h if x[j] + h <= hi[j] else -h
            out.append(x + e)
        return out

    def fun_jac(x, cols=None):
        """Residual and Jacobian (d r / d log θ; columns ``cols``), base and perturbed points in one sweep."""
        x = np.asarray(x, float)
        steps = perturbed(x, range(p) if cols is None else cols)
        base, *others = model.evaluate([x, *steps])
        r = residual(base)
        jac = np.column_stack([(residual(o) - r) / (s - x).sum()
                               for o, s in zip(others, steps, strict=True)]) if steps else np.zeros((n, 0))
        return r, jac

    # global pass: a Sobol design over the log box, one sweep
    candidates = [x_start]
    if starts:
        design = qmc.Sobol(d=p, scramble=True, seed=seed).random(starts)
        candidates += [lo + u * (hi - lo) for u in design]
    say(f"global pass: {len(candidates)} parameter sets × {n} measurements")
    costs = [float(np.sum(residual(v) ** 2)) for v in model.evaluate(candidates)]
    order = np.argsort(costs)
    picks = [candidates[k] for k in order[:LOCAL_STARTS]]

    def local(x0):
        """A bounded least-squares search from x0: (x, cost)."""
        memo = {}

        def f(x):
            r, jac = fun_jac(x)
            memo[np.asarray(x, float).tobytes()] = jac
            return r

        def jf(x):
            key = np.asarray(x, float).tobytes()
            return memo[key] if key in memo else fun_jac(x)[1]

        sol = optimize.least_squares(f, x0, jac=jf, bounds=(lo, hi), loss=loss, method="trf", x_scale=1.0,
                                     xtol=1e-6, ftol=1e-8, gtol=1e-8, max_nfev=LOCAL_EVALUATIONS)
        return sol.x, float(np.sum(f(sol.x) ** 2))

    def rough(x):
        """Indices of the free parameters whose residuals oscillate on the Jacobian's scale at x."""
        steps = [x + np.eye(p)[j] * (-h if x[j] - h >= lo[j] else h) for j in range(p)]
        r, jac = fun_jac(x)
        back = model.evaluate(steps)
        out = []
        for j in range(p):
            other = (residual(back[j]) - r) / (steps[j] - x).sum()
            mean = 0.5 * np.linalg.norm(jac[:, j] + other)
            # only a response that matters across the scan: a change of more than one σ
            if (np.linalg.norm(jac[:, j] - other) > ROUGHNESS_LIMIT * mean
                    and max(np.linalg.norm(jac[:, j]), np.linalg.norm(other)) * SCAN_HALF_WIDTH > 1.0):
                out.append(j)
        return out

    def scan(x, j):
        """(x, cost) of the lowest point of a scan of parameter j, the others one Gauss–Newton step
        from x's (all points in one sweep per stage)."""
        others = [k for k in range(p) if k != j]
        count = int(round(SCAN_HALF_WIDTH / SCAN_SPACING))
        points = []
        for k in range(-count, count + 1):
            t = x[j] + k * SCAN_SPACING
            if k and lo[j] <= t <= hi[j]:
                y = np.array(x, float)
                y[j] = t
                points.append(y)
        if others:
            trials = [[y, *(y + np.eye(p)[m] * (h if y[m] + h <= hi[m] else -h) for m in others)]
                      for y in points]
            values = model.evaluate([v for group in trials for v in group])
            moved = []
            for i, group in enumerate(trials):
                base = residual(values[i * (len(others) + 1)])
                jac = np.column_stack([(residual(values[i * (len(others) + 1) + 1 + a]) - base)
                                       / (group[1 + a] - group[0]).sum() for a in range(len(others))])
                step = np.linalg.lstsq(jac, -base, rcond=None)[0]
                y = np.array(group[0], float)
                y[others] = np.clip(y[others] + step, lo[others], hi[others])
                moved.append(y)
            points = points + moved
        costs = [float(np.sum(residual(v) ** 2)) for v in model.evaluate(points)]
        k = int(np.argmin(costs))
        return points[k], costs[k]

    best = None
    for k, x0 in enumerate(picks):
        say(f"local search {k + 1}/{len(picks)} from cost {costs[order[k]]:.4g}")
        x, c = local(x0)
        if best is None or c < best[1]:
            best = (x, c)
    x_hat, cost = best
    for _ in range(SCAN_ROUNDS):
        found = None
        margin = REFIT_MARGIN * (1.0 if data.known_sd else cost / (n - p))
        for j in rough(x_hat):
            say(f"{names[j]}: the residuals oscillate on the Jacobian's scale; scanning "
                f"±{SCAN_HALF_WIDTH:.0%}")
            x_scan, c_scan = scan(x_hat, j)
            if c_scan < cost - margin and (found is None or c_scan < found[1]):
                found = (x_scan, c_scan)
        if found is None:
            break
        say(f"the scan met cost {found[1]:.5g} below the estimate's {cost:.5g}: searching again from there")
        x_new, c_new = local(found[0])
        x_hat, cost = (x_new, c_new) if c_new < found[1] else found
    notes: list[str] = []
    converged = True
    for attempt in range(REFITS + 1):
        say("estimate " + ", ".join(f"{k} = {v:.5g}" for k, v in zip(names, np.exp(x_hat), strict=True))
            + f", cost {cost:.5g}")
        r, J = fun_jac(x_hat)
        dof = n - p
        s2 = 1.0 if data.known_sd else cost / dof
        jtj = J.T @ J
        rank = int(np.linalg.matrix_rank(J, tol=1e-10 * max(1.0, float(np.abs(J).max()))))
        cov = s2 * np.linalg.pinv(jtj)
        se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
        with np.errstate(invalid="ignore", divide="ignore"):
            corr = cov / np.outer(se, se)
        corr = np.where(np.isfinite(corr), corr, 0.0)
        np.fill_diagonal(corr, 1.0)

        lowest = [cost, x_hat]  # the lowest cost a profile meets, and where
        threshold = float(stats.chi2.ppf(0.95, 1) if data.known_sd else stats.f.ppf(0.95, 1, dof))

        def profile_cost(j, t, start_others, x_hat=x_hat, lowest=lowest):
            """Least-squares cost with parameter j fixed at t (log), minimised over the others."""
            others = [k for k in range(p) if k != j]

            def full(y):
                x = np.array(x_hat, float)
                x[j] = t
                x[others] = y
                return x

            if not others:
                c = float(np.sum(fun_jac(full([]), [])[0] ** 2))
                if c < lowest[0]:
                    lowest[:] = [c, full([])]
                return c, []
            sol = optimize.least_squares(lambda y: fun_jac(full(y), others)[0], start_others,
                                         jac=lambda y: fun_jac(full(y), others)[1],
                                         bounds=(lo[others], hi[others]), method="trf", xtol=1e-4, ftol=1e-5,
                                         max_nfev=PROFILE_STEPS)
            c = float(np.sum(fun_jac(full(sol.x), others)[0] ** 2))
            if c < lowest[0]:
                lowest[:] = [c, full(sol.x)]
            return c, sol.x

        estimates: dict[str, dict] = {}
        flat: dict[str, bool] = {}
        for j, name in enumerate(names):
            say(f"profile of {name} ({j + 1}/{p})")
            others = [k for k in range(p) if k != j]
            ends = []
            reached = False
            for sign in (-1.0, 1.0):
                limit = (lo if sign < 0 else hi)[j]
                room = abs(limit - x_hat[j])
                # the linearised conditional path of the others gives each inner search its start
                slope = np.zeros(len(others))
                if others and cov[j, j] > 0:
                    slope = cov[others, j] / cov[j, j]

                def D(delta, slope=slope, sign=sign, j=j, others=others, x_hat=x_hat, cost=cost, s2=s2):
                    t = x_hat[j] + sign * delta
                    y0 = (np.clip(x_hat[others] + slope * sign * delta, lo[others], hi[others]) if others
                          else [])
                    c, _ = profile_cost(j, t, y0)
                    return (c - cost) / s2

                if room <= 0.0:  # the estimate is at this bound: the interval ends there
                    ends.append(limit)
                    notes.append(f"{name} is at its {'lower' if sign < 0 else 'upper'} bound: widen --bounds")
                    continue
                d_in, v_in = 0.0, 0.0
                # the quadratic approximation's end first: where a quadratic profile meets the threshold
                guess = math.sqrt(threshold) * se[j] if np.isfinite(se[j]) and se[j] > 0 else 0.1
                delta = min(max(guess, 0.02), room)
                v = D(delta)
                if abs(v - threshold) < PROFILE_TOLERANCE * threshold:
                    ends.append(x_hat[j] + sign * delta)
                    continue
                while v < threshold and delta < room:
                    d_in, v_in = delta, v
                    delta = min(2.0 * delta, room)
                    v = D(delta)
                if v < threshold:  # flat up to the bound
                    reached = True
                    ends.append(limit)
                    continue
                for _ in range(4):  # the signed root of the profile is about linear in delta
                    a, b = math.sqrt(max(v_in, 0.0)), math.sqrt(max(v, 0.0))
                    mid = (d_in + (delta - d_in) * (math.sqrt(threshold) - a) / (b - a) if b > a
                           else 0.5 * (d_in + delta))
                    mid = min(max(mid, d_in + 0.05 * (delta - d_in)), delta - 0.05 * (delta - d_in))
                    vm = D(mid)
                    if abs(vm - threshold) < PROFILE_TOLERANCE * threshold:
                        delta = mid
                        break
                    if vm < threshold:
                        d_in, v_in = mid, vm
                    else:
                        delta, v = mid, vm
                ends.append(x_hat[j] + sign * delta)
            value = float(np.exp(x_hat[j]))
            flat[name] = reached
            estimates[name] = {"value": value, "stderr": float(value * se[j]),
                               "interval": [float(np.exp(ends[0])), float(np.exp(ends[1]))],
                               "unit": FREE_PARAMETERS[name].unit, "symbol": FREE_PARAMETERS[name].symbol,
                               "bounds": list(box[name]), "flat_profile": reached}

        if lowest[0] >= cost - REFIT_MARGIN * s2:
            break
        if attempt == REFITS:
            converged = False
            notes.append(f"a profile met cost {lowest[0]:.5g} below the estimate's {cost:.5g} after {REFITS} "
                         "new searches: the least-squares minimum may not be global (widen --starts)")
            break
        say(f"a profile met cost {lowest[0]:.5g} below the estimate's {cost:.5g}: searching again from there")
        x_hat, cost = local(lowest[1])
    notes = list(dict.fromkeys(notes))
    identifiable, verdict = _verdict(names, corr, flat, rank, data)
    if not converged:
        identifiable = False
        verdict = (f"Not converged to the global minimum: a profile met cost {lowest[0]:.5g} below the "
                   f"estimate's {cost:.5g}, so the standard errors and intervals describe a local minimum "
                   "and claim nothing about the parameters; rerun with more --starts or narrower --bounds. "
                   + verdict)
    fitted = model.drive_at(x_hat, drive)
    fitted = replace(fitted, allow_extrapolation=drive.allow_extrapolation)
    pred = model.evaluate([x_hat])[0]
    return FitResult(drive=fitted, base=drive, names=names, estimates=estimates, correlation=corr, data=data,
                     predicted=pred, weights=sigma, cost=cost, scale=math.sqrt(s2), dof=dof,
                     identifiable=identifiable, verdict=verdict, reading=reading, loss=loss,
                     simulations=model.simulations, evaluations=model.evaluations,
                     wall_time_s=time.perf_counter() - t0, notes=notes, converged=converged)


def _advice(data: Measurements) -> str:
    """What data would add information, from what the measurements do not vary."""
    tips = []
    if len({float(x) for x in data.preload}) <= 1:
        tips.append("measurements at a second preload")
    if len({float(x) for x in data.frequency}) <= 1:
        tips.append("measurements at another driving frequency")
    if len(set(data.kind)) == 1:
        dynamic = "the critical amplitude or the stall force"
        other = {"step": dynamic, "velocity": dynamic, "critical_amplitude": "steps against amplitude",
                 "force": "steps against amplitude"}
        tips.append(f"another kind of measurement ({other[data.kind[0]]})")
    amps = data.amplitude[np.isfinite(data.amplitude)]
    if amps.size and amps.max() < 1.5 * amps.min():
        tips.append("a wider range of amplitudes")
    if not tips:
        return "add measurements at other preloads, frequencies or amplitudes"
    return "add " + ", ".join(tips)


def _verdict(names, corr, flat, rank, data) -> tuple[bool, str]:
    sentences = []
    bad = set()
    advice = _advice(data)
    if rank < len(names):
        sentences.append(f"The Jacobian has rank {rank} < {len(names)}: the data do not determine "
                         + " and ".join(names) + f" jointly; {advice}.")
        bad.update(names)
    for name in names:
        if flat[name]:
            sentences.append(f"{name} is not identifiable: its profile likelihood stays within the 95 % rise "
                             f"up to a bound of its range; {advice}.")
            bad.add(name)
    for a in range(len(names)):
        for b in range(a + 1, len(names)):
            if abs(corr[a, b]) > CORRELATION_LIMIT:
                sentences.append(f"{names[a]} and {names[b]} are not separable from these data (correlation "
                                 f"{corr[a, b]:+.3f}, limit ±{CORRELATION_LIMIT:g}); {advice}.")
                bad.update((names[a], names[b]))
    if not bad:
        return True, ("Every free parameter is identifiable: closed 95 % profile intervals and "
                      f"|correlation| ≤ {CORRELATION_LIMIT:g}.")
    return False, " ".join(sentences)


def predict(drive: Drive, data: Measurements, *, reading: str = "steady", executor=None, cache=True,
            config: RunConfig | None = None) -> np.ndarray:
    """The model's value of every measurement of ``data`` for ``drive`` (SI), through the sweep engine."""
    check_drive(drive)
    check_choice("reading", reading, READINGS)
    points = [{"drive": d, "kind": data.kind[i], "amplitude": float(np.nan_to_num(data.amplitude[i])),
               "frequency": float(data.frequency[i]),
               "reading": reading if data.kind[i] == "critical_amplitude" else ""}
              for i, d in enumerate(_row_drives(drive, data))]
    frame = sweep.run(predict_point, points, executor=executor, cache=cache, progress=False, config=config)
    return frame["prediction"].to_numpy(float)


def write_measurements(path, data: Measurements, values: np.ndarray | None = None) -> None:
    """Write measurements (or ``values`` in their place) as a CSV :func:`read_measurements` reads."""
    columns = list(dict.fromkeys(data.column))
    header = ["amplitude_nm", "preload_N", "frequency_Hz", "radius_mm", *columns]
    if data.known_sd:
        header += [c + "_sd" for c in columns]
    values = data.value if values is None else values
    with open(Path(path), "w", newline="", encoding="utf-8") as handle:
        out = csv.writer(handle)
        out.writerow(header)
        for i in range(len(data)):
            scale = data.display(i)[0]
            cell = {"amplitude_nm": data.amplitude[i] * 1e9, "preload_N": data.preload[i],
                    "frequency_Hz": data.frequency[i], "radius_mm": data.radius[i] * 1e3,
                    data.column[i]: values[i] / scale, data.column[i] + "_sd": data.sd[i] / scale}
            out.writerow(["" if c not in cell or not math.isfinite(cell[c]) else repr(float(cell[c]))
                          for c in header])


def fitted_drive_file(drive: Drive, data_name: str, free: Sequence[str]) -> str:
    """The fitted drive as a drive file (:func:`passmd.model.drive_file.drive_toml`) that ``--drive`` and
    :func:`passmd.model.drive_file.load_drive` read back; the fitted keys name the data (``data_name``)
    as their source. ``free``: the fitted parameters' names (:data:`FREE_PARAMETERS`)."""
    from passmd.model.drive_file import DRIVE_KEYS, drive_toml

    fitted = {"actuator.damping_ratio": "actuator.viscosity", "flyback_time": "amplifier.slew_rate",
              "contact_stiffness_scale": "hemisphere_material.youngs_modulus"}
    sources = {}
    for name in free:
        key = fitted.get(name, name)
        if key in DRIVE_KEYS:
            sources[key] = f"fitted to {data_name} by passmd fit"
    if "contact_stiffness_scale" in free:
        sources["runner_material.youngs_modulus"] = f"fitted to {data_name} by passmd fit (scale on E)"
    return drive_toml(drive, sources, title=f"drive fitted by passmd fit to {data_name}")
