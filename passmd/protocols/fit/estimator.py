"""The estimator of :func:`~passmd.protocols.fit.estimator.fit`: global pass, local least squares, scans of
rough parameters, profiles.

A scrambled Sobol design over the bounds picks the starts, ``scipy.optimize.least_squares``
refines the best of them in log-parameter space, a parameter whose residuals oscillate on the
Jacobian's scale (:data:`ROUGHNESS_LIMIT`) is scanned, and each parameter's profile likelihood
gives its 95 % interval; a profile that meets a lower cost restarts the search
(``REFITS``). The tuning constants below are the ones the method description in
:mod:`passmd.protocols.fit` refers to.
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
from passmd.protocols.fit.free_parameters import FREE_PARAMETERS, _check_free, default_bounds
from passmd.protocols.fit.measurements import (
    READINGS,
    Measurements,
)
from passmd.protocols.fit.prediction import _Model
from passmd.protocols.fit.result import FitResult, _verdict
from passmd.runtime import sweep
from passmd.runtime.config import RunConfig
from passmd.runtime.validation import InputError, check_choice

__all__ = ['GLOBAL_STARTS', 'JACOBIAN_STEP', 'LOSSES', 'ROUGHNESS_LIMIT', 'fit']

#: Relative step of the forward-difference Jacobian (in log-parameter space). 1 % stays well
#: above the critical-amplitude bisection's resolution (0.1 nm of A_c ≈ 50 nm is 0.2 %) and below
#: the curvature scale of the steady step as a function of μ, k_p, c_p (tens of %). The simulated
#: step also wiggles by fractions of a nanometre on this scale, so a local search can stop in a
#: shallow local minimum: a rough parameter is scanned (``ROUGHNESS_LIMIT``), and the profiles
#: look for lower costs and restart it (``REFITS``).
JACOBIAN_STEP = 0.01
#: Points of the global pass's Sobol design (a power of two; the start values are added).
GLOBAL_STARTS = 16
#: A profile's end is accepted where its cost rise is within this fraction of the threshold (a
#: quadratic profile then puts the end within 5 % of the interval's half-width).
PROFILE_TOLERANCE = 0.1
#: Function evaluations of each inner minimisation of a profile over the other free parameters. It
#: starts on the linearised conditional path (the covariance's regression of the others on the
#: profiled one), a few Gauss–Newton steps from the conditional minimum.
PROFILE_STEPS = 4
#: New local searches when a profile meets a lower cost than the estimate (by more than
#: REFIT_MARGIN in units of s²: a third of a 95 % profile rise, so not a rounding effect): the
#: profiles then act as further starts, and the estimate, errors and intervals are computed again.
REFITS = 2
REFIT_MARGIN = 0.5
#: Local least-squares searches started from the best points of the global pass.
LOCAL_STARTS = 2
#: Function evaluations of one local least-squares search.
LOCAL_EVALUATIONS = 60
#: A free parameter is *rough* where the forward and backward differences of the residuals at the
#: estimate (step JACOBIAN_STEP) differ by more than this fraction of their mean: the response
#: oscillates on the Jacobian's scale. The step of the six-contact flexible drive does so in k_p
#: (by ±1–2 nm with a period of about 5–9 % of k_p at 0.2–0.6 N, also in the steady state), and
#: its least-squares cost is then a comb of minima a local search cannot cross. A smooth response
#: (the step against μ or ζ) gives h·|f''/f'| ≈ 0.01–0.03.
ROUGHNESS_LIMIT = 0.25
#: Scan of a rough parameter: offsets from the estimate in log space (±SCAN_HALF_WIDTH in steps
#: of SCAN_SPACING), each with one batched Gauss–Newton step of the other free parameters, whose
#: conditional minima then spread the comb's basins to about ±2 % in k_p. The lowest point, if
#: below the estimate by REFIT_MARGIN, starts a new local search (SCAN_ROUNDS times at most: the
#: new estimate lies inside the range just scanned, and the profiles still look for lower costs).
SCAN_SPACING = 0.015
SCAN_HALF_WIDTH = 0.18
SCAN_ROUNDS = 1
#: Robust losses of ``scipy.optimize.least_squares`` (the intervals use the plain sum of squares).
LOSSES = ("linear", "soft_l1", "huber", "cauchy", "arctan")


def _weights(data: Measurements) -> np.ndarray:
    if data.known_sd:
        return data.sd.copy()
    return np.array([data.display(i)[0] for i in range(len(data))])  # one display unit


def _check_bounds(drive, names, bounds, f_max) -> dict[str, tuple[float, float]]:
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
    starts: int = GLOBAL_STARTS,
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
        :func:`~passmd.protocols.fit.measurements.measurements_from_rows`.
    free : list of str
        Names from :data:`~passmd.protocols.fit.free_parameters.FREE_PARAMETERS`.
    bounds : dict, optional
        name -> (low, high) in SI; default
        :func:`~passmd.protocols.fit.free_parameters.default_bounds`.
    reading : {"steady", "first"}
        How the simulator reads a critical amplitude (Section 4.1's two protocols).
    loss : str
        Loss of the estimate (:data:`LOSSES`); the intervals use the sum of squares.
    starts : int
        Points of the global pass (a power of two >= 2; 0: start from the drive's values only).
    seed : int
        Seed of the scrambled Sobol design (the fit is deterministic for a seed).
    executor, cache, config
        How the model evaluations run (:func:`passmd.runtime.sweep.run`); a process pool is kept for the
        whole fit.
    progress : callable, optional
        Receives one line per stage (global pass, each local search, each profile).

    Raises
    ------
    InputError
        Bad arguments; also when there are no more measurements than free parameters.
    """
    t0 = time.perf_counter()
    check_drive(drive)
    if not isinstance(data, Measurements):
        raise InputError(f"data = {data!r} is not Measurements (read_measurements)", name="data", value=data)
    names = _check_free(drive, free)
    check_choice("reading", reading, READINGS)
    check_choice("loss", loss, LOSSES)
    if isinstance(starts, bool) or not isinstance(starts, int) or starts < 0 or (starts & (starts - 1)):
        raise InputError(f"starts = {starts!r} is out of range: must be 0 or a power of two", name="starts",
                         value=starts)
    n, p = len(data), len(names)
    if n <= p:
        raise InputError(f"{n} measurements cannot determine {p} free parameters: give more measurements "
                         "than "
                         "free parameters", name="data", value=n)
    f_max = float(np.max(data.frequency))
    box = _check_bounds(drive, names, bounds, f_max)
    say = progress or (lambda line: None)
    lo = np.log([box[k][0] for k in names])
    hi = np.log([box[k][1] for k in names])
    x_start = np.clip(np.log([max(FREE_PARAMETERS[k].get(drive), 1e-300) for k in names]), lo, hi)
    sigma = _weights(data)
    config = RunConfig() if config is None else config
    chosen = executor if executor is not None else config.executor or "process"
    with contextlib.ExitStack() as stack:
        if chosen == "process":  # one pool for the whole fit (sweep.process_pool: signals, worker cap)
            chosen = stack.enter_context(sweep.process_pool(config.workers))
        model = _Model(drive, data, names, reading, executor=chosen, cache=cache, config=config)
        problem = _Problem(model, data, sigma, lo, hi, loss)
        return _fit(problem, drive, names, box, x_start, reading, starts, seed, say, t0)


