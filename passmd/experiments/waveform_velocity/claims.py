"""Claim extractors of Section 5.2: steady velocities (Figs. 9b and 10).

Decides the ledger's Section 5.2 velocity rows (``passmd/data/reference/claims.csv``; Fig. 9a's
positions are :mod:`passmd.experiments.driving_waveform.claims`'), and the abstract's and conclusion's
claims drawn from them, from the steady velocities of Figs. 9b and 10, each at the ledger's reading
of μ (the readings tables ``fig9b_readings`` … ``fig10c_readings``) and of the short-period rule of
the optimized waveform: the velocity gain, the saw-tooth's step and velocity, the frequencies where
the velocity turns and where t_s no longer fits, the reachable maxima of Fig. 10 and their orderings
over preload, radius and runner material, the 0.1 N maximum at the loss of stick.

The reachable maximal velocity of a series is its largest steady velocity over the paper's
controllable range, the grid frequencies up to 110 kHz ("it is impossible to control the drives
with frequencies above 110 kHz"), where it lies is the maximal controllable frequency (assumption
``controllable_frequency``: the largest velocity on the whole grid). On a grid that lacks some of
the paper's frequencies (the quick profile) a maximum is only a lower bound and its location only
a bracket: a claim is then decided only where every value they allow decides it. Where the
frequencies that decide a claim are all above the one where Eq. 15's settling time, acceleration
and fly-back still fit the period, the verdict says so (:class:`passmd.ledger.checks.Scoped`): it
rests on the short-period rule (``cut`` or ``skip``, both readings), not on Eq. 15. The frequency up
to which Eq. 15 fits is computed exactly, by the criterion ``passmd run --waveform optimized``
refuses a frequency by (:func:`eq15_limit_kHz`); two maxima located on the grid are tied within one
grid step, two velocities or back-steps within the integrator's stated accuracy (the tie rule of
:mod:`passmd.ledger.rules`); a coarser grid's gaps make a claim inconclusive as
:class:`passmd.ledger.checks.CoarseGrid`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd.experiments.model_numerics.facts import POSITION_ACCURACY, VELOCITY_ACCURACY
from passmd.experiments.waveform_velocity.figures import FREQUENCIES, PAPER_MAXIMUM_KHZ
from passmd.ledger.checks import (
    ClaimFails,
    CoarseGrid,
    NoRun,
    NotEvaluable,
    Scoped,
    Subset,
    evidence,
    extractor,
)
from passmd.ledger.readings import default_reading
from passmd.model.optimized_waveform import highest_fitting_frequency
from passmd.protocols.section5 import make_design, section5_drive, variant_name

__all__ = ["GRID_STEP_KHZ", "at_frequency", "complete_grid", "controllable_maximum", "eq15_limit_kHz",
           "eq15_scope",
           "maximum_location", "on_paper_grid", "stick_edge", "turning_point"]

#: Axes of passmd.ledger.readings: Section 5's unstated μ, and the short-period rule of Eq. 15.
_SAWTOOTH_AXES = ("friction_coefficient",)
_OPTIMIZED_AXES = ("short_period", "friction_coefficient")

#: One step of the paper's 5 kHz frequency grid (Section 5.2): how near a located maximum must lie
#: to the frequency the paper names for it.
GRID_STEP_KHZ = 5.0


def _series(results, key: str, variant: str, reading, **where) -> pd.DataFrame:
    """One series of a velocity readings table at a reading's μ, by frequency."""
    table = results[f"{key}_readings"]
    mu = float(reading["friction_coefficient"])
    table = table[np.isclose(table["friction_coefficient"], mu, rtol=1e-9, atol=0)]
    sel = table["variant"] == variant
    for column, value in where.items():
        sel &= np.isclose(table[column], value, rtol=1e-9, atol=0) if isinstance(value, float) else (
            table[column] == value)
    part = table[sel].sort_values("frequency")
    if part.empty:
        raise NoRun(f"no {variant} rows of {key} for {where} at μ = {mu:g}")
    if not np.all(np.isfinite(part["velocity_mm_per_s"].to_numpy(dtype=float))):
        raise NotEvaluable("non-finite velocities on the frequency grid")
    return part


