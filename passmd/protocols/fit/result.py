"""What a calibration returns: :class:`~passmd.protocols.fit.result.FitResult`, the identifiability verdict
and the fitted drive file.

:class:`FitResult` holds the fitted drive, each estimate with its standard error and 95 %
profile interval, the correlation matrix and the residuals; its verdict says which parameters
the data do not determine (flat profile, rank-deficient Jacobian, or a correlation above
:data:`CORRELATION_LIMIT`) and what data would help. :func:`fitted_drive_file` writes the fitted
drive as a drive file that names the data as the fitted keys' source.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from passmd.model.parameters import Drive
from passmd.protocols.fit.measurements import (
    Measurements,
)

__all__ = ['CORRELATION_LIMIT', 'FitResult', 'fitted_drive_file']

#: The absolute correlation above which two free parameters are reported as not separable by the data.
#: 0.95: their joint confidence region is then a ridge at least (1+0.95)/(1−0.95) ≈ 6 times
#: longer than wide (eigenvalue ratio of the 2×2 correlation matrix; its axes √39 ≈ 6.2).
CORRELATION_LIMIT = 0.95


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


def fitted_drive_file(drive: Drive, data_name: str, free: Sequence[str]) -> str:
    """The fitted drive as a drive file (:func:`passmd.model.drive_file.drive_toml`) that ``--drive`` and
    :func:`passmd.model.drive_file.load_drive` read back; the fitted keys name the data (``data_name``)
    as their source. ``free``: the fitted parameters' names
    (:data:`~passmd.protocols.fit.free_parameters.FREE_PARAMETERS`)."""
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