class _Problem:
    """The weighted least-squares problem in log-parameter space, evaluated through the model's sweeps.

    Every method evaluates its points in as few ``model.evaluate`` calls as it can (one sweep
    each), and the model caches them, so a point met twice costs nothing the second time.
    """

    def __init__(self, model: _Model, data: Measurements, sigma: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                 loss: str):
        self.model, self.data, self.sigma, self.lo, self.hi, self.loss = model, data, sigma, lo, hi, loss
        self.n, self.p = len(data), len(lo)
        self.h = JACOBIAN_STEP

    def residual(self, pred: np.ndarray) -> np.ndarray:
        return (pred - self.data.value) / self.sigma

    def costs(self, points: Sequence[np.ndarray]) -> list[float]:
        """Sum of squared residuals at each point (one sweep)."""
        return [float(np.sum(self.residual(v) ** 2)) for v in self.model.evaluate(points)]

    def perturbed(self, x: np.ndarray, cols) -> list[np.ndarray]:
        """x stepped by +h in each column of ``cols`` (by -h where +h leaves the box)."""
        out = []
        for j in cols:
            e = np.zeros(self.p)
            e[j] = self.h if x[j] + self.h <= self.hi[j] else -self.h
            out.append(x + e)
        return out

    def fun_jac(self, x, cols=None) -> tuple[np.ndarray, np.ndarray]:
        """Residual and Jacobian (d r / d log θ; columns ``cols``), base and perturbed points in one sweep."""
        x = np.asarray(x, float)
        steps = self.perturbed(x, range(self.p) if cols is None else cols)
        base, *others = self.model.evaluate([x, *steps])
        r = self.residual(base)
        if not steps:
            return r, np.zeros((self.n, 0))
        return r, np.column_stack([(self.residual(o) - r) / (s - x).sum()
                                   for o, s in zip(others, steps, strict=True)])

    def local(self, x0: np.ndarray) -> tuple[np.ndarray, float]:
        """A bounded least-squares search from x0 (:data:`LOCAL_EVALUATIONS`): (x, cost)."""
        from scipy import optimize

        memo = {}  # the Jacobian of each residual evaluation, so jac(x) needs no second sweep

        def f(x):
            r, jac = self.fun_jac(x)
            memo[np.asarray(x, float).tobytes()] = jac
            return r

        def jf(x):
            key = np.asarray(x, float).tobytes()
            return memo[key] if key in memo else self.fun_jac(x)[1]

        sol = optimize.least_squares(f, x0, jac=jf, bounds=(self.lo, self.hi), loss=self.loss, method="trf",
                                     x_scale=1.0, xtol=1e-6, ftol=1e-8, gtol=1e-8, max_nfev=LOCAL_EVALUATIONS)
        return sol.x, float(np.sum(f(sol.x) ** 2))

    def rough(self, x: np.ndarray) -> list[int]:
        """Indices of the free parameters whose residuals oscillate on the Jacobian's scale at x
        (forward and backward differences disagree by more than :data:`ROUGHNESS_LIMIT`)."""
        p, h, lo = self.p, self.h, self.lo
        steps = [x + np.eye(p)[j] * (-h if x[j] - h >= lo[j] else h) for j in range(p)]
        r, jac = self.fun_jac(x)
        back = self.model.evaluate(steps)
        out = []
        for j in range(p):
            other = (self.residual(back[j]) - r) / (steps[j] - x).sum()
            mean = 0.5 * np.linalg.norm(jac[:, j] + other)
            # only a response that matters across the scan: a change of more than one σ
            if (np.linalg.norm(jac[:, j] - other) > ROUGHNESS_LIMIT * mean
                    and max(np.linalg.norm(jac[:, j]), np.linalg.norm(other)) * SCAN_HALF_WIDTH > 1.0):
                out.append(j)
        return out

    def scan(self, x: np.ndarray, j: int) -> tuple[np.ndarray, float]:
        """(x, cost) of the lowest point of a scan of parameter j, the others one Gauss–Newton step
        from x's (all points in one sweep per stage)."""
        p, h, lo, hi = self.p, self.h, self.lo, self.hi
        others = [k for k in range(p) if k != j]
        count = int(round(SCAN_HALF_WIDTH / SCAN_SPACING))
        points = []
        for k in range(-count, count + 1):
            t = x[j] + k * SCAN_SPACING
            if k and lo[j] <= t <= hi[j]:
                y = np.array(x, float)
                y[j] = t
                points.append(y)
        if others:
            trials = [[y, *(y + np.eye(p)[m] * (h if y[m] + h <= hi[m] else -h) for m in others)]
                      for y in points]
            values = self.model.evaluate([v for group in trials for v in group])
            moved = []
            for i, group in enumerate(trials):
                base = self.residual(values[i * (len(others) + 1)])
                jac = np.column_stack([(self.residual(values[i * (len(others) + 1) + 1 + a]) - base)
                                       / (group[1 + a] - group[0]).sum() for a in range(len(others))])
                step = np.linalg.lstsq(jac, -base, rcond=None)[0]
                y = np.array(group[0], float)
                y[others] = np.clip(y[others] + step, lo[others], hi[others])
                moved.append(y)
            points = points + moved
        costs = self.costs(points)
        k = int(np.argmin(costs))
        return points[k], costs[k]

    def profile_cost(self, j: int, t: float, start_others, x_hat: np.ndarray, lowest: list) -> float:
        """Least-squares cost with parameter j fixed at t (log), minimised over the others from
        ``start_others`` (:data:`PROFILE_STEPS`); ``lowest`` = [cost, x] keeps the lowest cost met."""
        from scipy import optimize

        others = [k for k in range(self.p) if k != j]

        def full(y):
            x = np.array(x_hat, float)
            x[j] = t
            x[others] = y
            return x

        if not others:
            c = float(np.sum(self.fun_jac(full([]), [])[0] ** 2))
            if c < lowest[0]:
                lowest[:] = [c, full([])]
            return c
        sol = optimize.least_squares(lambda y: self.fun_jac(full(y), others)[0], start_others,
                                     jac=lambda y: self.fun_jac(full(y), others)[1],
                                     bounds=(self.lo[others], self.hi[others]), method="trf", xtol=1e-4,
                                     ftol=1e-5, max_nfev=PROFILE_STEPS)
        c = float(np.sum(self.fun_jac(full(sol.x), others)[0] ** 2))
        if c < lowest[0]:
            lowest[:] = [c, full(sol.x)]
        return c