def _optimized(reading) -> str:
    """The optimized variant of a ledger reading (axis ``short_period`` of passmd.ledger.readings)."""
    return variant_name("optimized", reading["short_period"])


def complete_grid(part: pd.DataFrame, up_to_kHz: float = np.inf) -> bool:
    """Whether a series holds every frequency of the paper's grid (up to ``up_to_kHz``)."""
    paper = np.round(FREQUENCIES["paper"] / 1e3, 9)
    have = np.round(part["frequency_kHz"].to_numpy(), 9)
    return bool(np.isin(paper[paper <= up_to_kHz + 1e-9], have).all())


def on_paper_grid(ours, part: pd.DataFrame, failures_decide: bool = True, low_kHz: float = 0.0,
                  high_kHz: float = np.inf):
    """``ours`` when ``part`` holds every frequency of the paper's grid in [low_kHz, high_kHz], else a
    :class:`~passmd.ledger.checks.Subset` naming the missing ones: a check over every frequency that
    holds on part of the grid is undecided; one that fails is decided when ``failures_decide`` (a
    pointwise check: the failing frequency is on the paper's grid, its steady run the same)."""
    paper = np.round(FREQUENCIES["paper"] / 1e3, 9)
    paper = paper[(paper >= low_kHz - 1e-9) & (paper <= high_kHz + 1e-9)]
    missing = paper[~np.isin(paper, np.round(part["frequency_kHz"].to_numpy(), 9))]
    if missing.size == 0:
        return ours
    return Subset(ours, f"{missing.size} of the paper's frequencies "
                        f"({missing.min():g}–{missing.max():g} kHz)", failures_decide)


def eq15_scope(part: pd.DataFrame, frequencies_kHz) -> str:
    """``""`` when Eq. 15's waveform fits the period at one of the deciding ``frequencies_kHz`` of an
    optimized series, else where it does not (for :class:`passmd.ledger.checks.Scoped`)."""
    rows = part[np.isin(np.round(part["frequency_kHz"], 9), np.round(np.atleast_1d(frequencies_kHz), 9))]
    if rows.empty or rows["eq15_fits"].astype(bool).any():
        return ""
    fits = part.loc[part["eq15_fits"].astype(bool), "frequency_kHz"]
    limit = f"above {fits.max():g} kHz" if len(fits) else "at every grid frequency"
    return (f"Eq. 15 is undefined: t_s + t_a + the fly-back exceed the period {limit} (decided at "
            + ", ".join(f"{f:g}" for f in np.atleast_1d(frequencies_kHz))
            + " kHz: the short-period rule's waveform)")


def _scoped(ours, *scopes: str):
    outside = "; ".join(s for s in scopes if s)
    return Scoped(ours, outside) if scopes and all(scopes) else ours


def controllable_maximum(part: pd.DataFrame) -> pd.Series:
    """The row of the reachable maximal velocity: the largest over the grid frequencies up to the
    paper's control limit of 110 kHz."""
    inside = part[part["frequency_kHz"] <= PAPER_MAXIMUM_KHZ + 1e-9]
    if inside.empty:
        raise NotEvaluable(f"no grid frequency up to {PAPER_MAXIMUM_KHZ:g} kHz")
    return inside.loc[inside["velocity_mm_per_s"].idxmax()]


def _maxima(part: pd.DataFrame) -> pd.Series:
    """:func:`controllable_maximum`, only where the grid holds every paper frequency up to 110 kHz (on a
    coarser grid a missing frequency could be faster)."""
    if not complete_grid(part, PAPER_MAXIMUM_KHZ):
        raise CoarseGrid("the grid lacks some of the paper's frequencies up to 110 kHz, where the "
                         "reachable maximum could lie")
    return controllable_maximum(part)


