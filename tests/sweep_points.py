"""Point functions the sweep and cache tests run through :func:`passmd.runtime.sweep.run`.

They live in a module of their own (not in a test file) so that worker processes and Dask
workers can import them by name; the sweep engine itself holds no point function.
"""

from __future__ import annotations

import numpy as np

from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import Drive
from passmd.model.theory import drive_theory


def drive_theory_point(**drive_fields) -> dict:
    """Closed forms (:func:`passmd.model.theory.drive_theory`) of ``Drive(**drive_fields)``.

    A cheap, deterministic point function for sweeps over drive parameters, e.g. the
    analytic critical amplitude (Eqs. 7–8, 11–12) over a preload grid.
    """
    return drive_theory(Drive(**drive_fields))


def sawtooth_point(drive: Drive, amplitude: float, frequency: float, periods: int = 3,
                   flyback: str = "slew", springs: int | None = None) -> dict:
    """Measures of one saw-tooth run from rest (:func:`passmd.solver.simulation.simulate`).

    Returns the run's :meth:`~passmd.solver.results.SimulationResult.summary` (SI, keys
    carrying the unit; without ``periods``, which is a parameter) plus ``mean_step_m``,
    the mean of the per-period step sizes (needs ``periods >= 2``). ``springs`` None:
    exact MDR contacts, else N discrete springs.
    """
    from passmd.model import waveforms
    from passmd.solver import simulation

    wave = waveforms.sawtooth(amplitude, frequency, drive, periods=periods, flyback=flyback)
    result = simulation.simulate(drive, wave, contact_model="exact" if springs is None else "discrete",
                               springs=PROTOCOL.springs if springs is None else springs, max_points=2)
    summary = result.summary()
    del summary["periods"]  # an input of the point, already a column
    if result.step_sizes.size == 0:
        raise ValueError(f"periods = {periods!r} is out of range: a step size needs periods >= 2")
    summary["mean_step_m"] = float(np.mean(result.step_sizes))
    return summary