def _global_pass(problem: _Problem, x_start: np.ndarray, starts: int, seed: int, say) -> list[tuple]:
    """The best :data:`LOCAL_STARTS` of the start values and a scrambled Sobol design over the log box
    (one sweep), as (x, cost) pairs, lowest cost first."""
    from scipy.stats import qmc

    lo, hi = problem.lo, problem.hi
    candidates = [x_start]
    if starts:
        design = qmc.Sobol(d=problem.p, scramble=True, seed=seed).random(starts)
        candidates += [lo + u * (hi - lo) for u in design]
    say(f"global pass: {len(candidates)} parameter sets × {problem.n} measurements")
    costs = problem.costs(candidates)
    order = np.argsort(costs)
    return [(candidates[k], costs[k]) for k in order[:LOCAL_STARTS]]


def _search(problem: _Problem, picks: list[tuple], names: list[str], say) -> tuple[np.ndarray, float]:
    """The estimate (x, cost): local searches from the picks, then at most :data:`SCAN_ROUNDS`
    scans of the rough parameters, each restarting the local search from a lower cost it meets."""
    best = None
    for k, (x0, c0) in enumerate(picks):
        say(f"local search {k + 1}/{len(picks)} from cost {c0:.4g}")
        x, c = problem.local(x0)
        if best is None or c < best[1]:
            best = (x, c)
    x_hat, cost = best
    n, p = problem.n, problem.p
    for _ in range(SCAN_ROUNDS):
        found = None
        margin = REFIT_MARGIN * (1.0 if problem.data.known_sd else cost / (n - p))
        for j in problem.rough(x_hat):
            say(f"{names[j]}: the residuals oscillate on the Jacobian's scale; scanning "
                f"±{SCAN_HALF_WIDTH:.0%}")
            x_scan, c_scan = problem.scan(x_hat, j)
            if c_scan < cost - margin and (found is None or c_scan < found[1]):
                found = (x_scan, c_scan)
        if found is None:
            break
        say(f"the scan met cost {found[1]:.5g} below the estimate's {cost:.5g}: searching again from there")
        x_new, c_new = problem.local(found[0])
        x_hat, cost = (x_new, c_new) if c_new < found[1] else found
    return x_hat, cost


