"""The estimator of :func:`~passmd.protocols.fit.estimator.fit`: the whole range searched, then refined.

1. **Global pass**: a scrambled Sobol design of :data:`GLOBAL_POINTS_PER_PARAMETER` points per free
   parameter over the log box (rounded up to a power of two), one sweep. With one free parameter
   the coarse profile of stage 3 (a grid over the whole bounds) is the global pass.
2. **Local searches** (``scipy.optimize.least_squares``, trust-region reflective, log space) from
   the best :data:`LOCAL_STARTS` distinct points of the pass (at least :data:`DISTINCT` apart in
   the unit box), :data:`FIRST_SEARCH_EVALUATIONS` evaluations each.
3. **Profiles** of every parameter over its whole bounds (:mod:`passmd.protocols.fit.profiles`):
   coarse, then walked at 1 % wherever the comb of the step in k_p could hide a tooth within the
   95 % level, then refined around each low minimum.
4. **Polish** (three or more free parameters): the profile's inner minimisation is one
   Gauss–Newton step of the others from the neighbouring point; with two or more others the
   teeth of the comb are curved valleys in their plane, and that step can stop on a valley's wall.
   A full local search starts from :data:`MAX_BASINS` distinct local minima of the profiles
   within twice the 95 % rise of the best cost: those whose Gauss–Newton step in all free
   parameters projects the lowest cost.
5. **Basins**: the local minima of every profile within the level; the lowest point found
   anywhere is polished by a local search and is the estimate. Each basin adds the local
   interval of every parameter (:mod:`passmd.protocols.fit.regions`); a point met on the way
   below the estimate restarts stage 5 from it (:data:`REFITS` times at most).

The 95 % region of a parameter is every value whose profile (or a basin's local interval) lies
within :func:`region_level` of the minimum — the 95 % quantile of χ²_p (σ given) or p · F(p, n − p)
(σ estimated), p free parameters: the projection of the joint 95 % region, possibly several
pieces. With stated σ the minimum cost is tested against χ²_{n−p}
(:func:`~passmd.protocols.fit.result.goodness_of_fit`).
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace

import numpy as np

from passmd.model.parameters import Drive, check_drive
from passmd.protocols.fit import regions
from passmd.protocols.fit.checks import check_rows
from passmd.protocols.fit.free_parameters import (
    FREE_PARAMETERS,
    KEEPS,
    _check_free,
    default_bounds,
    plausible_bounds,
)
from passmd.protocols.fit.measurements import READINGS, Measurements
from passmd.protocols.fit.next_measurement import separating_row
from passmd.protocols.fit.prediction import _Model
from passmd.protocols.fit.problem import JACOBIAN_STEPS, Problem
from passmd.protocols.fit.profiles import FINE_SPACING, Profile, bottoms, coarse, fill, projected_cost
from passmd.protocols.fit.result import FitResult, goodness_of_fit, verdict
from passmd.runtime import sweep
from passmd.runtime.config import RunConfig
from passmd.runtime.validation import InputError, check_choice

__all__ = ["DISTINCT", "FIRST_SEARCH_EVALUATIONS", "GLOBAL_POINTS_PER_PARAMETER", "JACOBIAN_STEPS",
           "LOCAL_STARTS", "LOSSES", "MAX_BASINS", "POLISH_CANDIDATES", "PROGRESS_INTERVAL", "REFITS",
           "REFIT_MARGIN", "fit",
           "region_level"]

#: Points of the global pass per free parameter (the Sobol design takes the next power of two).
GLOBAL_POINTS_PER_PARAMETER = 64
#: Local searches from the best distinct points of the global pass.
LOCAL_STARTS = 2
#: Function evaluations of each of these first searches (the profiles then search the whole range).
FIRST_SEARCH_EVALUATIONS = 8
#: Least distance (in the unit box of the log bounds) between two starts of local searches.
DISTINCT = 0.05
#: New polishes when a point below the estimate turns up while the basins' intervals are computed.
REFITS = 2
#: A point counts as lower than the estimate when below it by more than this many s² (a third of
#: the 95 % rise: not a rounding effect).
REFIT_MARGIN = 0.5
#: At most this many basins (the lowest) get their own local intervals; as many local searches
#: polish the profiles' minima when three or more parameters are free.
MAX_BASINS = 8
#: The lowest distinct minima of the profiles whose projected Gauss–Newton cost ranks them for the
#: polish (three or more free parameters).
POLISH_CANDIDATES = 32
#: Robust losses of ``scipy.optimize.least_squares`` (the intervals use the plain sum of squares).
LOSSES = ("linear", "soft_l1", "huber", "cauchy", "arctan")


def _weights(data: Measurements) -> np.ndarray:
    if data.known_sd:
        return data.sd.copy()
    return np.array([data.display(i)[0] for i in range(len(data))])  # one display unit


def _check_bounds(drive, names, bounds, f_max) -> dict[str, tuple[float, float]]:
    """Each free parameter's (low, high): given, else :func:`default_bounds`; a given range beyond
    :func:`plausible_bounds` needs the drive's ``allow_extrapolation``."""
    bounds = {} if bounds is None else dict(bounds)
    for name in bounds:
        if name not in names:
            raise InputError(f"bounds names {name!r}, which is not a free parameter ({', '.join(names)})",
                             name="bounds", value=name)
    out = {}
    for name in names:
        low, high = bounds.get(name, default_bounds(drive, name, f_max))
        if not (math.isfinite(low) and math.isfinite(high) and 0 < low < high):
            raise InputError(f"bounds of {name} = {low!r}..{high!r} are not allowed: must be 0 < low < high",
                             name=name, value=(low, high))
        ok_low, ok_high = plausible_bounds(drive, name)
        if name in bounds and not drive.allow_extrapolation and (low < ok_low or high > ok_high):
            raise InputError(f"bounds of {name} = {low:.4g}..{high:.4g} are out of range: must be within "
                             f"{ok_low:.4g}..{ok_high:.4g}, its plausible range (allow_extrapolation=True on "
                             "the drive goes beyond it)", name="bounds", value=(low, high))
        out[name] = (float(low), float(high))
    return out


