"""Measurements made by other means than the fit's forward model (the calibration chapters' data and the
fit's tests and benchmarks).

A fit checked only on data its own forward model made hides what the model and the data do not
share (a protocol, a resolution, a fixed assumption). :func:`independent_steps` makes steps another
way: the integrator refined (:data:`REFINE`: ``scheme`` "controlled" at half the step and a 16×
tighter local error), a run of :data:`PERIODS` periods from rest and its *last* step (not the
fit's settled-step protocol), optionally with another fly-back rule than the drive's (the
mis-specified model a goodness-of-fit test must reject). :func:`noisy_steps` adds Gaussian noise of
a stated sd and writes the rows as a measurement file would.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from passmd.model.parameters import Drive
from passmd.model.waveforms import sawtooth
from passmd.protocols import fit
from passmd.runtime import sweep
from passmd.runtime.config import RunConfig
from passmd.solver import simulation
from passmd.solver.steps import SCHEMES

__all__ = ["PERIODS", "REFINE", "independent_step", "independent_steps", "noisy_steps"]

#: Refinement of the integrator for the independent data (steps halved, local error 16× tighter).
REFINE = 2.0
#: Periods of the independent data's runs from rest; their last step is the measurement.
PERIODS = 16


def independent_step(drive: Drive, amplitude: float, frequency: float, periods: int = PERIODS,
                     refine: float = REFINE, flyback=None) -> dict:
    """The last step of a ``periods``-period saw-tooth run from rest with the refined integrator (a sweep
    function): ``{"step_m": ...}``."""
    wave = sawtooth(amplitude, frequency, drive, periods=periods, flyback=flyback)
    scheme = SCHEMES["controlled"].replace(refine=refine)
    result = simulation.simulate(drive, wave, scheme=scheme, max_points=2)
    return {"step_m": float(result.step_sizes[-1])}


def independent_steps(drive: Drive, conditions, *, flyback=None, config: RunConfig | None = None,
                      executor: str | None = "serial", cache=False) -> np.ndarray:
    """Steps (m) at ``conditions`` = [(preload N, amplitude m, frequency Hz), ...] of ``drive`` made by
    :func:`independent_step` (``flyback`` overrides the drive's rule), through the sweep engine."""
    points = [{"drive": replace(drive, preload=float(p)), "amplitude": float(a), "frequency": float(f),
               "periods": PERIODS, "refine": REFINE, "flyback": flyback} for p, a, f in conditions]
    frame = sweep.run(independent_step, points, executor=executor, cache=cache, progress=False, config=config)
    return frame["step_m"].to_numpy(float)


def noisy_steps(drive: Drive, conditions, sd_nm: float, seed: int, *, flyback=None, name: str = "data",
                config: RunConfig | None = None, executor: str | None = "serial", cache=False
                ) -> fit.Measurements:
    """:func:`independent_steps` plus Gaussian noise of ``sd_nm`` (numpy's default generator, ``seed``), as
    measurements with that sd stated (``step_nm``, ``step_nm_sd``)."""
    exact = independent_steps(drive, conditions, flyback=flyback, config=config, executor=executor,
                              cache=cache)
    noisy = exact + np.random.default_rng(seed).normal(0.0, sd_nm * 1e-9, exact.size)
    header = ["amplitude_nm", "preload_N", "frequency_Hz", "step_nm", "step_nm_sd"]
    rows = [[repr(float(a * 1e9)), repr(float(p)), repr(float(f)), repr(float(v * 1e9)), repr(float(sd_nm))]
            for (p, a, f), v in zip(conditions, noisy, strict=True)]
    return fit.measurements_from_rows(header, rows, name=name)