def maximum_location(part: pd.DataFrame) -> tuple[float, float, float]:
    """Where the largest velocity on the whole grid lies (assumption ``controllable_frequency``):
    ``(grid frequency, low, high)`` kHz, the bracket a finer grid could still move it to (the grid
    frequency itself on the paper's grid, the open interval to its neighbours on a coarser one)."""
    f = part["frequency_kHz"].to_numpy()
    i = int(np.argmax(part["velocity_mm_per_s"].to_numpy(dtype=float)))
    if complete_grid(part):
        return float(f[i]), float(f[i]), float(f[i])
    return float(f[i]), float(f[max(i - 1, 0)]), float(f[min(i + 1, f.size - 1)])


def _located(part: pd.DataFrame, low: float, high: float, what: str) -> float:
    """The grid frequency of the largest velocity when its bracket lies wholly inside or outside
    [low, high] kHz; inconclusive when a finer grid could move it across."""
    at, lo, hi = maximum_location(part)
    inside = lo >= low - 1e-9 and hi <= high + 1e-9
    outside = hi < low - 1e-9 or lo > high + 1e-9
    if not (inside or outside):
        raise CoarseGrid(f"the largest velocity lies at {at:g} kHz of this grid; between its neighbours "
                           f"({lo:g}–{hi:g} kHz) a finer grid could move it "
                           f"{'into' if not inside else 'out of'} "
                           f"{what}")
    return at


def at_frequency(part: pd.DataFrame, frequency_kHz: float) -> pd.Series:
    """The row of a series at a grid frequency (kHz); inconclusive when the grid lacks it."""
    rows = part[np.isclose(part["frequency_kHz"], frequency_kHz)]
    if rows.empty:
        raise CoarseGrid(f"the frequency grid has no point at {frequency_kHz:g} kHz")
    return rows.iloc[0]


def _fig9b_pair(results, reading):
    saw = _series(results, "fig9b", "sawtooth", reading)
    opt = _series(results, "fig9b", _optimized(reading), reading)
    return saw["frequency_kHz"].to_numpy(), saw["velocity_mm_per_s"].to_numpy(), opt


@extractor("fig9b-optimized-faster-below-110khz", depends_on=_OPTIMIZED_AXES)
def _fig9b_faster(results, reading):
    f, v_saw, opt = _fig9b_pair(results, reading)
    gain = opt["velocity_mm_per_s"].to_numpy() - v_saw  # the observed switch: where it crosses zero
    return on_paper_grid({"x": f, "holds": gain > 0, "margin": gain}, opt)


def _largest_gain(results, reading):
    f, v_saw, opt = _fig9b_pair(results, reading)
    below = f <= PAPER_MAXIMUM_KHZ
    gain = opt["velocity_mm_per_s"].to_numpy()[below] - v_saw[below]
    i = int(np.argmax(gain))
    return gain[i], v_saw[below][i], eq15_scope(opt, f[below][i]), opt


@extractor("fig9b-max-gain-2.5mm_s", depends_on=_OPTIMIZED_AXES)
def _fig9b_max_gain(results, reading):
    # the largest gain up to 110 kHz: on part of the grid a lower bound, undecided either way
    gain, _, scope, opt = _largest_gain(results, reading)
    return on_paper_grid(_scoped(float(gain), scope), opt, False, high_kHz=PAPER_MAXIMUM_KHZ)


@extractor("abstract-velocity-gain-15pct", depends_on=_OPTIMIZED_AXES)
def _velocity_gain_pct(results, reading):
    gain, v_saw, scope, opt = _largest_gain(results, reading)
    return on_paper_grid(_scoped(float(100.0 * gain / v_saw), scope), opt, False, high_kHz=PAPER_MAXIMUM_KHZ)


