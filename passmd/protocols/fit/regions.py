"""The 95 % region of each free parameter: pieces, basins, and the measurement that would separate them.

A parameter's region is every value whose profile lies within the χ² quantile of the minimum
(:func:`pieces` of the profile). A parameter whose profile is multimodal because *another*
parameter is (a μ profile walked with k_p inside one tooth of its comb) is covered by the basins:
every local minimum of any profile within the level (:func:`basins`, prominence at least
:data:`BASIN_PROMINENCE`) adds its own local interval of each parameter (:func:`basin_intervals`,
a profile end found on the signed root of the cost rise). The union of both, merged where they
overlap, is the region; several separate pieces mean the parameter is known only to that set.
:func:`~passmd.protocols.fit.next_measurement.separating_row` computes which one added measurement
would best tell the basins apart.
"""

from __future__ import annotations

import math

import numpy as np

from passmd.protocols.fit.problem import Problem
from passmd.protocols.fit.profiles import FINE_SPACING

__all__ = ["BASIN_PROMINENCE", "END_ITERATIONS", "END_TOLERANCE", "basin_intervals", "basins", "merge",
           "pieces"]

#: Least rise (in units of the residual variance s²) between a basin and a lower one: smaller dips
#: are the inner minimisation's noise, not separate minima.
BASIN_PROMINENCE = 1.0
#: A local interval's end is accepted where the cost rise is within this fraction of the threshold.
END_TOLERANCE = 0.1
#: Secant steps on the signed root of the rise per local interval end.
END_ITERATIONS = 3


def pieces(t: np.ndarray, c: np.ndarray, cut: float) -> list[list[float]]:
    """The pieces [low, high] (log) of {t : profile ≤ cut}, ends interpolated to the crossing between a
    point below and one above; a piece touching the first or last point ends there."""
    out = []
    below = c <= cut
    k = 0
    while k < t.size:
        if not below[k]:
            k += 1
            continue
        start = k
        while k + 1 < t.size and below[k + 1]:
            k += 1
        low = t[start] if start == 0 else _crossing(t[start - 1], c[start - 1], t[start], c[start], cut)
        high = t[k] if k == t.size - 1 else _crossing(t[k], c[k], t[k + 1], c[k + 1], cut)
        out.append([float(low), float(high)])
        k += 1
    return out


def _crossing(ta, ca, tb, cb, cut) -> float:
    """Where the straight line through (ta, ca), (tb, cb) crosses ``cut`` (one point below, one above)."""
    return ta + (tb - ta) * (cut - ca) / (cb - ca) if cb != ca else 0.5 * (ta + tb)


def merge(intervals: list[list[float]], gap: float = 0.0) -> list[list[float]]:
    """The union of intervals as sorted disjoint pieces (pieces closer than ``gap`` joined)."""
    out: list[list[float]] = []
    for low, high in sorted(intervals):
        if out and low <= out[-1][1] + gap:
            out[-1][1] = max(out[-1][1], high)
        else:
            out.append([low, high])
    return out


def basins(t: np.ndarray, c: np.ndarray, cut: float, prominence: float) -> list[int]:
    """Indices of the profile's local minima at or below ``cut`` that rise by at least ``prominence``
    towards every lower point (or the ends of the profile) on each side."""
    out = []
    for k in range(t.size):
        if c[k] > cut:
            continue
        sides = []
        for step in (-1, 1):
            peak, i = c[k], k + step
            while 0 <= i < t.size and c[i] >= c[k]:
                peak = max(peak, c[i])
                i += step
            lower_beyond = 0 <= i < t.size  # a lower point on this side
            sides.append(peak - c[k] if lower_beyond else math.inf)
        if min(sides) >= prominence and (k == 0 or c[k - 1] >= c[k]) and (k == t.size - 1 or c[k + 1] > c[k]):
            out.append(k)
    return out


