"""The 95 % region of each free parameter: pieces, basins, and the measurement that would separate them.

A parameter's region is every value whose profile lies within the χ² quantile of the minimum
(:func:`pieces` of the profile). A parameter whose profile is multimodal because *another*
parameter is (a μ profile walked with k_p inside one tooth of its comb) is covered by the basins:
every local minimum of any profile within the level (:func:`basins`, prominence at least
:data:`BASIN_PROMINENCE`) adds its own local interval of each parameter (:func:`basin_interval`,
a profile end found on the signed root of the cost rise). The union of both, merged where they
overlap, is the region; several separate pieces mean the parameter is known only to that set.
:func:`separating_row` computes which one added measurement would best tell the basins apart.
"""

from __future__ import annotations

import math

import numpy as np

from passmd.protocols.fit.problem import Problem

__all__ = ["BASIN_PROMINENCE", "END_ITERATIONS", "END_TOLERANCE", "basin_interval", "basins", "merge",
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


def basin_interval(problem: Problem, x_b: np.ndarray, c_b: float, s2: float, threshold: float
                   ) -> tuple[list[list[float]], list[bool]]:
    """Each parameter's local 95 % interval around the basin minimum ``x_b`` (log): the end on either
    side where the cost, re-minimised over the others (started on the covariance's regression
    line), has risen by ``threshold`` · s². Returns the intervals and, per parameter, whether an
    end reached a bound with the rise still below the threshold."""
    _, jac = problem.fun_jac(x_b)
    cov = s2 * np.linalg.pinv(jac.T @ jac)
    p = problem.p
    intervals, flat = [], []
    for j in range(p):
        others = [k for k in range(p) if k != j]
        slope = cov[others, j] / cov[j, j] if others and cov[j, j] > 0 else np.zeros(len(others))
        se = math.sqrt(max(cov[j, j], 0.0))
        ends, reached = [], False
        for sign in (-1.0, 1.0):
            end, at_bound = _end(problem, j, others, slope, x_b, c_b, s2, threshold, sign, se)
            ends.append(end)
            reached = reached or at_bound
        intervals.append(sorted(ends))
        flat.append(reached)
    return intervals, flat


def _end(problem, j, others, slope, x_b, c_b, s2, threshold, sign, se) -> tuple[float, bool]:
    """One end of a basin's local interval (module docstring): (end, reached a bound)."""
    limit = (problem.lo if sign < 0 else problem.hi)[j]
    room = abs(limit - x_b[j])
    if room <= 0.0:
        return float(limit), False

    def rise(delta):
        x0 = np.array(x_b, float)
        x0[j] = x_b[j] + sign * delta
        if others:
            x0[others] = np.clip(x_b[others] + slope * sign * delta, problem.lo[others], problem.hi[others])
        (_, c), = problem.conditional([(j, x0[j], x0)])
        return max((c - c_b) / s2, 0.0)

    delta = min(max(math.sqrt(threshold) * se, 0.005), room) if math.isfinite(se) and se > 0 else room
    inside, outside = (0.0, 0.0), None  # (delta, rise) below and above the threshold
    for _ in range(END_ITERATIONS + 1):
        v = rise(delta)
        if abs(v - threshold) <= END_TOLERANCE * threshold:
            return float(x_b[j] + sign * delta), False
        if v < threshold:
            inside = max(inside, (delta, v))
            if delta >= room:
                return float(limit), True
        else:
            outside = (delta, v) if outside is None or delta < outside[0] else outside
        if outside is None:  # the signed root of the rise is about linear in delta: extrapolate
            delta = min(room, delta * math.sqrt(threshold / max(v, 1e-12 * threshold)) * 1.05, 4.0 * delta)
        else:
            a, b = math.sqrt(inside[1]), math.sqrt(outside[1])
            delta = inside[0] + (outside[0] - inside[0]) * (math.sqrt(threshold) - a) / (b - a)
    if outside is None:
        return float(x_b[j] + sign * inside[0]), False
    a, b = math.sqrt(inside[1]), math.sqrt(outside[1])
    delta = inside[0] + (outside[0] - inside[0]) * (math.sqrt(threshold) - a) / (b - a)
    return float(x_b[j] + sign * delta), False
