"""The drive parameters a calibration may free, and their default search ranges.

:data:`FREE_PARAMETERS` names each by the drive field it sets (dotted for a part, e.g.
``actuator.stiffness``) or a derived one (``contact_stiffness_scale``, ``flyback_time``), with how
it is read from and written into a :class:`~passmd.model.parameters.Drive` and its default bounds
(:func:`default_bounds`), taken from the plausible ranges of the parameter records.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import PLAUSIBLE_RANGES, Drive, check_drive
from passmd.runtime.validation import InputError

__all__ = ['FREE_PARAMETERS', 'KEEPS', 'FreeParameter', 'default_bounds', 'plausible_bounds']

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
    quarter = 0.25 / f_max if f_max > 0 else math.inf  # a fly-back within a quarter period
    return v / sr.soft_high, min(v / sr.soft_low, quarter)


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
#: What stays fixed of the actuator's damping when k_p or m_a is fitted (``fit(..., keep=...)``):
#: the damping ratio ζ (c_p = 2ζ√(k_p m_a) follows, as a drive file derives it) or the viscosity c_p.
KEEPS = ("damping_ratio", "viscosity")
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
        if name in ("flyback_time", "amplifier.slew_rate") and not isinstance(drive.amplifier.flyback, str):
            raise InputError(f"free = {name!r} has no effect: the drive's fly-back is a stated time "
                             f"({drive.amplifier.flyback:.4g} s, amplifier.flyback); give it the rule 'slew' "
                             "or 'fixed' to fit the slew rate", name="free", value=name)
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


def plausible_bounds(drive: Drive, name: str) -> tuple[float, float]:
    """The widest (low, high) of a free parameter without ``allow_extrapolation``: its plausible range
    (:data:`~passmd.model.parameters.PLAUSIBLE_RANGES`), as :func:`default_bounds` without the limit
    the data's frequencies set (the fly-back within a quarter period, checked row by row)."""
    low, high = FREE_PARAMETERS[name].bounds(drive, 0.0)
    return float(low), float(high)