def basin_intervals(problem: Problem, basin_list: list[tuple[np.ndarray, float]], s2: float, threshold: float
                    ) -> list[tuple[list[list[float]], list[bool]]]:
    """Each basin's local 95 % interval of every parameter (log): the end on either side where the
    cost, re-minimised over the others (started on the basin's covariance regression line), has
    risen by ``threshold`` · s², found on the signed root of the rise (:data:`END_ITERATIONS` secant
    steps, all ends of all basins in lockstep). Returns per basin the intervals and, per parameter,
    whether an end reached a bound with the rise still below the threshold."""
    p = problem.p
    ends = []
    for b, (x_b, c_b) in enumerate(basin_list):
        _, jac = problem.fun_jac(x_b)
        cov = s2 * np.linalg.pinv(jac.T @ jac)
        for j in range(p):
            others = [k for k in range(p) if k != j]
            slope = cov[others, j] / cov[j, j] if others and cov[j, j] > 0 else np.zeros(len(others))
            se = math.sqrt(max(cov[j, j], 0.0))
            for sign in (-1.0, 1.0):
                ends.append(_End(problem, b, j, sign, others, slope, x_b, c_b, se, threshold))
    for _ in range(END_ITERATIONS + 1):
        active = [e for e in ends if e.result is None]
        if not active:
            break
        results = problem.conditional([e.task() for e in active])
        for e, (_, c) in zip(active, results, strict=True):
            e.update(max((c - e.c_b) / s2, 0.0), threshold)
    out = []
    for b in range(len(basin_list)):
        intervals, flat = [], []
        for j in range(p):
            pair = [e for e in ends if e.b == b and e.j == j]
            intervals.append(sorted(e.final() for e in pair))
            flat.append(any(e.at_bound for e in pair))
        out.append((intervals, flat))
    return out


class _End:
    """One end of a basin's local interval of parameter j on side ``sign`` (:func:`basin_intervals`)."""

    def __init__(self, problem, b, j, sign, others, slope, x_b, c_b, se, threshold):
        self.problem, self.b, self.j, self.sign, self.others, self.slope = problem, b, j, sign, others, slope
        self.x_b, self.c_b = x_b, c_b
        self.limit = float((problem.lo if sign < 0 else problem.hi)[j])
        self.room = abs(self.limit - x_b[j])
        self.inside, self.outside = (0.0, 0.0), None  # (delta, rise) below and above the threshold
        self.at_bound = False
        self.result = self.limit if self.room <= 0.0 else None
        guess = math.sqrt(threshold) * se if math.isfinite(se) and se > 0 else self.room
        self.delta = min(max(guess, 0.2 * FINE_SPACING), self.room)

    def task(self):
        x0 = np.array(self.x_b, float)
        x0[self.j] = self.x_b[self.j] + self.sign * self.delta
        if self.others:
            lo, hi = self.problem.lo[self.others], self.problem.hi[self.others]
            x0[self.others] = np.clip(self.x_b[self.others] + self.slope * self.sign * self.delta, lo, hi)
        return self.j, x0[self.j], x0

    def update(self, v: float, threshold: float) -> None:
        delta = self.delta
        if abs(v - threshold) <= END_TOLERANCE * threshold:
            self.result = float(self.x_b[self.j] + self.sign * delta)
            return
        if v < threshold:
            self.inside = max(self.inside, (delta, v))
            if delta >= self.room:
                self.result, self.at_bound = self.limit, True
                return
        elif self.outside is None or delta < self.outside[0]:
            self.outside = (delta, v)
        if self.outside is None:  # the signed root of the rise is about linear in delta: extrapolate
            self.delta = min(self.room, delta * math.sqrt(threshold / max(v, 1e-12 * threshold)) * 1.05,
                             4.0 * delta)
        else:
            self.delta = self._interpolated(threshold)

    def _interpolated(self, threshold: float) -> float:
        a, b = math.sqrt(self.inside[1]), math.sqrt(self.outside[1])
        return self.inside[0] + (self.outside[0] - self.inside[0]) * (math.sqrt(threshold) - a) / (b - a)

    def final(self) -> float:
        if self.result is not None:
            return self.result
        if self.outside is None:
            return float(self.x_b[self.j] + self.sign * self.inside[0])
        threshold_delta = self.delta  # the last interpolation
        return float(self.x_b[self.j] + self.sign * threshold_delta)
