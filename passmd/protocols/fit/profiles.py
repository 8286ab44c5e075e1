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
   stepped over. The lowest intervals of each parameter are sampled at :data:`FINE_SPACING` (a
   fifth of the comb's shortest period) first; how far their fine points drop below the lower end
   of their interval measures how deep a tooth can hide between two coarse points, and every
   interval whose lower end lies within :data:`FILL_DROP` such drops above the level is sampled
   too, most promising first, in batches of :data:`FILL_BATCH` (:func:`fill`).
3. **Deepen**: around each local minimum within reach of the level the grid is halved
   :data:`DEEP_LEVELS` times (:func:`deepen`).

Every point evaluated on the way joins the problem's archive, whose lowest point is the estimate.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from passmd.protocols.fit.problem import Problem

__all__ = ["DEEP_LEVELS", "FILL_BATCH", "FILL_DROP", "FINE_SPACING", "PROFILE_MIN_POINTS", "PROFILE_SPACING",
           "Profile", "coarse", "deepen", "fill", "walk"]

#: Spacing of the coarse profile over a parameter's whole bounds (log units: 16 %), so that of the two
#: coarse points around any value one lies within 8 % of it, about one period of the comb.
PROFILE_SPACING = 0.15
#: Fewest points of a coarse profile (a narrow range still gets a profile).
PROFILE_MIN_POINTS = 16
#: Spacing of the fine profile (log units, 1 %): a fifth of the shortest period of the step's
#: oscillation in k_p seen at 100 Hz (about 7 %), so every tooth of the comb holds several points.
FINE_SPACING = 0.01
#: Coarse intervals sampled per batch (per parameter in the first batch).
FILL_BATCH = 4
#: A coarse interval is sampled when its lower end lies within this many times the largest drop seen
#: so far above the 95 % level: a tooth the coarse grid stepped over lies at most about one such drop
#: below its interval's lower end.
FILL_DROP = 2.0
#: Halvings of the grid around a local minimum within reach of the 95 % level (to 0.25 %).
DEEP_LEVELS = 2


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


def _projected(problem: Problem, x: np.ndarray, jac: np.ndarray) -> float:
    """The cost at ``x`` after a linear least-squares step of the Jacobian ``jac``'s columns."""
    r = problem.residual(problem.prediction(x))
    if jac.shape[1] == 0:
        return float(np.sum(r ** 2))
    step = np.linalg.lstsq(jac, -r, rcond=None)[0]
    return float(np.sum((r + jac @ step) ** 2))


def fill(problem: Problem, profiles: dict[int, Profile], level: Callable[[], float],
         margin: Callable[[], float]) -> int:
    """Sample at :data:`FINE_SPACING` the coarse intervals that may hold a minimum within the 95 % level
    (module docstring), most promising first; returns the number of intervals sampled.

    ``level()`` gives the current 95 % level, ``margin()`` the 95 % rise. First the
    :data:`FILL_BATCH` lowest intervals of each parameter; then, batch by batch, every interval
    whose lower end lies within :data:`FILL_DROP` × the largest drop seen so far (how far below the
    lower end of its interval a sampled point went) above the level.
    """
    done: set[tuple[int, float]] = set()
    drops = dict.fromkeys(profiles, 0.0)
    first = True
    while True:
        cut = level()
        candidates = []
        for j, profile in profiles.items():
            t, c, xs = profile.arrays()
            coarse = [k for k in range(t.size - 1) if t[k + 1] - t[k] > 1.5 * FINE_SPACING
                      and (j, float(t[k])) not in done]
            mine = sorted((min(c[k], c[k + 1]), j, k, t, c, xs) for k in coarse)
            reach = cut + FILL_DROP * drops[j]
            candidates += mine[:FILL_BATCH] if first else [m for m in mine if m[0] <= reach]
        first = False
        if not candidates:
            return len(done)
        candidates.sort(key=lambda item: item[0])
        batch = candidates[:FILL_BATCH * (len(profiles) if len(done) == 0 else 1)]
        done.update((j, float(t[k])) for _, j, k, t, _, _ in batch)
        _sample(problem, profiles, [(j, t[k], t[k + 1], xs[k], xs[k + 1]) for _, j, k, t, _, xs in batch],
                level() + margin())
        for low, j, k, t, _, _ in batch:
            tt, cc, _ = profiles[j].arrays()
            inside = (tt > t[k]) & (tt < t[k + 1])
            if inside.any():
                drops[j] = max(drops[j], low - float(cc[inside].min()))


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
        if _projected(problem, x, jacobians[(e.tobytes(), j)]) <= cut:
            tasks.append((j, x[j], x))
    if tasks:
        for (j, t, _), (x, c) in zip(tasks, problem.conditional(tasks), strict=True):
            profiles[j].add(t, c, x)


def deepen(problem: Problem, profiles: dict[int, Profile], cut: float, margin: float) -> None:
    """Halve the grid :data:`DEEP_LEVELS` times next to each local minimum of a profile whose cost is
    below ``cut + margin``, starting the others from the minimum's."""
    for _ in range(DEEP_LEVELS):
        tasks = []
        for j, profile in profiles.items():
            t, c, xs = profile.arrays()
            for k in range(t.size):
                if c[k] > cut + margin:
                    continue
                if (k > 0 and c[k - 1] < c[k]) or (k + 1 < t.size and c[k + 1] < c[k]):
                    continue
                for other in (k - 1, k + 1):
                    if 0 <= other < t.size and abs(t[other] - t[k]) > 0.2 * FINE_SPACING:
                        tasks.append((j, 0.5 * (t[k] + t[other]), xs[k]))
        if not tasks:
            return
        for (j, t, _), (x, c) in zip(tasks, problem.conditional(tasks), strict=True):
            profiles[j].add(t, c, x)