def fit(
    drive: Drive,
    data: Measurements,
    free: Sequence[str],
    *,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    reading: str = "steady",
    loss: str = "linear",
    keep: str = "damping_ratio",
    seed: int = 0,
    executor: str | cf.Executor | None = None,
    cache=True,
    config: RunConfig | None = None,
    progress: Callable[[str], None] | None = None,
) -> FitResult:
    """Fit the free parameters of ``drive`` to ``data`` (module docstring).

    Parameters
    ----------
    drive : Drive
        The drive whose other parameters are known; its values of the free ones are a start.
    data : Measurements
        From :func:`~passmd.protocols.fit.measurements.read_measurements` or
        :func:`~passmd.protocols.fit.measurements.measurements_from_rows`. Every row is checked
        against the drive before anything is simulated (:func:`~passmd.protocols.fit.checks.check_rows`).
    free : list of str
        Names from :data:`~passmd.protocols.fit.free_parameters.FREE_PARAMETERS`.
    bounds : dict, optional
        name -> (low, high) in SI; default
        :func:`~passmd.protocols.fit.free_parameters.default_bounds`.
    reading : {"steady", "first"}
        How the simulator reads a critical amplitude (Section 4.1's two protocols).
    loss : str
        Loss of the local searches (:data:`LOSSES`); profiles and intervals use the sum of squares.
    keep : {"damping_ratio", "viscosity"}
        What stays fixed of the actuator's damping when its stiffness or mass is fitted: the
        damping ratio ζ (default; c_p = 2ζ√(k_p m_a) follows, as a drive file derives it) or the
        viscosity c_p.
    seed : int
        Seed of the scrambled Sobol design (the fit is deterministic for a seed).
    executor, cache, config
        How the model evaluations run (:func:`passmd.runtime.sweep.run`); a process pool is kept for
        the whole fit.
    progress : callable, optional
        Receives one line per stage, and at least one every :data:`PROGRESS_INTERVAL` s while a stage
        runs (from another thread).

    Raises
    ------
    InputError
        Bad arguments, a row the drive cannot run, or no more measurements than free parameters.
    """
    t0 = time.perf_counter()
    check_drive(drive)
    if not isinstance(data, Measurements):
        raise InputError(f"data = {data!r} is not Measurements (read_measurements)", name="data", value=data)
    names = _check_free(drive, free)
    check_choice("reading", reading, READINGS)
    check_choice("loss", loss, LOSSES)
    check_choice("keep", keep, KEEPS)
    n, p = len(data), len(names)
    if n <= p:
        raise InputError(f"{n} measurements cannot determine {p} free parameters: give more measurements "
                         "than free parameters", name="data", value=n)
    f_max = float(np.max(data.frequency))
    box = _check_bounds(drive, names, bounds, f_max)
    check_rows(drive, data, box)
    report = _Heartbeat(progress) if progress is not None else (lambda line: None)
    lo = np.log([box[k][0] for k in names])
    hi = np.log([box[k][1] for k in names])
    x_start = np.clip(np.log([max(FREE_PARAMETERS[k].get(drive), 1e-300) for k in names]), lo, hi)
    config = RunConfig() if config is None else config
    chosen = executor if executor is not None else (
        config.executor or ("dask" if config.scheduler else "process"))
    with contextlib.ExitStack() as stack:
        if chosen == "process":  # one pool for the whole fit (sweep.process_pool: signals, worker cap)
            chosen = stack.enter_context(sweep.process_pool(config.workers))
        model = _Model(drive, data, names, reading, executor=chosen, cache=cache, config=config, keep=keep)

        def say(line: str) -> None:
            report(f"{line} ({model.evaluations} parameter sets so far)")

        problem = Problem(model, data, _weights(data), lo, hi, loss)
        if isinstance(report, _Heartbeat):
            stack.callback(report.stop)
            report.start(lambda: model.evaluations)
        return _fit(problem, drive, names, box, x_start, reading, keep, seed, say, t0)


