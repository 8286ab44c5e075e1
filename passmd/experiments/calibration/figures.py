"""The calibration chapter's fits: what a calibration can and cannot tell, on data with known parameters.

* :func:`comb_fit`: the actuator stiffness of one flexible contact from three steps at one preload.
  The step oscillates in k_p, so several teeth of the comb fit the data within the 95 % level: the
  region is a set of separate pieces, and the fit computes the one added measurement that would
  separate them best; that measurement, made and added, is fitted again.
* :func:`flyback_fits`: μ of one flexible contact from steps made with the fixed full-stroke
  fly-back, fitted with the slew-rate rule (a wrong fixed assumption the χ² test must reject)
  and with the right rule.

* :func:`paper_fit`: one unknown of the paper fitted to the numbers its text states
  (:data:`PAPER_DATA`), each held to the tolerance of the ledger's claim on it (:func:`paper_measurements`).

The comb's and the fly-back's data are made by other means than the fit's forward model
(:func:`passmd.protocols.synthetic.noisy_steps`). :data:`FIGURES` holds a row per figure the chapter
shows: a fit's tables (:meth:`~passmd.protocols.fit.result.FitResult.profile_table`, :func:`fit_table`),
drawn by :mod:`passmd.plots.fit`; the ledger computes none of them (no claim requires them).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd

from passmd.experiments import FigureSpec
from passmd.ledger.claims import load_claims
from passmd.ledger.reference import REFERENCE_DIR
from passmd.model.parameters import Drive
from passmd.model.tables import Amplifier
from passmd.protocols import fit
from passmd.protocols.fit.prediction import drive_at
from passmd.protocols.synthetic import noisy_steps
from passmd.runtime.config import RunConfig

__all__ = ["COMB", "FIGURES", "FLYBACK", "PAPER_DATA", "PAPER_DATA_CLAIMS", "PAPER_TITLE", "WRONG_TITLE",
           "comb_fit", "comb_profile", "fit_table", "flyback_fits", "join", "paper_fit", "paper_measurements"]

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


#: The paper's stated numbers as measurements (rules in ``passmd/data/reference/README.md``).
PAPER_DATA = REFERENCE_DIR / "paper_as_data.csv"
#: The ledger's claim on the same number as each row of :data:`PAPER_DATA` (by the row's ``id``): the
#: book's fits hold each number to the tolerance the ledger judges it with (:func:`paper_measurements`).
PAPER_DATA_CLAIMS = {"fig5a-critical-amplitude-50nm": "fig5a-no-step-below-50nm",
                     "fig9a-standard-position-552nm": "fig9a-standard-position-552nm"}


def paper_measurements() -> fit.Measurements:
    """:data:`PAPER_DATA` with each row's standard deviation the tolerance of the ledger's claim on the same
    number (:data:`PAPER_DATA_CLAIMS`; an absolute tolerance in the claim's unit, or a relative one times
    the stated value), so that a fit and the ledger hold the paper's numbers to one tolerance."""
    data = fit.read_measurements(PAPER_DATA)
    ids = pd.read_csv(PAPER_DATA, dtype=str)["id"].tolist()
    claims = load_claims().set_index("id")
    sd = np.array(data.sd, dtype=float)
    for i, row_id in enumerate(ids):
        claim = claims.loc[PAPER_DATA_CLAIMS[row_id]]
        scale, unit = data.display(i)
        if claim["tolerance_kind"] == "rel":
            sd[i] = float(claim["tolerance_num"]) * data.value[i]
        elif claim["tolerance_kind"] == "abs" and claim["unit"] == unit:
            sd[i] = float(claim["tolerance_num"]) * scale
        else:
            raise ValueError(f"claim {claim.name!r}: its tolerance ({claim['tolerance_kind']}, "
                             f"{claim['unit']}) is not one a row in {unit} can take")
    return replace(data, sd=sd)
#: Titles of the fit figures: the rejected fly-back fit, and μ fitted to the paper's numbers.
WRONG_TITLE = "Steps made with the fixed fly-back against the model with the slew-rate fly-back (μ fitted)"
PAPER_TITLE = "Paper's numbers against the model with the fitted μ (others at the book's defaults)"


def paper_fit(name: str, config: RunConfig | None = None) -> fit.FitResult:
    """The parameter ``name`` of the book's default drive fitted alone to the paper's numbers
    (:func:`paper_measurements`)."""
    return fit.fit(Drive(), paper_measurements(), [name], config=config)


def comb_profile(result: fit.FitResult) -> pd.DataFrame:
    """The profile of k_p of a comb fit, with the k_p that made the data (:data:`COMB`)."""
    table = result.profile_table("actuator.stiffness")
    table.attrs["truth"] = COMB["stiffness"]
    return table


def fit_table(result: fit.FitResult, title: str) -> pd.DataFrame:
    """A fit's :meth:`~passmd.protocols.fit.result.FitResult.residual_table` drawn under ``title``."""
    table = result.residual_table()
    table.attrs["title"] = title
    return table


#: The chapter's rows of the figure table: every figure it shows.
FIGURES = (
    FigureSpec("calibration_comb_profile", "Profile of k_p from three steps: a comb of minima, a region in "
               "pieces", "calibration", lambda c: comb_profile(comb_fit(c)["first"]), "fit:profile_figure"),
    FigureSpec("calibration_comb_profile_added", "Profile of k_p with the added measurement the first fit "
               "named", "calibration", lambda c: comb_profile(comb_fit(c)["second"]), "fit:profile_figure"),
    FigureSpec("calibration_wrong_flyback", "Steps made with the fixed fly-back, fitted with the slew-rate "
               "one: a rejected fit", "calibration",
               lambda c: fit_table(flyback_fits(c)["wrong"], WRONG_TITLE), "fit:fit_figure"),
    FigureSpec("calibration_paper_mu", "The paper's stated numbers against the model with μ fitted to them",
               "calibration", lambda c: fit_table(paper_fit("friction_coefficient", c), PAPER_TITLE),
               "fit:fit_figure"),
)