def turning_point(part: pd.DataFrame, where_kHz: float) -> pd.DataFrame:
    """The part of a velocity series from its turning point on, when it rises and then falls there.

    "Began decreasing above X" needs a rise before the fall and the turning point (the largest
    velocity) within one grid step of X. Raises :class:`passmd.ledger.checks.ClaimFails` naming the
    located turning point otherwise, and :class:`passmd.ledger.checks.NotEvaluable` when fewer than
    two grid points follow it.
    """
    f = part["frequency_kHz"].to_numpy()
    v = part["velocity_mm_per_s"].to_numpy(dtype=float)
    i = int(np.argmax(v))
    if i == len(f) - 1:
        raise ClaimFails(f"the velocity still rises at the grid's last point ({f[i]:g} kHz): it never "
                         "begins decreasing")
    if i == 0:
        raise ClaimFails(f"no rise before the fall: the velocity is largest at the grid's first point "
                         f"({f[0]:g} kHz, {v[0]:.3g} mm/s) and {v[-1]:.3g} mm/s at {f[-1]:g} kHz")
    step = min(f[i] - f[i - 1], f[i + 1] - f[i])
    if abs(f[i] - where_kHz) > step:
        raise ClaimFails(f"the velocity turns at {f[i]:g} kHz ({v[i]:.3g} mm/s), not within one grid step "
                         f"({step:g} kHz) of {where_kHz:g} kHz")
    return part.iloc[i:]


@extractor("fig9b-optimized-decreases-above-110khz", depends_on=_OPTIMIZED_AXES)
def _fig9b_opt_decreases(results, reading):
    opt = _series(results, "fig9b", _optimized(reading), reading)
    try:
        after = turning_point(opt, PAPER_MAXIMUM_KHZ)
    except ClaimFails as failure:
        if not complete_grid(opt):  # a missing frequency could move the turning point
            raise CoarseGrid(f"fails on this table's part of the grid ({failure}), which lacks some of the "
                             "paper's frequencies") from None
        at = float(opt.loc[opt["velocity_mm_per_s"].idxmax(), "frequency_kHz"])
        raise ClaimFails(str(failure), eq15_scope(opt, at)) from None
    if len(after) < 2:
        raise NotEvaluable("fewer than two grid frequencies from the turning point on")
    ours = {"x": after["frequency_kHz"].to_numpy(), "y": after["velocity_mm_per_s"].to_numpy()}
    return on_paper_grid(_scoped(ours, eq15_scope(opt, ours["x"])), opt, False)


#: Why the saw-tooth's rise above 110 kHz cannot fail in this model: with no stick phase left, the
#: steady step barely changes with the frequency, and a velocity that is step × f rises with f.
_STEP_TIMES_F = ("above 110 kHz the saw-tooth's steady step is nearly constant (a few % over 110–130 kHz on "
                 "both profiles), so its velocity, the step times f, rises with f for any step that falls "
                 "slower than 1/f: the row tests the model's step, not the rise the paper contrasts with the "
                 "optimized waveform's fall")


@extractor("fig9b-standard-increases-above-110khz", depends_on=_SAWTOOTH_AXES, not_informative=_STEP_TIMES_F)
def _fig9b_std_increases(results, reading):
    part = _series(results, "fig9b", "sawtooth", reading)
    part = part[part["frequency_kHz"] >= PAPER_MAXIMUM_KHZ - 1e-9]
    if len(part) < 2:
        raise NotEvaluable("fewer than two grid frequencies at or above 110 kHz")
    return on_paper_grid({"x": part["frequency_kHz"].to_numpy(), "y": part["velocity_mm_per_s"].to_numpy()},
                         part, False, low_kHz=PAPER_MAXIMUM_KHZ)


@evidence("fig9b-standard-increases-above-110khz")
def _fig9b_std_evidence(results):
    part = _series(results, "fig9b", "sawtooth", default_reading())
    part = part[part["frequency_kHz"] >= PAPER_MAXIMUM_KHZ - 1e-9]
    step = part["step_nm"].to_numpy()
    return [f"saw-tooth step from 110 to {part['frequency_kHz'].max():g} kHz: "
            f"{step.min():.4g}–{step.max():.4g} nm "
            f"({100 * np.ptp(step) / abs(step).max():.2g} % of its size) at the defaults"]


@extractor("fig9b-step-decreases-with-frequency", depends_on=_SAWTOOTH_AXES)
def _fig9b_step_decreases(results, reading):
    saw = _series(results, "fig9b", "sawtooth", reading)
    # a trend's allowance scales with the series' spread: on part of the grid neither verdict decides
    return on_paper_grid({"x": saw["frequency_kHz"].to_numpy(), "y": saw["step_nm"].to_numpy()}, saw, False)


