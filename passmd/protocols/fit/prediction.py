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