#: Longest silence of a fit's progress (s): while one stage runs longer, a line says it still runs.
PROGRESS_INTERVAL = 10.0


class _Heartbeat:
    """The fit's ``progress`` callback, with a line at least every :data:`PROGRESS_INTERVAL` s: a
    daemon thread repeats the current stage ("still: ...") while a long sweep runs (a large data
    file, slow points), so a fit is never silent for minutes."""

    def __init__(self, report: Callable[[str], None]):
        import threading

        self.report, self.lock = report, threading.Lock()
        self.stage, self.last = "the start values", time.monotonic()
        self.done = threading.Event()
        self.thread = threading.Thread(target=self._beat, name="passmd-fit-progress", daemon=True)
        self.count: Callable[[], int] = lambda: 0

    def __call__(self, line: str) -> None:
        with self.lock:
            self.stage, self.last = line.split(" (", 1)[0], time.monotonic()
            self.report(line)

    def start(self, count: Callable[[], int]) -> None:
        self.count = count
        self.thread.start()

    def stop(self) -> None:
        self.done.set()

    def _beat(self) -> None:
        while not self.done.wait(max(0.0, self.last + PROGRESS_INTERVAL - time.monotonic())):
            with self.lock:
                if time.monotonic() - self.last >= PROGRESS_INTERVAL and not self.done.is_set():
                    self.report(f"still: {self.stage} ({self.count()} parameter sets so far)")
                    self.last = time.monotonic()


def _global_pass(problem: Problem, x_start: np.ndarray, seed: int, say) -> list[tuple[np.ndarray, float]]:
    """The start values and a scrambled Sobol design over the log box (one sweep): the best
    :data:`LOCAL_STARTS` points at least :data:`DISTINCT` apart, lowest cost first."""
    from scipy.stats import qmc

    lo, hi, p = problem.lo, problem.hi, problem.p
    count = 1 << max(0, math.ceil(math.log2(GLOBAL_POINTS_PER_PARAMETER * p)))
    design = qmc.Sobol(d=p, scramble=True, seed=seed).random(count)
    candidates = [x_start] + [lo + u * (hi - lo) for u in design]
    say(f"global pass: {len(candidates)} parameter sets × {problem.n} measurements")
    costs = problem.costs(candidates)
    picks: list[tuple[np.ndarray, float]] = []
    width = np.where(hi > lo, hi - lo, 1.0)
    for k in np.argsort(costs):
        x = candidates[k]
        if all(np.max(np.abs(x - y) / width) >= DISTINCT for y, _ in picks):
            picks.append((x, costs[k]))
        if len(picks) == LOCAL_STARTS:
            break
    return picks