@extractor("study-fig9b-sawtooth-velocity-16.5mm_s-at-110khz")
def _fig9b_sawtooth_110(results):
    part = _series(results, "fig9b", "sawtooth", default_reading())
    return float(at_frequency(part, PAPER_MAXIMUM_KHZ)["velocity_mm_per_s"])


def eq15_limit_kHz(part: pd.DataFrame) -> float:
    """The highest frequency (kHz) at which the Eq. 15 period of a series' drive fits whole, t_s and all:
    :func:`passmd.model.optimized_waveform.highest_fitting_frequency`, the criterion ``passmd run
    --waveform optimized`` refuses a frequency by."""
    row = part.iloc[0]
    drive = section5_drive(float(row["hemisphere_radius"]), float(row["preload"]), str(row["runner"]),
                           str(row["actuator_model"]), float(row["friction_coefficient"]))
    design = make_design(float(row["settling_time"]), float(row["acceleration_time"]),
                         float(row["acceleration_amplitude"]))
    return highest_fitting_frequency(design, drive.actuator.full_stroke_amplitude, drive) / 1e3


@extractor("fig9b-no-time-to-settle-above-110khz", depends_on=_OPTIMIZED_AXES)
def _fig9b_settling(results, reading):
    opt = _series(results, "fig9b", _optimized(reading), reading)
    return on_paper_grid({"x": opt["frequency_kHz"].to_numpy(),
                          "holds": opt["settling_fits"].to_numpy(dtype=float), "switch": eq15_limit_kHz(opt)},
                         opt)


def _fig10a_part(results, preload, reading):
    return _series(results, "fig10a", _optimized(reading), reading, preload=preload)


@extractor("fig10a-max-velocity-19mm_s", depends_on=_OPTIMIZED_AXES)
def _fig10a_vmax(results, reading):
    # the largest velocity up to the control limit; on a coarser grid a lower bound, which decides
    # only when it already lies above the tolerance band
    part = _fig10a_part(results, 0.4, reading)
    best = controllable_maximum(part)
    value = float(best["velocity_mm_per_s"])
    if not complete_grid(part, PAPER_MAXIMUM_KHZ) and value <= 19.0 * 1.1:
        raise CoarseGrid(f"{value:.3g} mm/s is the largest on this grid, a lower bound of the reachable "
                         "maximum: a missing frequency up to 110 kHz could be faster")
    return _scoped(value, eq15_scope(part, float(best["frequency_kHz"])))


@extractor("fig10a-max-velocity-at-110khz", depends_on=_OPTIMIZED_AXES)
def _fig10a_fmax(results, reading):
    part = _fig10a_part(results, 0.4, reading)
    at = _located(part, PAPER_MAXIMUM_KHZ - GRID_STEP_KHZ, PAPER_MAXIMUM_KHZ + GRID_STEP_KHZ,
                  f"{PAPER_MAXIMUM_KHZ:g} ± {GRID_STEP_KHZ:g} kHz")
    return _scoped(at, eq15_scope(part, at))


#: What two values of a column of the velocity tables must differ by to be told apart: the stated
#: accuracy of the integrator (passmd.experiments.model_numerics.facts), in the column's unit.
_RESOLUTION = {"back_step_nm": POSITION_ACCURACY * 1e9, "velocity_mm_per_s": VELOCITY_ACCURACY * 1e3}


def _maximum_pair(first: pd.DataFrame, second: pd.DataFrame, column: str) -> dict:
    """``column`` at the reachable maxima of two series (complete grids only), scoped by Eq. 15, with the
    integrator's stated accuracy as the resolution of the tie rule (two back-steps of 0 nm are tied)."""
    a, b = _maxima(first), _maxima(second)
    ours = {"lhs": float(a[column]), "rhs": float(b[column]), "resolution": _RESOLUTION[column]}
    return _scoped(ours, eq15_scope(first, float(a["frequency_kHz"])),
                   eq15_scope(second, float(b["frequency_kHz"])))


