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

__all__ = ['SPLIT_BELOW_SETS_PER_WORKER', 'predict', 'predict_point', 'row_parts']

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
        from passmd.protocols import critical_amplitude

        found = critical_amplitude.critical_amplitude(drive, protocol=reading, frequency=frequency,
                                                      progress=False)
        value = found["critical_amplitude_m"]
        return {"prediction": float(found["bracket_low_m"] if math.isnan(value) else value), "settled": True}
    from passmd.protocols import stall

    found = stall.generated_force(replace(drive, load_cell=True), amplitude, frequency, progress=False)
    return {"prediction": float(found["generated_force_N"]), "settled": bool(found["converged"])}


def _row_changes(drive: Drive, data: Measurements, i: int) -> dict:
    """What row i changes of ``drive``: its preload, radius (with Table 2's actuator for another
    radius), number of contacts and actuator model, where the row gives them."""
    changes = dict(data.model[i]) if data.model else {}
    if math.isfinite(data.preload[i]):
        changes["preload"] = float(data.preload[i])
    radius = data.radius[i]
    if math.isfinite(radius) and not math.isclose(radius, drive.hemisphere_radius, rel_tol=1e-12):
        changes["hemisphere_radius"] = float(radius)
        changes["actuator"] = actuator_for_radius(float(radius))
    return changes


def _row_drive(drive: Drive, data: Measurements, i: int) -> Drive:
    """Row i's drive (:func:`_row_changes` applied to ``drive``)."""
    changes = _row_changes(drive, data, i)
    return replace(drive, **changes) if changes else drive


def _row_drives(drive: Drive, data: Measurements) -> list[Drive]:
    """Each row's drive (:func:`_row_drive`)."""
    return [_row_drive(drive, data, i) for i in range(len(data))]


def drive_at(base: Drive, names: Sequence[str], values: Sequence[float], zeta: float | None) -> Drive:
    """``base`` with the free parameters ``names`` at ``values`` (SI; applied in their order), and, when
    ``zeta`` is given, the viscosity 2ζ√(k_p m_a) of the new k_p and m_a (the damping ratio held)."""
    d = base
    for p in sorted((FREE_PARAMETERS[n] for n in names), key=lambda p: p.order):
        d = p.set(d, float(values[list(names).index(p.name)]), base)
    if zeta is not None:
        act = d.actuator
        d = replace(d, actuator=replace(act, viscosity=2.0 * zeta * math.sqrt(act.stiffness * act.mass)))
    return d


def predict_set(drive: Drive, names: tuple, values: tuple, zeta: float | None, rows: tuple, reading: str
                ) -> dict:
    """The model's value of every row of ``rows`` at one parameter set (a sweep function: one cache entry
    per set and rows).

    ``rows``: per measurement ``(kind, amplitude, frequency, changes)``, ``changes`` the row's
    changes of the drive as (field, value) pairs (:func:`_row_changes`). Returns ``predictions``
    (SI) and ``settled`` per row (:func:`predict_point`).
    """
    at = drive_at(drive, names, values, zeta)
    predictions, settled = [], []
    drives: dict[tuple, Drive] = {}  # rows of the same conditions (say, one preload) share their drive
    for kind, amplitude, frequency, changes in rows:
        row = drives.get(changes)
        if row is None:
            given = dict(changes)
            if "actuator" in given:  # another radius: Table 2's actuator, then the fitted values on it
                row = drive_at(replace(drive, **given), names, values, zeta)
            else:
                row = replace(at, **given) if given else at
            drives[changes] = row
        out = predict_point(row, kind, amplitude, frequency, reading if kind == "critical_amplitude" else "")
        predictions.append(out["prediction"])
        settled.append(out["settled"])
    return {"predictions": predictions, "settled": settled}


#: A batch of fewer than this many parameter sets per worker has each set's rows split into parts,
#: one sweep point each (:func:`row_parts`); larger batches keep the workers busy with whole sets.
SPLIT_BELOW_SETS_PER_WORKER = 4


