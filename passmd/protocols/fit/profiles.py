"""Profiles of a calibration's cost over each free parameter's whole range.

A parameter's profile is the least-squares cost with that parameter fixed and the others
re-minimised (:meth:`passmd.protocols.fit.problem.Problem.conditional`, warm-started from the
neighbouring grid point). The steady step of a flexible drive oscillates in the actuator
stiffness (the runner's residual vibration meets the next fly-back at a phase that turns with
k_p: a period of 7–12 % of k_p, ±1.5–3 nm at 100 Hz), so along k_p the cost is a comb whose teeth
a local search or a local profile cannot see past. The profile is therefore built in stages:

1. **Coarse**: points :data:`PROFILE_SPACING` apart in log (at least :data:`PROFILE_MIN_POINTS`)
   over the whole bounds, walked outward from the estimate (:func:`coarse`).
2. **Fill**: a coarse interval may hold a tooth within the 95 % level that the coarse grid
   stepped over. A few points in the lowest intervals first probe whether the profile is smooth
   on the coarse grid (then nothing is sampled finely). Else the lowest intervals of each
   parameter are sampled at :data:`FINE_SPACING` (a
   fifth of the comb's shortest period) first; how far their fine points' predictions depart from
   the straight line between the interval's ends measures each measurement's oscillation. Every
   interval whose predictions, widened by :data:`FILL_SAFETY` × that amplitude, could reach a cost
   within the level is sampled too, most promising first, in batches of :data:`FILL_BATCH`
   (:func:`fill`): where the data cannot rule a tooth out, the profile looks.
3. **Bottoms**: the bottom of every local minimum within reach of the level, by successive
   parabolic interpolation inside the bracket of its neighbours (:func:`bottoms`).

Every point evaluated on the way joins the problem's archive, whose lowest point is the estimate.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from passmd.protocols.fit.problem import Problem

__all__ = ["BOTTOM_DROP", "BOTTOM_FIRST", "BOTTOM_MAX", "BOTTOM_RESOLUTION", "BOTTOM_STEPS", "FILL_BATCH",
           "FILL_FIRST", "FILL_SAFETY", "FINE_SPACING", "PROBE_POINTS", "PROFILE_MIN_POINTS",
           "PROFILE_SPACING", "SMOOTH_DEPARTURE", "Profile", "bottoms", "coarse", "fill", "projected_cost",
           "walk"]

#: Spacing of the coarse profile over a parameter's whole bounds (log units: 16 %), so that of the two
#: coarse points around any value one lies within 8 % of it, about one period of the comb.
PROFILE_SPACING = 0.15
#: Fewest points of a coarse profile (a narrow range still gets a profile).
PROFILE_MIN_POINTS = 16
#: Spacing of the fine profile (log units, 1 %): a fifth of the shortest period of the step's
#: oscillation in k_p seen at 100 Hz (about 7 %), so every tooth of the comb holds several points.
FINE_SPACING = 0.01
#: Coarse intervals sampled first, per parameter (the lowest ones): they measure the oscillation.
FILL_FIRST = 2
#: Points of each of the FILL_FIRST lowest coarse intervals that probe whether a profile is smooth.
PROBE_POINTS = 3
#: A profile is smooth on the coarse grid when its probe points' predictions depart from the straight
#: line between their interval's ends by at most this many σ: no comb to sample finely.
SMOOTH_DEPARTURE = 0.5
#: Coarse intervals sampled per later batch.
FILL_BATCH = 6
#: Factor on the measured amplitude of the predictions' oscillation when deciding whether an interval
#: could hold a minimum (the amplitude varies along the range).
FILL_SAFETY = 1.0
#: Local minima of each profile whose bottoms are looked for first (:func:`bottoms`).
BOTTOM_FIRST = 3
#: A local minimum's bottom is looked for when its grid value lies within the 95 % level plus this
#: many times the largest drop from a grid value to its bottom seen so far.
BOTTOM_DROP = 2.0
#: Most local minima of one profile whose bottoms are looked for (the lowest).
BOTTOM_MAX = 16
#: Points added per local minimum, each narrowing its bracket by parabolic interpolation.
BOTTOM_STEPS = 6
#: A bracket narrower than this (log units: 0.02 %) has found its bottom.
BOTTOM_RESOLUTION = 2e-4


@dataclass
class Profile:
    """Parameter ``j``'s profile: at each grid value t (log), the lowest cost found with θ_j = e^t and
    the vector where it was found."""

    j: int
    points: dict[float, tuple[float, np.ndarray]] = field(default_factory=dict)

    def add(self, t: float, cost: float, x: np.ndarray) -> None:
        t = float(t)
        if t not in self.points or cost < self.points[t][0]:
            self.points[t] = (float(cost), np.asarray(x, float).copy())

    def arrays(self) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
        """(t, cost, x) sorted by t."""
        ts = sorted(self.points)
        return np.array(ts), np.array([self.points[t][0] for t in ts]), [self.points[t][1] for t in ts]


def walk(problem: Problem, profiles: dict[int, Profile], walkers: list[tuple[int, list[float], np.ndarray]]
         ) -> None:
    """Walk each ``(j, ts, x)``: parameter j fixed at ts in turn, the others re-minimised from the
    previous point's (starting from x's); all walkers advance together (two sweeps per step)."""
    if problem.p == 1:  # nothing to re-minimise: every point in one sweep
        xs = [np.array([t]) for _, ts, _ in walkers for t in ts]
        for x, c in zip(xs, problem.costs(xs), strict=True):
            profiles[0].add(x[0], c, x)
        return
    active = [[j, list(ts), np.asarray(x, float)] for j, ts, x in walkers if len(ts)]
    while active:
        results = problem.conditional([(j, ts[0], x) for j, ts, x in active])
        for walker, (x, c) in zip(active, results, strict=True):
            j, ts, _ = walker
            profiles[j].add(ts.pop(0), c, x)
            walker[2] = x
        active = [w for w in active if w[1]]


def coarse(problem: Problem, profiles: dict[int, Profile], x_hat: np.ndarray, cost: float) -> None:
    """The coarse profile of every parameter over its bounds (module docstring), walked outward from
    the estimate on both sides."""
    walkers = []
    for j in range(problem.p):
        profiles[j].add(x_hat[j], cost, x_hat)
        points = max(PROFILE_MIN_POINTS, math.ceil((problem.hi[j] - problem.lo[j]) / PROFILE_SPACING) + 1)
        grid = np.linspace(problem.lo[j], problem.hi[j], points)
        walkers.append((j, [float(t) for t in grid[grid > x_hat[j]]], x_hat))
        walkers.append((j, [float(t) for t in grid[grid < x_hat[j]][::-1]], x_hat))
    walk(problem, profiles, walkers)


def projected_cost(problem: Problem, x: np.ndarray, jac: np.ndarray) -> float:
    """The cost at ``x`` after a linear least-squares step of the Jacobian ``jac``'s columns."""
    r = problem.residual(problem.prediction(x))
    if jac.shape[1] == 0:
        return float(np.sum(r ** 2))
    step = np.linalg.lstsq(jac, -r, rcond=None)[0]
    return float(np.sum((r + jac @ step) ** 2))