def region_level(free: int, n: int, known_sd: bool) -> float:
    """The 95 % rise of a profile above the minimum, in units of s²: the 95 % quantile of χ² with
    ``free`` degrees of freedom (σ given), or ``free`` · F(free, n − free) (σ estimated).

    A parameter's region is then the projection of the joint 95 % region of all free parameters.
    The per-parameter level (χ²₁) assumes a cost that is quadratic near its minimum; on a comb of
    minima (the step in k_p) the minimum is the best of several teeth and χ²₁ regions cover the
    truth too rarely (``benchmarks/bench_fit_coverage.py`` counts how often each covers it).
    """
    from scipy import stats

    if free < 1 or n <= free:
        raise InputError(f"free = {free}, n = {n}: need 1 <= free < n", name="free", value=free)
    if known_sd:
        return float(stats.chi2.ppf(0.95, free))
    return float(free * stats.f.ppf(0.95, free, n - free))


def _threshold(problem: Problem) -> float:
    return region_level(problem.p, problem.n, problem.data.known_sd)


def _s2(problem: Problem, cost: float) -> float:
    return 1.0 if problem.data.known_sd else max(cost, 1e-300) / (problem.n - problem.p)


def _basins(problem: Problem, profiles: dict[int, Profile], cut: float, s2: float
            ) -> list[tuple[np.ndarray, float]]:
    """The distinct local minima of all profiles at or below ``cut`` (lowest first)."""
    found = []
    for profile in profiles.values():
        t, c, xs = profile.arrays()
        found += [(xs[k], c[k]) for k in regions.basins(t, c, cut, regions.BASIN_PROMINENCE * s2)]
    found.sort(key=lambda item: item[1])
    out: list[tuple[np.ndarray, float]] = []
    for x, c in found:
        if all(np.max(np.abs(x - y)) > 1.5 * FINE_SPACING for y, _ in out) and len(out) < MAX_BASINS:
            out.append((x, c))
    return out


def _regions(problem, profiles, basin_list, x_hat, cost, s2, threshold, say):
    """Per parameter: pieces (log), the walk profile's flatness at a bound, and every basin's local
    intervals."""
    cut = cost + threshold * s2
    say(f"local intervals around {len(basin_list)} local minimum/minima of the profiles")
    local = regions.basin_intervals(problem, basin_list, s2, threshold)
    out = []
    for j in range(problem.p):
        t, c, _ = profiles[j].arrays()
        parts = regions.pieces(t, c, cut)
        walk_flat = bool(parts) and (parts[0][0] <= problem.lo[j] or parts[-1][1] >= problem.hi[j])
        parts += [intervals[j] for intervals, _ in local]
        flat = walk_flat or any(f[j] for _, f in local)
        out.append((regions.merge(parts, gap=0.5 * FINE_SPACING), flat))
    return out


def _polish(problem: Problem, profiles: dict[int, Profile], cut: float, say) -> None:
    """Full local searches from the low local minima of the profiles at or below ``cut`` (module
    docstring, stage 4): of the :data:`POLISH_CANDIDATES` lowest distinct ones, the
    :data:`MAX_BASINS` whose Gauss–Newton step in all free parameters projects the lowest cost (a
    point on a valley's wall projects a drop, a valley's bottom none)."""
    found = []
    for profile in profiles.values():
        t, c, xs = profile.arrays()
        found += [(c[k], xs[k]) for k in range(1, t.size - 1)
                  if c[k] <= cut and c[k] <= c[k - 1] and c[k] <= c[k + 1]]
    found.sort(key=lambda item: item[0])
    starts: list[np.ndarray] = []
    for _, x in found:
        if all(np.max(np.abs(x - y)) > 1.5 * FINE_SPACING for y in starts):
            starts.append(x)
        if len(starts) == POLISH_CANDIDATES:
            break
    if not starts:
        return
    problem.evaluate([v for x in starts for v in (x, *problem._steps(x, range(problem.p)))])  # one sweep
    projected = [projected_cost(problem, x, problem.fun_jac(x)[1]) for x in starts]
    chosen = [starts[k] for k in np.argsort(projected, kind="stable")[:MAX_BASINS]]
    for k, x in enumerate(chosen):
        say(f"polish {k + 1}/{len(chosen)}: a local search from a minimum of the profiles")
        problem.local(x)