def row_parts(sets: int, rows: int, workers: int) -> int:
    """Parts to split each of ``sets`` parameter sets' ``rows`` rows into for ``workers`` workers.

    A fit evaluates a few sets at a time (a Jacobian, a profile's inner steps); one point per set
    then leaves workers idle while the last sets finish. The parts: the fewest (at least
    ``workers / sets``) that make the number of points a multiple of ``workers``, at most one per
    row; 1 for one worker or a batch of at least :data:`SPLIT_BELOW_SETS_PER_WORKER` sets per
    worker. Every row is simulated on its own, so the predictions do not depend on the parts.
    """
    if workers <= 1 or rows <= 1 or sets >= SPLIT_BELOW_SETS_PER_WORKER * workers:
        return 1
    least = min(rows, -(-workers // sets))
    for parts in range(least, rows + 1):
        if sets * parts % workers == 0:
            return parts
    return least


def _row_slices(rows: int, parts: int) -> list[slice]:
    """``parts`` contiguous slices of ``rows`` rows, sizes differing by at most one."""
    bounds = [round(k * rows / parts) for k in range(parts + 1)]
    return [slice(a, b) for a, b in zip(bounds[:-1], bounds[1:], strict=True)]


def _workers(executor, config: RunConfig) -> int:
    """Workers a sweep on ``executor`` runs: the pool's, one for ``"serial"``, else as
    :func:`passmd.runtime.sweep.run` counts them."""
    from passmd.runtime.config import MAX_WORKERS, useful_workers

    if executor == "serial":
        return 1
    pool = getattr(executor, "_max_workers", None)  # a concurrent.futures pool
    if isinstance(pool, int) and pool >= 1:
        return pool
    return useful_workers(config.workers, MAX_WORKERS)


class _Model:
    """Predictions of all rows at parameter vectors (log space), through the sweep engine: one sweep
    point (and cache entry) per parameter vector, or per part of its rows in a small batch
    (:func:`row_parts`)."""

    def __init__(self, drive, data, names, reading, *, executor, cache, config, keep="damping_ratio"):
        self.drive, self.data, self.names, self.reading = drive, data, list(names), reading
        self.executor, self.cache, self.config, self.keep = executor, cache, config, keep
        self.base = replace(drive, allow_extrapolation=True)
        rows = [(data.kind[i], float(np.nan_to_num(data.amplitude[i])), float(data.frequency[i]),
                 tuple(sorted(_row_changes(self.base, data, i).items()))) for i in range(len(data))]
        # identical conditions (repeated measurements) are simulated once: each row reads its
        # condition's prediction
        index = {row: k for k, row in enumerate(dict.fromkeys(rows))}
        self.rows = tuple(index)
        self.row_of = np.array([index[row] for row in rows], dtype=int)
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
        """``base`` at the log-parameter vector x."""
        return drive_at(base, self.names, np.exp(np.asarray(x, float)).tolist(), self.zeta)

    def evaluate(self, xs: Sequence[np.ndarray]) -> list[np.ndarray]:
        """Predictions (SI, one array per vector); vectors already computed come from memory."""
        keys = [np.asarray(x, float).tobytes() for x in xs]
        todo = list(dict.fromkeys(k for k in keys if k not in self.memo))
        if todo:
            config = self.config if self.config is not None else RunConfig()
            parts = _row_slices(len(self.rows), row_parts(len(todo), len(self.rows),
                                                          _workers(self.executor, config)))
            points = [{"drive": self.base, "names": tuple(self.names),
                       "values": tuple(np.exp(np.frombuffer(k)).tolist()), "zeta": self.zeta,
                       "rows": self.rows[part], "reading": self.reading} for k in todo for part in parts]
            frame, cached = sweep.run_with_hits(predict_set, points, executor=self.executor, cache=self.cache,
                                                progress=False, config=self.config)
            predictions, settled = frame["predictions"].tolist(), frame["settled"].tolist()
            for i, k in enumerate(todo):
                mine = range(i * len(parts), (i + 1) * len(parts))
                self.memo[k] = np.concatenate([np.asarray(predictions[j], float) for j in mine])[self.row_of]
                self.settled[k] = np.concatenate([np.asarray(settled[j], bool) for j in mine])[self.row_of]
            self.simulations += sum(len(points[j]["rows"]) for j in range(len(points)) if j not in cached)
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
    distinct = list({_point_key(p): p for p in points}.values())  # identical conditions: simulated once
    frame = sweep.run(predict_point, distinct, executor=executor, cache=cache, progress=False, config=config)
    value = dict(zip((_point_key(p) for p in distinct), frame["prediction"].to_numpy(float), strict=True))
    return np.array([value[_point_key(p)] for p in points], dtype=float)


def _point_key(point: dict) -> tuple:
    return tuple((k, repr(v)) for k, v in sorted(point.items()))
