"""Profiles of a calibration's cost over each free parameter's whole range.

A parameter's profile is the least-squares cost with that parameter fixed and the others
re-minimised (:meth:`passmd.protocols.fit.problem.Problem.conditional`, warm-started from the
neighbouring grid point). The steady step of a flexible drive oscillates in the actuator
stiffness (the runner's residual vibration meets the next fly-back at a phase that turns with
k_p: a period of 7–12 % of k_p, ±1.5–3 nm at 100 Hz), so along k_p the cost is a comb whose teeth
a local search or a local profile cannot see past. The profile is therefore built in stages:

1. **Coarse**: :data:`PROFILE_POINTS` points evenly spaced in log over the whole bounds, walked
   outward from the estimate (:func:`coarse`).
2. **Swing**: a fine walk (:data:`FINE_SPACING`) of :data:`COMB_WINDOW` points either side of the
   estimate measures how far the cost swings between neighbouring teeth (:func:`swing`).
3. **Fill**: every coarse interval whose lower end lies within :data:`FILL_SWING` swings of the
   95 % level may hold a tooth within the level that the coarse grid stepped over; it is sampled
   at :data:`FINE_SPACING`, a fifth of the comb's shortest period (:func:`fill`).
4. **Deepen**: around each local minimum within reach of the level the grid is halved
   :data:`DEEP_LEVELS` times (:func:`deepen`).

Every point evaluated on the way joins the problem's archive, whose lowest point is the estimate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from passmd.protocols.fit.problem import Problem

__all__ = ["COMB_WINDOW", "DEEP_LEVELS", "FILL_SWING", "FINE_SPACING", "PROFILE_POINTS", "Profile", "coarse",
           "deepen", "fill", "swing", "walk"]

#: Points of the coarse profile over a parameter's whole bounds (evenly spaced in log, both ends
#: included): the k_p range of 4e4–6.5e8 N/m in steps of 23 %, enough to follow the cost's trend.
PROFILE_POINTS = 48
#: Spacing of the fine profile (log units, 1 %): a fifth of the shortest period of the step's
#: oscillation in k_p seen at 100 Hz (about 7 %), so every tooth of the comb holds several points.
FINE_SPACING = 0.01
#: Fine points either side of the estimate over which the profile's swing is measured (±6 %: most of
#: a period of the comb).
COMB_WINDOW = 6
#: An interval of the coarse profile is sampled finely when its lower end is within this many swings
#: of the profile near the estimate above the 95 % level (the comb's depth varies along k_p).
FILL_SWING = 2.0
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
    """The coarse profile of every parameter: :data:`PROFILE_POINTS` over its bounds, walked outward
    from the estimate on both sides."""
    walkers = []
    for j in range(problem.p):
        profiles[j].add(x_hat[j], cost, x_hat)
        grid = np.linspace(problem.lo[j], problem.hi[j], PROFILE_POINTS)
        walkers.append((j, [float(t) for t in grid[grid > x_hat[j]]], x_hat))
        walkers.append((j, [float(t) for t in grid[grid < x_hat[j]][::-1]], x_hat))
    walk(problem, profiles, walkers)


def swing(problem: Problem, profiles: dict[int, Profile], x_hat: np.ndarray) -> dict[int, float]:
    """Per parameter, the swing of its profile (highest minus lowest cost) over a fine walk of
    :data:`COMB_WINDOW` points either side of the estimate: how much the cost can change between two
    points of the coarse grid without their showing it (the comb's depth near the minimum)."""
    walkers = []
    for j in range(problem.p):
        for sign in (1.0, -1.0):
            ts = [x_hat[j] + sign * k * FINE_SPACING for k in range(1, COMB_WINDOW + 1)]
            walkers.append((j, [t for t in ts if problem.lo[j] <= t <= problem.hi[j]], x_hat))
    walk(problem, profiles, walkers)
    out = {}
    for j in range(problem.p):
        t, c, _ = profiles[j].arrays()
        near = np.abs(t - x_hat[j]) <= COMB_WINDOW * FINE_SPACING * (1 + 1e-9)
        out[j] = float(np.max(c[near]) - np.min(c[near])) if np.count_nonzero(near) > 1 else 0.0
    return out


def _projected(problem: Problem, x: np.ndarray, jac: np.ndarray) -> float:
    """The cost at ``x`` after a linear least-squares step of the Jacobian ``jac``'s columns."""
    r = problem.residual(problem.prediction(x))
    if jac.shape[1] == 0:
        return float(np.sum(r ** 2))
    step = np.linalg.lstsq(jac, -r, rcond=None)[0]
    return float(np.sum((r + jac @ step) ** 2))


def fill(problem: Problem, profiles: dict[int, Profile], swings: dict[int, float], cut: float,
         margin: float) -> int:
    """Sample at :data:`FINE_SPACING` every interval of a profile whose lower end lies within
    ``cut`` + :data:`FILL_SWING` × the parameter's swing (:func:`swing`), so that no tooth of a comb
    within the level is stepped over; returns the number of intervals sampled.

    Each fine point is evaluated once, the others interpolated between the interval's ends, and
    its cost projected through the nearer end's Jacobian of the others (one linear step); the
    points whose projected cost is within ``cut + margin`` then get a Gauss–Newton step
    (:meth:`~passmd.protocols.fit.problem.Problem.conditional`).
    """
    jobs = []
    for j, profile in profiles.items():
        t, c, xs = profile.arrays()
        for k in range(t.size - 1):
            a, b = t[k], t[k + 1]
            if b - a <= 1.5 * FINE_SPACING or min(c[k], c[k + 1]) > cut + FILL_SWING * swings[j]:
                continue
            m = math.ceil((b - a) / FINE_SPACING)
            for i in range(1, m):
                w = i / m
                x = (1.0 - w) * xs[k] + w * xs[k + 1]
                x[j] = a + w * (b - a)
                jobs.append((j, x, xs[k] if w <= 0.5 else xs[k + 1]))
    if not jobs:
        return 0
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
        if _projected(problem, x, jacobians[(e.tobytes(), j)]) <= cut + margin:
            tasks.append((j, x[j], x))
    if tasks:
        for (j, t, _), (x, c) in zip(tasks, problem.conditional(tasks), strict=True):
            profiles[j].add(t, c, x)
    return len(ends)


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