def _fit(problem: Problem, drive, names, box, x_start, reading, keep, seed, say, t0) -> FitResult:
    """The stages of the module docstring, then the result."""
    p = problem.p
    threshold = _threshold(problem)
    if p == 1:  # the coarse profile over the whole bounds is the global pass
        problem.costs([x_start])
    else:
        picks = _global_pass(problem, x_start, seed, say)
        for k, (x0, c0) in enumerate(picks):
            say(f"local search {k + 1}/{len(picks)} from cost {c0:.4g}")
            problem.local(x0, FIRST_SEARCH_EVALUATIONS)
    x_hat, cost = problem.best()
    say(f"profiles over the whole bounds from cost {cost:.5g}")
    profiles = {j: Profile(j) for j in range(p)}
    coarse(problem, profiles, x_hat, cost)

    def level() -> float:
        c = problem.best()[1]
        return c + threshold * _s2(problem, c)

    walked = fill(problem, profiles, level, lambda: threshold * _s2(problem, problem.best()[1]))
    say(f"profiles sampled at {FINE_SPACING:.0%} over {walked} intervals that may hold a minimum")
    bottoms(problem, profiles, level, lambda: threshold * _s2(problem, problem.best()[1]))
    if p >= 3:
        _polish(problem, profiles, level() + threshold * _s2(problem, problem.best()[1]), say)
    converged, notes = True, []
    for attempt in range(REFITS + 1):
        x_hat, cost = problem.local(problem.best()[0])
        s2 = _s2(problem, cost)
        basin_list = _basins(problem, profiles, cost + threshold * s2, s2)
        if not any(np.array_equal(x_hat, x) for x, _ in basin_list):
            basin_list = [(x_hat, cost), *basin_list][:MAX_BASINS]
        found = _regions(problem, profiles, basin_list, x_hat, cost, s2, threshold, say)
        say("estimate " + ", ".join(f"{k} = {v:.5g}" for k, v in zip(names, np.exp(x_hat), strict=True))
            + f", cost {cost:.5g}; 95 % region: " + ", ".join(
                f"{k} in {len(parts)} piece(s)" for k, (parts, _) in zip(names, found, strict=True)))
        # the regions' points can form new local minima of a profile: their bottoms too
        bottoms(problem, profiles, level, lambda: threshold * _s2(problem, problem.best()[1]))
        lowest = problem.best()[1]
        if lowest >= cost - REFIT_MARGIN * s2:
            break
        if attempt == REFITS:
            converged = False
            notes.append(f"a point of cost {lowest:.5g} turned up below the estimate's {cost:.5g} after "
                         f"{REFITS} new searches: the least-squares minimum may not be global")
            break
        say(f"a point of cost {lowest:.5g} is below the estimate's {cost:.5g}: searching again from there")
    return _result(problem, drive, names, box, profiles, basin_list, found, x_hat, cost, s2, threshold,
                   reading, keep, converged, notes, t0)


