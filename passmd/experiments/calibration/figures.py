"""The calibration chapter's fits: what a calibration can and cannot tell, on data with known parameters.

* :func:`comb_fit`: the actuator stiffness of one flexible contact from three steps at one preload.
  The step oscillates in k_p, so several teeth of the comb fit the data within the 95 % level: the
  region is a set of separate pieces, and the fit computes the one added measurement that would
  separate them best; that measurement, made and added, is fitted again.
* :func:`flyback_fits`: μ of one flexible contact from steps made with the fixed full-stroke
  fly-back, fitted with the slew-rate rule (a wrong fixed assumption the χ² test must reject)
  and with the right rule.

The data are made by other means than the fit's forward model
(:func:`passmd.protocols.synthetic.noisy_steps`). The chapter draws each fit with
:mod:`passmd.plots.fit` (a fit result, not a table), so :data:`FIGURES` holds no row.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from passmd.model.parameters import Drive
from passmd.model.tables import Amplifier
from passmd.protocols import fit
from passmd.protocols.fit.prediction import drive_at
from passmd.protocols.synthetic import noisy_steps
from passmd.runtime.config import RunConfig

__all__ = ["COMB", "FIGURES", "FLYBACK", "comb_fit", "flyback_fits", "join"]

#: The comb example: one flexible contact (Table 1–2, R = 1 mm), k_p = 5e6 N/m, three steps at 0.4 N,
#: 100 Hz, 1 nm noise.
COMB = {"stiffness": 5e6, "preload": 0.4, "amplitudes_nm": (120.0, 160.0, 200.0), "frequency": 100.0,
        "sd_nm": 1.0, "seed": 1, "added_seed": 2}
#: The fly-back example: one flexible contact, μ = 0.25, steps at 0.3 and 0.5 N and 100–200 nm made with
#: the fixed full-stroke fly-back, 0.5 nm noise.
FLYBACK = {"friction_coefficient": 0.25, "preloads": (0.3, 0.5), "amplitudes_nm": (100.0, 150.0, 200.0),
           "frequency": 100.0, "sd_nm": 0.5, "seed": 2, "data_rule": "fixed"}


def join(first: fit.Measurements, second: fit.Measurements) -> fit.Measurements:
    """The rows of ``first`` followed by those of ``second`` (both with or both without sd)."""
    arrays = {k: np.concatenate([getattr(first, k), getattr(second, k)])
              for k in ("value", "sd", "amplitude", "frequency", "preload", "radius")}
    last = max(first.line)
    return replace(first, kind=first.kind + second.kind, column=first.column + second.column,
                   line=first.line + tuple(last + k for k in second.line), model=first.model + second.model,
                   **arrays)


def comb_fit(config: RunConfig | None = None) -> dict:
    """The comb example (:data:`COMB`): ``{"truth", "data", "first", "row", "added", "second"}`` with
    the first fit, the row it suggests (None if none), that row made at the truth and the fit with it."""
    base = Drive(contacts=1)
    truth = drive_at(base, ["actuator.stiffness"], [COMB["stiffness"]], base.actuator.damping_ratio)
    conditions = [(COMB["preload"], a * 1e-9, COMB["frequency"]) for a in COMB["amplitudes_nm"]]
    data = noisy_steps(truth, conditions, COMB["sd_nm"], COMB["seed"], name="three steps", config=config)
    first = fit.fit(base, data, ["actuator.stiffness"], config=config)
    out = {"truth": truth, "data": data, "first": first, "row": first.next_measurement, "added": None,
           "second": None}
    row = first.next_measurement
    if row is not None:
        where = [(row["preload_N"], row["amplitude_m"], row["frequency_Hz"])]
        added = noisy_steps(truth, where, COMB["sd_nm"], COMB["added_seed"], name="added step", config=config)
        both = join(data, added)
        out.update(added=added, second=fit.fit(base, both, ["actuator.stiffness"], config=config))
    return out


def flyback_fits(config: RunConfig | None = None) -> dict:
    """The fly-back example (:data:`FLYBACK`): ``{"truth", "data", "wrong", "right"}``, the fits with the
    slew-rate rule (wrong) and with the data's fixed rule (right)."""
    base = Drive(contacts=1)
    truth = base.replace(friction_coefficient=FLYBACK["friction_coefficient"])
    conditions = [(p, a * 1e-9, FLYBACK["frequency"]) for p in FLYBACK["preloads"]
                  for a in FLYBACK["amplitudes_nm"]]
    data = noisy_steps(truth, conditions, FLYBACK["sd_nm"], FLYBACK["seed"], flyback=FLYBACK["data_rule"],
                       name="steps made with the fixed fly-back", config=config)
    wrong = fit.fit(base, data, ["friction_coefficient"], config=config)
    right = fit.fit(base.replace(amplifier=Amplifier(flyback=FLYBACK["data_rule"])), data,
                        ["friction_coefficient"], config=config)
    return {"truth": truth, "data": data, "wrong": wrong, "right": right}


#: The chapter's rows of the figure table: none (its figures draw fit results, :mod:`passmd.plots.fit`).
FIGURES = ()