@extractor("fig10a-0.1n-stick-lost-above-80khz", depends_on=_OPTIMIZED_AXES)
def _fig10a_stick(results, reading):
    part = _fig10a_part(results, 0.1, reading)
    return on_paper_grid({"x": part["frequency_kHz"].to_numpy(),
                          "holds": part["stick_during_acceleration"].to_numpy(dtype=float)}, part)


def stick_edge(part: pd.DataFrame) -> float:
    """The highest grid frequency (kHz) at which the runner still sticks during t_a, with stick lost
    at every grid frequency above it: where the loss of stick of the 0.1 N claim begins.

    :class:`passmd.ledger.checks.ClaimFails` when stick is never lost at the top of the grid or never
    holds at all.
    """
    f = part["frequency_kHz"].to_numpy()
    stick = part["stick_during_acceleration"].to_numpy(dtype=bool)
    if stick[-1]:
        raise ClaimFails(f"the runner still sticks during t_a at the grid's last frequency, {f[-1]:g} kHz: "
                         "no loss of stick limits the velocity")
    if not stick.any():
        raise ClaimFails("the runner slips during t_a at every grid frequency")
    return float(f[np.flatnonzero(stick)[-1]])


@extractor("fig10a-0.1n-maximum-at-or-below-80khz", depends_on=_OPTIMIZED_AXES)
def _fig10a_01n_at_80(results, reading):
    # the maximum is limited by the loss of stick: it lies at the last frequency before stick is lost
    part = _fig10a_part(results, 0.1, reading)
    if not complete_grid(part):
        raise CoarseGrid("the grid lacks some of the paper's frequencies, between which the maximum and "
                         "the loss of stick could lie")
    at = maximum_location(part)[0]
    return _scoped({"lhs": at, "rhs": stick_edge(part), "resolution": GRID_STEP_KHZ}, eq15_scope(part, at))


@evidence("fig10a-0.1n-maximum-at-or-below-80khz")
def _fig10a_01n_at_80_evidence(results):
    part = _fig10a_part(results, 0.1, default_reading())
    fits = part.loc[part["eq15_fits"].astype(bool), "frequency_kHz"]
    stick = part.loc[part["stick_during_acceleration"].astype(bool), "frequency_kHz"]
    fitting = f"{fits.max():g} kHz" if len(fits) else "no grid frequency"
    return [f"0.1 N: t_s + t_a + the fly-back fit into the period up to {fitting}; the runner sticks during "
            "t_a "
            f"at {', '.join(f'{x:g}' for x in stick) or 'no grid frequency'} kHz"]


def _fig10b_part(results, radius_mm, reading):
    return _series(results, "fig10b", _optimized(reading), reading, radius_mm=radius_mm)


@extractor("fig10b-r1-higher-max-frequency", depends_on=_OPTIMIZED_AXES)
def _fig10b_frequency(results, reading):
    r1, r025 = _fig10b_part(results, 1.0, reading), _fig10b_part(results, 0.25, reading)
    if not (complete_grid(r1) and complete_grid(r025)):
        raise CoarseGrid("the grid lacks some of the paper's frequencies, where either maximum could lie")
    at1, at025 = maximum_location(r1)[0], maximum_location(r025)[0]
    # a maximum located on the grid is known to one grid step: closer ones are tied
    return _scoped({"lhs": at1, "rhs": at025, "resolution": GRID_STEP_KHZ}, eq15_scope(r1, at1),
                   eq15_scope(r025, at025))


def _fig10c_part(results, runner, reading):
    return _series(results, "fig10c", _optimized(reading), reading, runner=runner)


@extractor("conclusion-youngs-modulus-weaker-than-preload-and-radius", depends_on=_OPTIMIZED_AXES)
def _conclusion_youngs(results, reading):
    pairs = {
        "material": (_fig10c_part(results, "molybdenum", reading), _fig10c_part(results, "steel", reading)),
        "preload": (_fig10a_part(results, 1.0, reading), _fig10a_part(results, 0.4, reading)),
        "radius": (_fig10b_part(results, 1.0, reading), _fig10b_part(results, 0.25, reading)),
    }
    effect, scopes = {}, []
    for name, (a, b) in pairs.items():
        ab = _maximum_pair(a, b, "velocity_mm_per_s")
        scopes.append(ab.outside if isinstance(ab, Scoped) else "")
        ab = ab.ours if isinstance(ab, Scoped) else ab
        effect[name] = abs(ab["lhs"] - ab["rhs"])
    return _scoped({"lhs": effect["material"], "rhs": min(effect["preload"], effect["radius"]),
                    "resolution": 2 * _RESOLUTION["velocity_mm_per_s"]}, *scopes)


