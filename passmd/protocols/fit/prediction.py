"""The model's value of a measurement: one simulation protocol per measured quantity, run as a sweep.

:func:`predict_point` runs the protocol a measured quantity needs (step, velocity, critical
amplitude, stall force or position) for one drive and condition; :func:`predict` evaluates every
row of a :class:`~passmd.protocols.fit.measurements.Measurements` through
:func:`passmd.runtime.sweep.run` (parallel and cached). The estimator's model of the free
parameters builds on the same points.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from passmd.model.parameters import Drive, check_drive
from passmd.model.tables import actuator_for_radius
from passmd.protocols.fit.free_parameters import FREE_PARAMETERS
from passmd.protocols.fit.measurements import (
    READINGS,
    Measurements,
)
from passmd.runtime import sweep
from passmd.runtime.config import RunConfig
from passmd.runtime.validation import check_choice

__all__ = ['predict', 'predict_point']

#: Largest relative drift of a steady-velocity run (its fourth quarter against its third) whose
#: velocity counts as steady; a larger one marks the prediction unsettled.
STEADY_DRIFT = 0.01


def predict_point(drive: Drive, kind: str, amplitude: float, frequency: float, reading: str) -> dict:
    """The model's value of one measurement (SI), a sweep function: ``{"prediction": value,
    "settled": bool}`` (``settled`` False: a step or velocity that had not settled by the end of its
    run, module docstring of :mod:`passmd.protocols.fit.measurements`)."""
    from passmd.protocols import velocity

    if kind == "position":
        run = velocity.step_run(drive, amplitude, frequency, "sawtooth")
        return {"prediction": float(run["final_position_m"]), "settled": True}
    if kind in ("step", "velocity"):  # of a running drive: settled below STEP_PROTOCOL_BELOW, else steady
        if frequency < velocity.STEP_PROTOCOL_BELOW:
            run = velocity.settled_step(drive, amplitude, frequency)
            step, settled = run["step_m"], run["settled"]
        else:
            run = velocity.steady_run(drive, amplitude, frequency, "sawtooth", "cut")
            step, settled = run["step_m"], abs(run["velocity_drift"]) <= STEADY_DRIFT
        return {"prediction": float(step if kind == "step" else step * frequency), "settled": bool(settled)}
    if kind == "critical_amplitude":
        from passmd.protocols import critical_amplitude as ca

        found = ca.critical_amplitude(drive, protocol=reading, frequency=frequency, progress=False)
        value = found["critical_amplitude_m"]
        return {"prediction": float(found["bracket_low_m"] if math.isnan(value) else value), "settled": True}
    from passmd.protocols import stall

    found = stall.generated_force(replace(drive, load_cell=True), amplitude, frequency, progress=False)
    return {"prediction": float(found["generated_force_N"]), "settled": bool(found["converged"])}


def _row_drive(drive: Drive, data: Measurements, i: int) -> Drive:
    """Row i's drive: ``drive`` at the row's preload, radius (Table 2 actuator for another radius),
    number of contacts and actuator model, where the row gives them."""
    changes = dict(data.model[i]) if data.model else {}
    if math.isfinite(data.preload[i]):
        changes["preload"] = float(data.preload[i])
    radius = data.radius[i]
    if math.isfinite(radius) and not math.isclose(radius, drive.hemisphere_radius, rel_tol=1e-12):
        changes["hemisphere_radius"] = float(data.radius[i])
        changes["actuator"] = actuator_for_radius(float(data.radius[i]))
    return replace(drive, **changes) if changes else drive


def _row_drives(drive: Drive, data: Measurements) -> list[Drive]:
    """Each row's drive (:func:`_row_drive`)."""
    return [_row_drive(drive, data, i) for i in range(len(data))]


class _Model:
    """Predictions of all rows at parameter vectors (log space), through the sweep engine."""

    def __init__(self, drive, data, names, reading, *, executor, cache, config, keep="damping_ratio"):
        self.drive, self.data, self.names, self.reading = drive, data, names, reading
        self.executor, self.cache, self.config, self.keep = executor, cache, config, keep
        self.params = sorted((FREE_PARAMETERS[n] for n in names), key=lambda p: p.order)
        self.index = {n: k for k, n in enumerate(names)}
        self.rows = _row_drives(replace(drive, allow_extrapolation=True), data)
        self.memo: dict[bytes, np.ndarray] = {}
        self.settled: dict[bytes, np.ndarray] = {}
        self.simulations = 0
        self.evaluations = 0
        # the damping ratio a moving k_p or m_a keeps (keep="damping_ratio", unless the damping is free)
        self.zeta = None
        damping = {"actuator.viscosity", "actuator.damping_ratio"}
        moving = {"actuator.stiffness", "actuator.mass"} & set(names)
        if keep == "damping_ratio" and not damping & set(names) and moving:
            self.zeta = drive.actuator.damping_ratio

    def drive_at(self, x, base: Drive) -> Drive:
        d = base
        for p in self.params:
            d = p.set(d, float(np.exp(x[self.index[p.name]])), base)
        if self.zeta is not None:
            act = d.actuator
            viscosity = 2.0 * self.zeta * math.sqrt(act.stiffness * act.mass)
            d = replace(d, actuator=replace(act, viscosity=viscosity))
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
            settled = frame["settled"].to_numpy(bool).reshape(len(todo), len(self.rows))
            for k, v, s in zip(todo, values, settled, strict=True):
                self.memo[k] = v
                self.settled[k] = s
            self.simulations += frame.attrs["sweep"]["computed"]
            self.evaluations += len(todo)
        return [self.memo[k] for k in keys]


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
