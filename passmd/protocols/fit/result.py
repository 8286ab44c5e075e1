"""What a calibration returns: :class:`~passmd.protocols.fit.result.FitResult`, the goodness of fit, the
identifiability verdict and the fitted drive file.

:class:`FitResult` holds the fitted drive, each estimate with its local standard error, its 95 %
region (the pieces of its profile within the χ² quantile, their hull, the basins inside), the
correlation matrix, the residuals and the goodness-of-fit test (:func:`goodness_of_fit`). Its
verdict (:func:`verdict`) says when the model does not describe the data (then no interval is
calibrated), which parameters the data do not determine (a region reaching a bound, or several
separate pieces) and which measurement would help. :func:`fitted_drive_file` writes the fitted drive
as a drive file whose every value names its source.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from passmd.model.parameters import Drive
from passmd.protocols.fit.measurements import (
    Measurements,
)

__all__ = ['CORRELATION_LIMIT', 'REJECT_P', 'FitResult', 'fitted_drive_file', 'goodness_of_fit', 'verdict']

#: The absolute correlation above which two free parameters are reported as traded off against each
#: other: their joint confidence region is then a ridge at least (1+0.95)/(1−0.95) ≈ 6 times longer
#: than wide (eigenvalue ratio of the 2×2 correlation matrix; its axes √39 ≈ 6.2). The profile
#: regions account for it; the verdict names the pair and the remedy.
CORRELATION_LIMIT = 0.95
#: Below this p-value of the χ² test the model is taken not to describe the data (a 1 % test: a
#: right model is rejected in 1 % of data sets).
REJECT_P = 0.01


@dataclass
class FitResult:
    """The fitted drive, the estimates with their uncertainties and the identifiability verdict."""

    drive: Drive  # the fitted drive (the given drive with the estimates)
    base: Drive  # the drive the fit started from
    names: list[str]  # free parameters, in the order given
    # name -> value, stderr (local), interval (the region's hull), intervals (its pieces), basins,
    # profile {value, cost}, unit (SI), symbol, bounds, flat_profile
    estimates: dict[str, dict]
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
    converged: bool = True  # False: a lower point than the estimate turned up after the last search
    goodness_of_fit: dict = field(default_factory=dict)  # goodness_of_fit(): chi2, dof, p_value, ...
    next_measurement: dict | None = None  # the added row that best separates several basins
    keep: str = "damping_ratio"  # what of the damping stayed fixed while k_p or m_a moved
    basins: list[dict] = field(default_factory=list)  # every basin within the level: parameters, cost
    level: float = math.nan  # the 95 % rise of a profile in units of s² (the estimator sets it)
    # the fitted drives at the ends of each parameter's 95 % region, the others re-fitted there (its
    # extreme points): name -> value (SI) of every free parameter; predictions span the region with them
    region_points: list[dict] = field(default_factory=list)

    def region_drives(self) -> list[Drive]:
        """The drives at ``region_points`` (as ``drive`` is the drive at the estimate)."""
        from passmd.protocols.fit.prediction import drive_at

        zeta = self.base.actuator.damping_ratio if self._holds_zeta() else None
        out = []
        for point in self.region_points:
            at = drive_at(self.base, self.names, [point[n] for n in self.names], zeta)
            out.append(replace(at, allow_extrapolation=self.drive.allow_extrapolation))
        return out

    def _holds_zeta(self) -> bool:
        """Whether ζ stayed fixed while k_p or m_a moved (as the fit's model held it)."""
        moving = any(n in self.names for n in ("actuator.stiffness", "actuator.mass"))
        free_damping = any(n in self.names for n in ("actuator.viscosity", "actuator.damping_ratio"))
        return self.keep == "damping_ratio" and moving and not free_damping

    @property
    def model_rejected(self) -> bool:
        """Whether the χ² test rejects the model (σ given, p below :data:`REJECT_P`)."""
        return bool(self.goodness_of_fit.get("rejected", False))

    @property
    def residuals(self) -> np.ndarray:
        """(measured − predicted) / σ per row."""
        return (self.data.value - self.predicted) / self.weights

    def residual_table(self) -> pd.DataFrame:
        """One row per measurement, values in its column's display unit (``unit``): the preload (the
        drive's where the row gives none), the frequency, the amplitude (nm), measured, sd, predicted
        and the normalised residual. ``attrs``: the ``estimates`` (name -> value, SI) and
        ``goodness_of_fit``."""
        data = self.data
        scale, unit = zip(*(data.display(i) for i in range(len(data))), strict=True)
        table = pd.DataFrame({
            "line": data.line, "quantity": data.column, "kind": data.kind, "unit": unit,
            "preload_N": np.where(np.isfinite(data.preload), data.preload, self.base.preload),
            "frequency_Hz": data.frequency,
            "amplitude_nm": data.amplitude * 1e9, "measured": data.value / scale, "sd": data.sd / scale,
            "predicted": self.predicted / scale, "normalized_residual": self.residuals})
        table.attrs.update(estimates={n: self.estimates[n]["value"] for n in self.names},
                           goodness_of_fit=dict(self.goodness_of_fit))
        return table

    def profile_table(self, name: str) -> pd.DataFrame:
        """The profile of the free parameter ``name``: ``value`` (SI), ``cost`` and ``rise`` (the cost
        above the minimum in units of s²). ``attrs``: ``parameter``, ``unit``, ``level`` (the 95 %
        rise), ``intervals`` (the region's pieces) and ``basins`` (their values)."""
        est = self.estimates[name]
        table = pd.DataFrame({"value": est["profile"]["value"], "cost": est["profile"]["cost"]})
        table["rise"] = (table["cost"] - self.cost) / self.scale ** 2
        table.attrs.update(parameter=name, unit=est["unit"], level=self.level,
                           intervals=[tuple(piece) for piece in est["intervals"]],
                           basins=[basin["value"] for basin in est["basins"]])
        return table

    def report(self) -> dict:
        """The JSON report (SI units; keys as the command line's --json)."""
        rows = self.residual_table()[["line", "quantity", "measured", "predicted", "unit",
                                      "normalized_residual"]].to_dict("records")
        return {
            "estimates": {n: {k: v for k, v in self.estimates[n].items()} for n in self.names},
            "residuals": rows,
            "correlation": {"parameters": list(self.names), "matrix": self.correlation.tolist(),
                            "limit": CORRELATION_LIMIT},
            "identifiable": self.identifiable,
            "model_rejected": self.model_rejected,
            "goodness_of_fit": dict(self.goodness_of_fit),
            "basins": list(self.basins),
            "next_measurement": self.next_measurement,
            "keep": self.keep,
            "level": self.level,
            "region_points": list(self.region_points),
            "flyback": self.drive.amplifier.flyback,
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
        other = {"step": dynamic, "velocity": dynamic, "position": dynamic,
                 "critical_amplitude": "steps against amplitude", "force": "steps against amplitude"}
        tips.append(f"another kind of measurement ({other[data.kind[0]]})")
    amps = data.amplitude[np.isfinite(data.amplitude)]
    if amps.size and amps.max() < 1.5 * amps.min():
        tips.append("a wider range of amplitudes")
    if not tips:
        return "add measurements at other preloads, frequencies or amplitudes"
    return "add " + ", ".join(tips)


def goodness_of_fit(cost: float, dof: int, known_sd: bool) -> dict:
    """The χ² test of the minimum: with stated σ the minimum cost follows χ² with ``dof`` degrees of
    freedom when the model is right; ``p_value`` is its upper tail (``scipy.stats.chi2.sf``) and
    ``rejected`` is p < :data:`REJECT_P`. Without σ the residual scale is estimated from the same
    residuals and no test can be made (``p_value`` None)."""
    from scipy import stats

    if not known_sd:
        return {"chi2": None, "dof": dof, "p_value": None, "testable": False, "rejected": False}
    p = float(stats.chi2.sf(cost, dof))
    return {"chi2": float(cost), "dof": dof, "p_value": p, "testable": True, "rejected": p < REJECT_P}


def _fixed(drive: Drive, names, keep: str) -> str:
    """What the model holds fixed that could explain a misfit."""
    rule = drive.amplifier.flyback
    shown = {"slew": "'slew' (slew-rate limited, (A/A_max)·V_pp/SR)",
             "fixed": "'fixed' (the full-stroke V_pp/SR)"}
    flyback = shown[rule] if isinstance(rule, str) else f"a stated {rule * 1e6:.4g} µs"
    held = [label for key, label in (("friction_coefficient", "μ"), ("actuator.stiffness", "k_p"),
                                     ("actuator.mass", "m_a"), ("actuator.damping_ratio", "ζ"),
                                     ("runner_mass", "m_r"), ("contact_stiffness_scale", "E_1, E_2"))
            if key not in names and not (key == "actuator.damping_ratio" and "actuator.viscosity" in names)]
    if drive.actuator_model == "rigid":
        held = [h for h in held if h not in ("k_p", "m_a", "ζ")]
    moving = {"actuator.stiffness", "actuator.mass"} & set(names) and not {
        "actuator.viscosity", "actuator.damping_ratio"} & set(names)
    held_text = ", ".join(held)
    if moving:
        held_text += f"; while k_p or m_a moves, {keep.replace('_', ' ')} stays"
    return (f"the fly-back rule ({flyback}; --flyback), the reading of each measured quantity (a step or "
            "velocity is the settled one of a running drive; position_nm a run of three periods from rest), "
            f"the parameters held fixed ({held_text}), the {drive.contacts}-contact arrangement and the "
            f"{drive.actuator_model} actuators")


def _pieces_text(est: dict) -> str:
    unit = f" {est['unit']}" if est["unit"] else ""
    return ", ".join(f"{a:.4g}–{b:.4g}{unit}" for a, b in est["intervals"])


def _separation(suggestion: dict | None, data: Measurements) -> str:
    if not suggestion:
        return _advice(data)
    scale = {"step": (1e-9, "nm"), "velocity": (1e-3, "mm/s"), "position": (1e-9, "nm"), "force": (1.0, "N"),
             "critical_amplitude": (1e-9, "nm")}[suggestion["kind"]]
    values = ", ".join(f"{v / scale[0]:.4g}" for v in suggestion["predictions"])
    amplitude = suggestion["amplitude_m"]
    where = f"A = {amplitude * 1e9:.4g} nm, " if np.isfinite(amplitude) else ""
    return (f"the one added measurement that would separate them best is {suggestion['column']} at {where}"
            f"F_p = {suggestion['preload_N']:.4g} N, f = {suggestion['frequency_Hz']:.4g} Hz (predicted "
            f"{values} {scale[1]} at the basins; it would exclude {suggestion['excluded']} of "
            f"{suggestion['pairs']} basin pairs at its σ)")


def verdict(names, estimates, corr, rank, data, gof, converged, suggestion, drive, keep) -> tuple[bool, str]:
    """(identifiable, text): the goodness of fit, then what the data do not determine and what would."""
    sentences, bad = [], set()
    advice = _advice(data)
    if gof.get("testable"):
        test = f"χ² = {gof['chi2']:.4g} on {gof['dof']} degrees of freedom, p = {gof['p_value']:.3g}"
        if gof["rejected"]:
            sentences.append(f"The model does not describe the data ({test} < {REJECT_P:g}): no interval is "
                             "calibrated. What the model holds fixed may be wrong: "
                             f"{_fixed(drive, names, keep)}.")
            bad.update(names)
    else:
        test = "no standard deviations given: the residual scale was estimated from the residuals, so the " \
               "goodness of fit cannot be tested"
    if not converged:
        sentences.append("Not converged to the global minimum: a point below the estimate turned up after "
                         "the last search, so the regions may be incomplete.")
        bad.update(names)
    if rank < len(names):
        sentences.append(f"The Jacobian has rank {rank} < {len(names)}: the data do not determine "
                         + " and ".join(names) + f" jointly; {advice}.")
        bad.update(names)
    for name in names:
        est = estimates[name]
        if est["flat_profile"]:
            sentences.append(f"{name} is not identifiable: its 95 % region ({_pieces_text(est)}) reaches a "
                             f"bound of its range; {advice}.")
            bad.add(name)
        elif len(est["intervals"]) > 1:
            sentences.append(f"{name} is not uniquely identified: {len(est['basins'])} basins within the "
                             f"95 % level, in {len(est['intervals'])} separate pieces ({_pieces_text(est)}); "
                             f"{_separation(suggestion, data)}.")
            bad.add(name)
    for a in range(len(names)):
        for b in range(a + 1, len(names)):
            if abs(corr[a, b]) > CORRELATION_LIMIT:
                sentences.append(f"{names[a]} and {names[b]} trade off against each other (local correlation "
                                 f"{corr[a, b]:+.3f}); their regions are profiles, which allow for it; "
                                 f"{advice} to narrow them.")
    if not bad:
        return True, (f"Every free parameter is identifiable: one closed 95 % region each, inside its bounds "
                      f"({test}). " + " ".join(sentences)).strip()
    return False, " ".join(sentences) + (f" ({test}.)" if not gof.get("rejected") else "")


def fitted_drive_file(result: FitResult, data_name: str, sources: dict | None = None) -> str:
    """The fitted drive as a drive file (:func:`passmd.model.drive_file.drive_toml`) that ``--drive`` and
    :func:`passmd.model.drive_file.load_drive` read back to ``result.drive``.

    ``sources``: where each of the starting drive's values came from, by drive-file key (as
    :func:`passmd.model.drive_file.resolve` gives them: the user's file, an option, a default);
    the fitted keys name ``data_name``. When k_p or m_a was fitted with the damping ratio held
    (``result.keep``), the file gives ζ and the viscosity follows from it, as ``drive show``
    derives it; else it gives c_p.
    """
    from passmd.model.drive_file import DRIVE_KEYS, drive_toml

    free = result.names
    fitted = {"actuator.damping_ratio": "actuator.viscosity", "flyback_time": "amplifier.slew_rate",
              "contact_stiffness_scale": "hemisphere_material.youngs_modulus"}
    out = {key: text for key, text in (sources or {}).items() if key in DRIVE_KEYS}
    by = f"fitted to {data_name} by passmd fit"
    for name in free:
        key = fitted.get(name, name)
        if key in DRIVE_KEYS:
            out[key] = by
    if "actuator.damping_ratio" in free:
        out["actuator.damping_ratio"] = by
        out["actuator.viscosity"] = "derived from the fitted ζ: 2ζ√(k_p m_a)"
    if "contact_stiffness_scale" in free:
        out["runner_material.youngs_modulus"] = f"{by} (scale on E)"
    moving = [n for n in ("actuator.stiffness", "actuator.mass") if n in free]
    hold_zeta = (result.keep == "damping_ratio" and moving and "actuator.viscosity" not in free
                 and "actuator.damping_ratio" not in free)
    zeta = None
    if hold_zeta:
        zeta = result.base.actuator.damping_ratio
        out["actuator.damping_ratio"] = (f"held while {' and '.join(moving)} was fitted (was: "
                                         f"{out.get('actuator.damping_ratio', 'derived from c_p')})")
        out["actuator.viscosity"] = "derived from ζ: 2ζ√(k_p m_a)"
    elif moving and "actuator.viscosity" not in free and "actuator.damping_ratio" not in free:
        out["actuator.viscosity"] = f"held while {' and '.join(moving)} was fitted (was: " \
                                    f"{out.get('actuator.viscosity', 'given')})"
    held = [f"{DRIVE_KEYS[k].symbol} = {_key_value(result.drive, k)} ({k}: {out[k]})" for k in out
            if out[k].startswith("held")]
    notes = [f"Fitted to {data_name}: {', '.join(free)}; every other value as below (held)."]
    notes += [f"Held while fitting: {line}" for line in held]
    points = getattr(result, "region_points", ())  # a record of a fit made before regions were kept: none
    if points:
        notes.append(f"[fit_region] at the end: the fitted keys at {len(points)} points of the "
                     "fit's 95 % region, whose predictions span its band.")
    return drive_toml(result.drive, out, title=f"drive fitted by passmd fit to {data_name}",
                      damping_ratio=zeta, notes=notes, region=_region_values(result))


def _key_value(drive: Drive, key: str) -> str:
    """A drive-file key's value in ``drive``, as a short number (ζ and c_p of the actuator)."""
    value = drive.actuator.damping_ratio if key == "actuator.damping_ratio" else drive.actuator.viscosity
    return f"{value:.4g}"


def _region_values(result: FitResult) -> list[dict]:
    """The drive-file values of the keys the fit moved, at each of its region's points (those that
    differ between the region's drives)."""
    from passmd.model.drive_file import parameter_rows
    from passmd.model.drive_keys import DRIVE_KEYS, SI_UNITS

    if not getattr(result, "region_points", ()):
        return []
    rows = [{r["key"]: r["value"] for r in parameter_rows(d)} for d in result.region_drives()]
    if len(rows) < 2:
        return []
    keys = [k for k in DRIVE_KEYS if DRIVE_KEYS[k].unit in SI_UNITS and len({row[k] for row in rows}) > 1]
    return [{k: row[k] for k in keys} for row in rows]
