"""Human and JSON output of the commands: display units, checked numbers, aligned rows.

Human output uses nm, N, mm and kHz; ``--json`` prints one JSON object in SI units whose
keys carry the unit. Both go through :func:`plain`, so a non-finite number is the same
:class:`~passmd.cli.result_bounds.ResultError` with and without ``--json``.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np

from passmd.cli.errors import UsageError
from passmd.cli.result_bounds import ResultError
from passmd.model.parameters import Drive
from passmd.runtime.outputs import check_writable, file_target
from passmd.runtime.units import from_si

__all__ = ["JSON_HELP", "check_output_file", "check_results", "describe", "drive_record", "emit_json",
           "emit_rows", "fmt", "nm", "plain", "sides"]

JSON_HELP = "print one JSON object (SI units) instead (default: off)"


def check_output_file(flag: str, name: str) -> None:
    """An output option names a file (not a directory) in an existing directory (before running:
    :class:`UsageError`, exit 2)."""
    target = Path(name)
    if target.is_dir():
        raise UsageError(f"{flag} = {name!r} is a directory: give a file name")
    parent = target.parent if str(target.parent) else Path(".")
    if not parent.is_dir():
        raise UsageError(f"cannot write {flag} {name}: directory {str(parent)!r} does not exist")
    made_at = file_target(name)
    if made_at is not None:  # a regular file (new or replaced) is made in its real folder: probe it
        folder = os.path.dirname(made_at)
        try:
            check_writable(folder)
        except OSError as exc:
            raise UsageError(f"cannot write {flag} {name}: cannot create files in {folder}: "
                             f"{exc.strerror or exc}") from None


def fmt(value_si: float, unit: str) -> str:
    """``value_si`` in the display ``unit`` with 6 significant digits, e.g. ``"0.4 N"``."""
    return f"{from_si(value_si, unit):.6g} {unit}".rstrip()


def flyback_label(rule) -> str:
    """A fly-back rule for people: ``"slew"``, ``"fixed"`` or a stated time in µs (``"1.5 us"``)."""
    return rule if isinstance(rule, str) else fmt(rule, "us")


def plain(obj, where: str = "result"):
    """JSON-ready: numpy scalars/arrays to Python; a non-finite float is a :class:`ResultError`."""
    if isinstance(obj, dict):
        return {str(k): plain(v, str(k)) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, np.ndarray)):
        return [plain(x, where) for x in (obj.tolist() if isinstance(obj, np.ndarray) else obj)]
    if isinstance(obj, (np.bool_, bool)):
        return bool(obj)
    if isinstance(obj, (np.integer, int)):
        return int(obj)
    if isinstance(obj, (np.floating, float)):
        if not math.isfinite(float(obj)):
            raise ResultError(f"result {where} = {float(obj)!r} is not finite: the configuration is outside "
                              "what the model can compute")
        return float(obj)
    return obj


def check_results(record: dict) -> dict:
    """Every number of a command's record finite (same check with and without ``--json``)."""
    plain(record)
    return record


def emit_json(payload: dict, out) -> None:
    out.write(json.dumps(plain(payload), indent=2, allow_nan=False) + "\n")


def emit_rows(title: str, rows: list[tuple[str, str]], out) -> None:
    out.write(title + "\n")
    width = max((len(label) for label, _ in rows), default=0)
    for label, value in rows:
        out.write(f"  {label:<{width}}  {value}\n")


def nm(values, shown: int = 8) -> str:
    """Lengths in nm; long lists show their first and last values (--json has all)."""
    text = [f"{x:.4g}" for x in from_si(np.atleast_1d(np.asarray(values, dtype=float)), "nm")]
    if len(text) > shown:
        half = shown // 2
        return f"{', '.join(text[:half])}, …, {', '.join(text[-half:])} nm ({len(text)} values)"
    return ", ".join(text) + " nm"


def sides(values, unit: str, digits: int = 5, counts=None) -> str:
    """One value, or the two sides of the six-contact drive (two and four contacts), or one per
    contact group of another arrangement (``counts``: contacts per group)."""
    arr = np.atleast_1d(np.asarray(values, dtype=float))
    text = [f"{x:.{digits}g}" for x in from_si(arr, unit)]
    if counts is not None:
        return " | ".join(f"{t} {unit} (group {g + 1}, ×{n})" for g, (t, n) in enumerate(zip(text, counts,
                                                                                         strict=True)))
    if len(text) == 2:
        return f"{text[0]} {unit} (side 1, ×2) | {text[1]} {unit} (side 2, ×4)"
    return f"{text[0]} {unit}"


def describe(drive: Drive, omit=()) -> str:
    """One line naming the drive: radius, preload, friction, contacts, actuators; ``omit``: the
    parameters a sweep varies (``"radius"``, ``"preload"``, ``"mu"``), left out."""
    parts = {"radius": f"R = {fmt(drive.hemisphere_radius, 'mm')}",
             "preload": f"F_p = {fmt(drive.preload, 'N')}", "mu": f"μ = {drive.friction_coefficient:g}"}
    return ", ".join([text for name, text in parts.items() if name not in omit]
                     + [f"{drive.contacts} contact{'s' * (drive.contacts > 1)}",
                        f"{drive.actuator_model} actuators"])


def drive_record(drive: Drive) -> dict:
    """The drive's parameters in SI, keys carrying the unit (the ``drive`` object of ``--json``)."""
    act, amp = drive.actuator, drive.amplifier
    return {
        "contacts": drive.contacts,
        "actuator_model": drive.actuator_model,
        "preload_N": drive.preload,
        "hemisphere_radius_m": drive.hemisphere_radius,
        "friction_coefficient": drive.friction_coefficient,
        "runner_mass_kg": drive.runner_mass,
        "load_cell_stiffness_N_per_m": drive.load_cell_stiffness,
        "load_cell": drive.load_cell,
        "hemisphere_youngs_modulus_Pa": drive.hemisphere_material.youngs_modulus,
        "hemisphere_poissons_ratio": drive.hemisphere_material.poissons_ratio,
        "runner_youngs_modulus_Pa": drive.runner_material.youngs_modulus,
        "runner_poissons_ratio": drive.runner_material.poissons_ratio,
        "actuator_stiffness_N_per_m": act.stiffness,
        "actuator_mass_kg": act.mass,
        "actuator_viscosity_kg_per_s": act.viscosity,
        "full_stroke_amplitude_m": act.full_stroke_amplitude,
        "amplifier_voltage_V": amp.peak_to_peak_voltage,
        "slew_rate_V_per_s": amp.slew_rate,
        "flyback": amp.flyback,  # "slew", "fixed" or a stated time in s
        **({"contact_groups": [{"count": g.count, "load_share": g.load_share,
                                "normal_force_N": g.normal_force, "radius_m": g.radius,
                                "contact_angle_rad": g.contact_angle, "side": g.side}
                               for g in drive.contact_groups]}
           if drive.contact_groups else {}),
    }