def _reach(problem: Problem, pa: np.ndarray, pb: np.ndarray, comb: np.ndarray) -> float:
    """The lowest cost the predictions between two profile points can reach if each measurement's
    prediction stays within the span of its values there widened by ``comb`` (its oscillation's
    amplitude)."""
    low, high = np.minimum(pa, pb) - comb, np.maximum(pa, pb) + comb
    y = problem.data.value
    gap = np.maximum(0.0, np.maximum(low - y, y - high)) / problem.sigma
    return float(np.sum(gap ** 2))


def fill(problem: Problem, profiles: dict[int, Profile], level: Callable[[], float],
         margin: Callable[[], float]) -> int:
    """Sample at :data:`FINE_SPACING` the coarse intervals that may hold a minimum within the 95 % level
    (module docstring), most promising first; returns the number of intervals sampled.

    ``level()`` gives the current 95 % level, ``margin()`` the 95 % rise. A parameter whose profile is
    smooth on the coarse grid (``_probe``) needs none. Else first the
    :data:`FILL_FIRST` lowest intervals of each parameter: their fine points measure how far each
    measurement's prediction departs from the straight line between the interval's ends (the
    amplitude of its oscillation). Then, batch by batch, every interval whose predictions, widened
    by :data:`FILL_SAFETY` × that amplitude, could reach a cost within the level (``_reach``).
    """
    done: set[tuple[int, float]] = set()
    comb = {j: np.zeros(problem.n) for j in profiles}
    smooth = _probe(problem, profiles)
    first = True
    while True:
        cut = level()
        candidates = []
        for j, profile in profiles.items():
            if j in smooth:
                continue
            t, c, xs = profile.arrays()
            mine = []
            for k in range(t.size - 1):
                if t[k + 1] - t[k] <= 1.5 * FINE_SPACING or (j, float(t[k])) in done:
                    continue
                if first:
                    mine.append((min(c[k], c[k + 1]), j, k, t, xs))
                    continue
                pa, pb = problem.evaluate([xs[k], xs[k + 1]])
                reach = _reach(problem, pa, pb, FILL_SAFETY * comb[j])
                if reach <= cut:
                    mine.append((reach, j, k, t, xs))
            candidates += sorted(mine, key=lambda m: m[0])[:FILL_FIRST] if first else mine
        if not candidates:
            return len(done)
        batch = candidates if first else sorted(candidates, key=lambda m: m[0])[:FILL_BATCH]
        first = False
        done.update((j, float(t[k])) for _, j, k, t, _ in batch)
        intervals = [(j, t[k], t[k + 1], xs[k], xs[k + 1]) for _, j, k, t, xs in batch]
        _sample(problem, profiles, intervals, level() + margin())
        for j, a, b, xa, xb in intervals:  # the oscillation's amplitude along the interval
            pa, pb = problem.evaluate([xa, xb])
            tt, _, xx = profiles[j].arrays()
            for t_in, x_in in zip(tt, xx, strict=True):
                if a < t_in < b:
                    w = (t_in - a) / (b - a)
                    line = (1.0 - w) * pa + w * pb
                    comb[j] = np.maximum(comb[j], np.abs(problem.prediction(x_in) - line))