def _covariance(problem: _Problem, x_hat: np.ndarray, cost: float):
    """(s², Jacobian rank, covariance, standard errors, correlation) of the log parameters at x_hat."""
    _, J = problem.fun_jac(x_hat)
    s2 = 1.0 if problem.data.known_sd else cost / (problem.n - problem.p)
    jtj = J.T @ J
    rank = int(np.linalg.matrix_rank(J, tol=1e-10 * max(1.0, float(np.abs(J).max()))))
    cov = s2 * np.linalg.pinv(jtj)
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(se, se)
    corr = np.where(np.isfinite(corr), corr, 0.0)
    np.fill_diagonal(corr, 1.0)
    return s2, rank, cov, se, corr


class _Profile:
    """Parameter j's profile around the estimate: the cost rise (in units of s²) at a log distance
    ``delta`` on side ``sign``, the others starting on the covariance's linearised conditional path."""

    def __init__(self, problem: _Problem, j: int, x_hat, cost: float, s2: float, cov, lowest: list):
        self.problem, self.j, self.x_hat, self.lowest = problem, j, x_hat, lowest
        self.cost, self.s2 = cost, s2
        self.others = [k for k in range(problem.p) if k != j]
        self.slope = np.zeros(len(self.others))
        if self.others and cov[j, j] > 0:
            self.slope = cov[self.others, j] / cov[j, j]

    def rise(self, sign: float, delta: float) -> float:
        lo, hi, others, x_hat = self.problem.lo, self.problem.hi, self.others, self.x_hat
        t = x_hat[self.j] + sign * delta
        y0 = (np.clip(x_hat[others] + self.slope * sign * delta, lo[others], hi[others]) if others
              else [])
        c = self.problem.profile_cost(self.j, t, y0, x_hat, self.lowest)
        return (c - self.cost) / self.s2