# The Fig. 10 orderings: one column at the reachable maxima of two series of one table
# (_maximum_pair); each claim's extractor and its evidence (the maxima at the defaults) are made
# from one row of _FIG10_ORDERINGS.

def _maxima_evidence(results, key, column, unit, pairs):
    out = []
    for where in pairs:
        part = _series(results, key, "optimized", default_reading(), **where)
        best = controllable_maximum(part)
        name = ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}" for k, v in where.items())
        out.append(f"{name}: reachable maximum {best['velocity_mm_per_s']:.4g} mm/s at "
                   f"{best['frequency_kHz']:g} kHz"
                   + (f", {column.replace('_nm', '').replace('_', ' ')} {best[column]:.4g} {unit}"
                      if column != "velocity_mm_per_s" else "")
                   + ("" if bool(best["eq15_fits"]) else " (Eq. 15 undefined there)"))
    return out


def _fig10_evidence(claim_id, key, column, unit, pairs):
    return evidence(claim_id)(lambda results: _maxima_evidence(results, key, column, unit, pairs))


def _fig10_ordering(claim_id, key, column, unit, pairs) -> tuple:
    """The extractor and the evidence of one Fig. 10 ordering: ``column`` at the reachable maxima of
    the two series ``pairs`` of table ``key`` (the first is the claim's left-hand side)."""
    first, second = pairs

    @extractor(claim_id, depends_on=_OPTIMIZED_AXES)
    def ordering(results, reading):
        return _maximum_pair(_series(results, key, _optimized(reading), reading, **first),
                             _series(results, key, _optimized(reading), reading, **second), column)

    return ordering, _fig10_evidence(claim_id, key, column, unit, pairs)


#: The Fig. 10 orderings: (claim, table, column, unit, (the series of its left-hand side, of its right)).
_FIG10_ORDERINGS = (
    ("fig10a-1n-slower", "fig10a", "velocity_mm_per_s", "mm/s", ({"preload": 1.0}, {"preload": 0.4})),
    ("fig10a-1n-larger-back-step", "fig10a", "back_step_nm", "nm", ({"preload": 1.0}, {"preload": 0.4})),
    # the back-step at each preload's reachable maximum, as for 1 N: the velocity the sentence explains
    ("fig10a-0.1n-smaller-back-step", "fig10a", "back_step_nm", "nm", ({"preload": 0.1}, {"preload": 0.4})),
    ("fig10a-0.1n-slightly-slower", "fig10a", "velocity_mm_per_s", "mm/s",
     ({"preload": 0.1}, {"preload": 0.4})),
    # 'a higher velocity': Fig. 10b's quantity is each radius's reachable maximal velocity
    ("fig10b-r1-faster", "fig10b", "velocity_mm_per_s", "mm/s", ({"radius_mm": 1.0}, {"radius_mm": 0.25})),
    ("fig10b-r1-smaller-back-step", "fig10b", "back_step_nm", "nm",
     ({"radius_mm": 1.0}, {"radius_mm": 0.25})),
    ("fig10c-youngs-modulus-negligible", "fig10c", "velocity_mm_per_s", "mm/s",
     ({"runner": "molybdenum"}, {"runner": "steel"})),
)
#: The Fig. 10 orderings' extractors and evidence functions, and the evidence of the 0.4 N maximum
#: (found by passmd.ledger.checks).
_FIG10_FUNCTIONS = (
    _fig10_evidence("fig10a-max-velocity-19mm_s", "fig10a", "velocity_mm_per_s", "mm/s", ({"preload": 0.4},)),
    *(function for row in _FIG10_ORDERINGS for function in _fig10_ordering(*row)),
)