def _result(problem, drive, names, box, profiles, basin_list, found, x_hat, cost, s2, threshold, reading,
            keep, converged, notes, t0) -> FitResult:
    data, model, n, p = problem.data, problem.model, problem.n, problem.p
    _, jac = problem.fun_jac(x_hat)
    rank = int(np.linalg.matrix_rank(jac, tol=1e-10 * max(1.0, float(np.abs(jac).max()))))
    cov = s2 * np.linalg.pinv(jac.T @ jac)
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(se, se)
    corr = np.where(np.isfinite(corr), corr, 0.0)
    np.fill_diagonal(corr, 1.0)
    basin_list = _with_piece_minima(profiles, basin_list, found)
    estimates = {}
    for j, name in enumerate(names):
        parts, flat = found[j]
        value = float(np.exp(x_hat[j]))
        t, c, _ = profiles[j].arrays()
        inside = [k for k in range(len(basin_list))
                  if any(a - 1e-12 <= basin_list[k][0][j] <= b + 1e-12 for a, b in parts)]
        basins = [{"value": float(np.exp(basin_list[k][0][j])), "cost": float(basin_list[k][1])}
                  for k in inside]
        for a, b in parts:  # a piece without a listed basin: its lowest profile point is one
            if not any(a - 1e-12 <= basin_list[k][0][j] <= b + 1e-12 for k in inside):
                sel = (t >= a) & (t <= b)
                if sel.any():
                    low = int(np.flatnonzero(sel)[np.argmin(c[sel])])
                    basins.append({"value": float(np.exp(t[low])), "cost": float(c[low])})
        basins.sort(key=lambda item: item["value"])
        at_bound = x_hat[j] <= problem.lo[j] or x_hat[j] >= problem.hi[j]
        if at_bound:
            notes.append(f"{name} is at a bound of its range: widen --bounds")
        estimates[name] = {
            "value": value, "stderr": float(value * se[j]),
            "interval": ([float(np.exp(parts[0][0])), float(np.exp(parts[-1][1]))] if parts
                         else [value, value]),
            "intervals": [[float(np.exp(a)), float(np.exp(b))] for a, b in parts],
            "basins": basins,
            "unit": FREE_PARAMETERS[name].unit, "symbol": FREE_PARAMETERS[name].symbol,
            "bounds": list(box[name]), "flat_profile": bool(flat),
            "profile": {"value": np.exp(t).tolist(), "cost": c.tolist()},
        }
    gof = goodness_of_fit(cost, n - p, data.known_sd)
    suggestion = None
    if any(len(estimates[name]["intervals"]) > 1 for name in names) and len(basin_list) > 1:
        sigma = float(np.median(problem.sigma)) * (1.0 if data.known_sd else math.sqrt(s2))
        suggestion = separating_row(model, [x for x, _ in basin_list], [c for _, c in basin_list], sigma, s2,
                                    threshold)
    ok, text = verdict(names, estimates, corr, rank, data, gof, converged, suggestion, model.drive, keep)
    fitted = replace(model.drive_at(x_hat, drive), allow_extrapolation=drive.allow_extrapolation)
    pred = problem.prediction(x_hat)
    settled = model.settled.get(x_hat.tobytes(), np.ones(n, bool))
    unsettled = [data.line[i] for i in range(n) if not settled[i]]
    if unsettled:
        notes.append("the model's step had not settled by the end of its run at line(s) "
                     + ", ".join(map(str, unsettled)) + " (the mean step of the run's second half is used)")
    return FitResult(drive=fitted, base=drive, names=names, estimates=estimates, correlation=corr, data=data,
                     predicted=pred, weights=problem.sigma, cost=cost, scale=math.sqrt(s2), dof=n - p,
                     identifiable=ok, verdict=text, reading=reading, loss=problem.loss,
                     simulations=model.simulations, evaluations=model.evaluations,
                     wall_time_s=time.perf_counter() - t0, notes=list(dict.fromkeys(notes)),
                     converged=converged, goodness_of_fit=gof, next_measurement=suggestion, keep=keep,
                     level=threshold,
                     basins=[{"parameters": dict(zip(names, np.exp(x).tolist(), strict=True)), "cost": c}
                             for x, c in basin_list],
                     region_points=_region_points(names, profiles, x_hat, cost + threshold * s2))


def _with_piece_minima(profiles: dict[int, Profile], basin_list, found) -> list[tuple[np.ndarray, float]]:
    """``basin_list`` and, for every piece of a region that holds none of them, the lowest profile point
    in it: the basins the verdict counts, the report lists and the separating row tells apart."""
    out = list(basin_list)
    for j, (parts, _) in enumerate(found):
        t, c, xs = profiles[j].arrays()
        for a, b in parts:
            if any(a - 1e-12 <= x[j] <= b + 1e-12 for x, _ in out):
                continue
            sel = np.flatnonzero((t >= a) & (t <= b))
            if sel.size:
                low = int(sel[np.argmin(c[sel])])
                out.append((np.asarray(xs[low], float), float(c[low])))
    return out


def _region_points(names, profiles: dict[int, Profile], x_hat: np.ndarray, cut: float) -> list[dict]:
    """The parameter sets at the ends of each parameter's 95 % region (the lowest and highest profile
    points within the level, the others re-fitted there): distinct ones, the estimate left out."""
    found = []
    for profile in profiles.values():
        t, c, xs = profile.arrays()
        inside = np.flatnonzero(c <= cut)
        found += [xs[k] for k in (inside[:1].tolist() + inside[-1:].tolist())]
    out: list[np.ndarray] = [np.asarray(x_hat, float)]
    for x in found:
        if all(np.max(np.abs(np.asarray(x) - y)) > 1e-12 for y in out):
            out.append(np.asarray(x, float))
    return [dict(zip(names, np.exp(x).tolist(), strict=True)) for x in out[1:]]