def _profile_end(profile: _Profile, sign: float, se: float, threshold: float) -> tuple[float, bool]:
    """One end of a 95 % profile interval (log): (end, flat), flat when the rise stays below the
    threshold up to the bound. The quadratic approximation's end first, then doubling the distance
    until the rise crosses the threshold, then a root search on the signed root of the rise."""
    j, x_hat = profile.j, profile.x_hat
    limit = (profile.problem.lo if sign < 0 else profile.problem.hi)[j]
    room = abs(limit - x_hat[j])
    d_in, v_in = 0.0, 0.0
    guess = math.sqrt(threshold) * se if np.isfinite(se) and se > 0 else 0.1
    delta = min(max(guess, 0.02), room)
    v = profile.rise(sign, delta)
    if abs(v - threshold) < PROFILE_TOLERANCE * threshold:
        return x_hat[j] + sign * delta, False
    while v < threshold and delta < room:
        d_in, v_in = delta, v
        delta = min(2.0 * delta, room)
        v = profile.rise(sign, delta)
    if v < threshold:  # flat up to the bound
        return limit, True
    for _ in range(4):  # the signed root of the profile is about linear in delta
        a, b = math.sqrt(max(v_in, 0.0)), math.sqrt(max(v, 0.0))
        mid = (d_in + (delta - d_in) * (math.sqrt(threshold) - a) / (b - a) if b > a
               else 0.5 * (d_in + delta))
        mid = min(max(mid, d_in + 0.05 * (delta - d_in)), delta - 0.05 * (delta - d_in))
        vm = profile.rise(sign, mid)
        if abs(vm - threshold) < PROFILE_TOLERANCE * threshold:
            delta = mid
            break
        if vm < threshold:
            d_in, v_in = mid, vm
        else:
            delta, v = mid, vm
    return x_hat[j] + sign * delta, False


