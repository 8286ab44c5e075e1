"""The estimator's polish stage with three or more free parameters: a full local search from each low
minimum of the profiles, where one Gauss–Newton step of the others cannot follow a curved valley."""

from __future__ import annotations

import numpy as np

from passmd.protocols import fit
from passmd.protocols.fit import estimator
from passmd.protocols.fit.problem import Problem
from passmd.protocols.fit.profiles import Profile


class _Valley:
    """Residuals of a curved valley in three log-parameters (Rosenbrock's in x0, x1; x2 follows x0²):
    zero cost only at (1, 1, 1); along the valley floor the others change non-linearly."""

    def __init__(self, data):
        self.data, self.evaluations = data, 0

    def evaluate(self, xs):
        self.evaluations += len(xs)
        valley = [np.array([10 * (x[1] - x[0] ** 2), 1 - x[0], 10 * (x[2] - x[0] ** 2), 0.0]) for x in xs]
        return [self.data.value + r for r in valley]


def _problem() -> Problem:
    header = ["amplitude_nm", "preload_N", "frequency_Hz", "step_nm"]
    data = fit.measurements_from_rows(header, [["100", "0.4", "100", "50"]] * 4, name="valley")
    return Problem(_Valley(data), data, np.ones(4), np.full(3, -2.0), np.full(3, 2.0), "linear")


def test_polish_reaches_the_valley_floor_that_one_gauss_newton_step_misses():
    problem = _problem()
    wall = np.array([-1.0, 1.0, 1.0])  # on the valley's floor line x1 = x2 = x0², far from its lowest point
    cost = problem.costs([wall])[0]
    # the counter-example: the profiles' inner minimisation (one Gauss–Newton step of the others, x0
    # held) stays at x0 = -1, cost ≥ 4
    (_, stepped), = problem.conditional([(0, wall[0], wall)])
    assert stepped >= 4.0 - 1e-9
    profiles = {j: Profile(j) for j in range(3)}
    for t, c in ((-1.1, cost + 1.0), (-1.0, cost), (-0.9, cost + 1.0)):  # a local minimum of x0's profile
        x = wall.copy()
        x[0] = t
        profiles[0].add(t, c, x)
    estimator._polish(problem, profiles, cut=cost + 1.0, say=lambda line: None)
    x_best, c_best = problem.best()
    assert c_best < 1e-3 * cost and np.allclose(x_best, 1.0, atol=0.05)


def test_polish_ignores_minima_above_the_cut_and_repeats_of_one_basin():
    problem = _problem()
    profiles = {j: Profile(j) for j in range(3)}
    base = np.array([-1.0, 1.0, 1.0])
    for t, c in ((-1.1, 9.0), (-1.0, 5.0), (-0.9, 9.0)):
        x = base.copy()
        x[0] = t
        profiles[0].add(t, c, x)
    estimator._polish(problem, profiles, cut=4.0, say=lambda line: None)
    assert problem.model.evaluations == 0  # above the cut: no search
    lines = []
    twin = {j: Profile(j) for j in range(3)}
    for j in (0, 1):  # the same point is a minimum of two profiles: one search
        for dt, c in ((-0.1, 9.0), (0.0, 5.0), (0.1, 9.0)):
            x = base.copy()
            x[j] += dt
            twin[j].add(x[j], c, x)
    estimator._polish(problem, twin, cut=6.0, say=lines.append)
    assert len(lines) == 1