def _probe(problem: Problem, profiles: dict[int, Profile]) -> set[int]:
    """The parameters whose profile is smooth on the coarse grid: in the :data:`FILL_FIRST` lowest
    coarse intervals, :data:`PROBE_POINTS` evenly spaced points (the others interpolated, one
    evaluation each) depart from the straight line between the interval's ends by at most
    :data:`SMOOTH_DEPARTURE` σ in every measurement."""
    jobs = []
    for j, profile in profiles.items():
        t, c, xs = profile.arrays()
        lows = sorted((min(c[k], c[k + 1]), k) for k in range(t.size - 1)
                      if t[k + 1] - t[k] > 1.5 * FINE_SPACING)
        for _, k in lows[:FILL_FIRST]:
            for i in range(1, PROBE_POINTS + 1):
                w = i / (PROBE_POINTS + 1)
                x = (1.0 - w) * xs[k] + w * xs[k + 1]
                x[j] = t[k] + w * (t[k + 1] - t[k])
                jobs.append((j, w, x, xs[k], xs[k + 1]))
    values = problem.evaluate([x for _, _, x, _, _ in jobs])
    departure = dict.fromkeys(profiles, 0.0)
    for (j, w, x, xa, xb), v in zip(jobs, values, strict=True):
        profiles[j].add(x[j], problem.archive[x.tobytes()][1], x)
        pa, pb = problem.evaluate([xa, xb])
        line = (1.0 - w) * pa + w * pb
        departure[j] = max(departure[j], float(np.max(np.abs(v - line) / problem.sigma)))
    return {j for j in profiles if departure[j] <= SMOOTH_DEPARTURE}


def _sample(problem: Problem, profiles: dict[int, Profile], intervals, cut: float) -> None:
    """Fine points of each interval (j, a, b, x_a, x_b), one evaluation each, the others interpolated
    between the ends', and a Gauss–Newton step where the cost projected through the nearer end's
    Jacobian of the others is within ``cut`` (:func:`fill`)."""
    jobs = []
    for j, a, b, xa, xb in intervals:
        m = math.ceil((b - a) / FINE_SPACING)
        for i in range(1, m):
            w = i / m
            x = (1.0 - w) * xa + w * xb
            x[j] = a + w * (b - a)
            jobs.append((j, x, xa if w <= 0.5 else xb))
    cols = {j: [k for k in range(problem.p) if k != j] for j in profiles}
    ends = {(e.tobytes(), j): (e, j) for j, _, e in jobs}
    batch = [x for _, x, _ in jobs]
    for e, j in ends.values():
        batch += problem._steps(e, cols[j])
    problem.evaluate(batch)  # the fine points and the ends' Jacobians, one sweep
    jacobians = {key: problem.fun_jac(e, cols[j])[1] for key, (e, j) in ends.items()}
    tasks = []
    for j, x, e in jobs:
        profiles[j].add(x[j], problem.archive[x.tobytes()][1], x)
        if projected_cost(problem, x, jacobians[(e.tobytes(), j)]) <= cut:
            tasks.append((j, x[j], x))
    if tasks:
        for (j, t, _), (x, c) in zip(tasks, problem.conditional(tasks), strict=True):
            profiles[j].add(t, c, x)