def _estimates(problem: _Problem, names, box, x_hat, cost, s2, cov, se, threshold, lowest, notes, say):
    """Each free parameter's estimate, standard error and profile interval ({name: record}, {name:
    flat profile}); a bound the estimate sits on adds a note to ``notes``."""
    estimates: dict[str, dict] = {}
    flat: dict[str, bool] = {}
    for j, name in enumerate(names):
        say(f"profile of {name} ({j + 1}/{problem.p})")
        profile = _Profile(problem, j, x_hat, cost, s2, cov, lowest)
        ends = []
        reached = False
        for sign in (-1.0, 1.0):
            limit = (problem.lo if sign < 0 else problem.hi)[j]
            if abs(limit - x_hat[j]) <= 0.0:  # the estimate is at this bound: the interval ends there
                ends.append(limit)
                notes.append(f"{name} is at its {'lower' if sign < 0 else 'upper'} bound: widen --bounds")
                continue
            end, at_bound = _profile_end(profile, sign, se[j], threshold)
            ends.append(end)
            reached = reached or at_bound
        value = float(np.exp(x_hat[j]))
        flat[name] = reached
        estimates[name] = {"value": value, "stderr": float(value * se[j]),
                           "interval": [float(np.exp(ends[0])), float(np.exp(ends[1]))],
                           "unit": FREE_PARAMETERS[name].unit, "symbol": FREE_PARAMETERS[name].symbol,
                           "bounds": list(box[name]), "flat_profile": reached}
    return estimates, flat


def _fit(problem: _Problem, drive, names, box, x_start, reading, starts, seed, say, t0) -> FitResult:
    """Global pass, local searches and scans, then errors and profiles; a profile that meets a lower
    cost restarts the local search from there (:data:`REFITS` times at most)."""
    from scipy import stats

    data, model, n, p = problem.data, problem.model, problem.n, problem.p
    x_hat, cost = _search(problem, _global_pass(problem, x_start, starts, seed, say), names, say)
    dof = n - p
    threshold = float(stats.chi2.ppf(0.95, 1) if data.known_sd else stats.f.ppf(0.95, 1, dof))
    notes: list[str] = []
    converged = True
    for attempt in range(REFITS + 1):
        say("estimate " + ", ".join(f"{k} = {v:.5g}" for k, v in zip(names, np.exp(x_hat), strict=True))
            + f", cost {cost:.5g}")
        s2, rank, cov, se, corr = _covariance(problem, x_hat, cost)
        lowest = [cost, x_hat]  # the lowest cost a profile meets, and where
        estimates, flat = _estimates(problem, names, box, x_hat, cost, s2, cov, se, threshold, lowest, notes,
                                     say)
        if lowest[0] >= cost - REFIT_MARGIN * s2:
            break
        if attempt == REFITS:
            converged = False
            notes.append(f"a profile met cost {lowest[0]:.5g} below the estimate's {cost:.5g} after {REFITS} "
                         "new searches: the least-squares minimum may not be global (widen --starts)")
            break
        say(f"a profile met cost {lowest[0]:.5g} below the estimate's {cost:.5g}: searching again from there")
        x_hat, cost = problem.local(lowest[1])
    notes = list(dict.fromkeys(notes))
    identifiable, verdict = _verdict(names, corr, flat, rank, data)
    if not converged:
        identifiable = False
        verdict = (f"Not converged to the global minimum: a profile met cost {lowest[0]:.5g} below the "
                   f"estimate's {cost:.5g}, so the standard errors and intervals describe a local minimum "
                   "and claim nothing about the parameters; rerun with more --starts or narrower --bounds. "
                   + verdict)
    fitted = replace(model.drive_at(x_hat, drive), allow_extrapolation=drive.allow_extrapolation)
    pred = model.evaluate([x_hat])[0]
    return FitResult(drive=fitted, base=drive, names=names, estimates=estimates, correlation=corr, data=data,
                     predicted=pred, weights=problem.sigma, cost=cost, scale=math.sqrt(s2), dof=dof,
                     identifiable=identifiable, verdict=verdict, reading=reading, loss=problem.loss,
                     simulations=model.simulations, evaluations=model.evaluations,
                     wall_time_s=time.perf_counter() - t0, notes=notes, converged=converged)