def _vertex(ta, ca, tb, cb, tc, cc) -> float:
    """The abscissa of the parabola through three points (b the lowest, a < b < c), kept inside (a, c)
    and away from b; the midpoint of the longer side when the parabola does not open upward."""
    num = (tb - ta) ** 2 * (cb - cc) - (tb - tc) ** 2 * (cb - ca)
    den = (tb - ta) * (cb - cc) - (tb - tc) * (cb - ca)
    longer = 0.5 * (ta + tb) if tb - ta > tc - tb else 0.5 * (tb + tc)
    if den == 0.0:
        return longer
    v = tb - 0.5 * num / den
    if not (ta < v < tc) or abs(v - tb) < 0.01 * (tc - ta):
        return longer
    return v


def bottoms(problem: Problem, profiles: dict[int, Profile], level: Callable[[], float],
            margin: Callable[[], float]) -> None:
    """Find the bottom of every local minimum of a profile that may lie within the 95 % level.

    A tooth of the comb can be narrower than the fine grid (0.3 % of k_p at Δχ² = 3.84 for 15 steps
    of six contacts at 0.5 nm), so a grid point can sit far up its flank. Each local minimum of the
    profile as sampled so far (lower than one neighbour, not higher than the other) is bracketed by
    its neighbours and narrowed by successive parabolic interpolation (each new point with the
    others re-minimised), all minima in lockstep, until the bracket is narrower than
    :data:`BOTTOM_RESOLUTION` or :data:`BOTTOM_STEPS` points were added. First the
    :data:`BOTTOM_FIRST` lowest minima of each parameter; then every other minimum whose grid value
    lies within the level plus :data:`BOTTOM_DROP` × the largest drop from a grid value to its bottom
    seen so far, at most :data:`BOTTOM_MAX` per parameter in all.
    """
    minima = {}
    for j, profile in profiles.items():
        t, c, _ = profile.arrays()
        found = [(float(c[k]), float(t[k - 1]), float(t[k + 1])) for k in range(1, t.size - 1)
                 if c[k] <= c[k - 1] and c[k] <= c[k + 1] and (c[k] < c[k - 1] or c[k] < c[k + 1])]
        minima[j] = sorted(found)[:BOTTOM_MAX]
    drop = dict.fromkeys(profiles, 0.0)
    first = True
    while True:
        cut = level() + margin()
        chase = []
        for j in profiles:
            reach = cut + BOTTOM_DROP * drop[j]
            take = minima[j][:BOTTOM_FIRST] if first else [m for m in minima[j] if m[0] <= reach]
            minima[j] = [m for m in minima[j] if m not in take]
            chase += [(j, a, b, grid) for grid, a, b in take]
        first = False
        if not chase:
            return
        for _ in range(BOTTOM_STEPS):
            tasks = []
            for j, a, b, _ in chase:
                t, c, xs = profiles[j].arrays()
                inside = np.flatnonzero((t >= a) & (t <= b))
                k = int(inside[np.argmin(c[inside])])
                if k == 0 or k == t.size - 1 or t[k + 1] - t[k - 1] < BOTTOM_RESOLUTION:
                    continue
                v = _vertex(t[k - 1], c[k - 1], t[k], c[k], t[k + 1], c[k + 1])
                tasks.append((j, v, xs[k]))
            if not tasks:
                break
            for (j, v, _), (x, cost) in zip(tasks, problem.conditional(tasks), strict=True):
                profiles[j].add(v, cost, x)
        for j, a, b, grid in chase:
            t, c, _ = profiles[j].arrays()
            drop[j] = max(drop[j], grid - float(c[(t >= a) & (t <= b)].min()))
