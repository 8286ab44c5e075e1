"""The weighted least-squares problem of a calibration in log-parameter space, and its searches.

:class:`Problem` turns the model's predictions (the private ``passmd.protocols.fit.prediction._Model``,
one cached sweep per call) into weighted residuals and costs, keeps every parameter vector it
evaluated with its cost (:attr:`Problem.archive`: the estimate is the lowest point seen
anywhere), and runs the two searches the estimator builds on: a bounded local least-squares
search (:meth:`Problem.local`) and batched Gauss–Newton steps of some parameters with the others
held fixed (:meth:`Problem.conditional`, the inner minimisation of every profile).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from passmd.protocols.fit.measurements import Measurements
from passmd.protocols.fit.prediction import _Model

__all__ = ["GN_STEP_LIMIT", "JACOBIAN_STEPS", "LOCAL_EVALUATIONS", "Problem"]

#: Relative step of the forward-difference Jacobian (log-parameter space) by measured quantity; a fit
#: takes the largest of its data's. Steps, velocities, positions: 0.1 %. The steady step of six
#: flexible contacts changes by 0.17 nm per 0.1 % of k_p, smoothly (its second differences at 0.02 %
#: spacing scatter by 2e-4 nm), and a tooth of the comb in k_p is only about 0.3 % wide within the
#: 95 % level, so a wider step would straddle it; 0.1 % stays well above the settled step's
#: accuracy (0.01 nm) relative to the change it measures. Critical amplitudes and stall forces: 1 %,
#: above the bisection's resolution (0.1 nm of A_c ≈ 50 nm is 0.2 %) and the stall tolerance.
JACOBIAN_STEPS = {"step": 1e-3, "velocity": 1e-3, "position": 1e-3, "critical_amplitude": 1e-2, "force": 1e-2}
#: Function evaluations of one local least-squares search (each with its Jacobian, one sweep).
LOCAL_EVALUATIONS = 40
#: Largest move of one Gauss–Newton step of a profile's inner minimisation (log units, i.e. a
#: factor e^0.5 ≈ 1.65): a step computed across a kink of the response stays near its start.
GN_STEP_LIMIT = 0.5


class Problem:
    """Weighted residuals of the data at log-parameter vectors, evaluated through the model's sweeps.

    Every method evaluates its points in as few sweeps as it can, and the model keeps every
    prediction, so a point met twice costs nothing the second time.
    """

    def __init__(self, model: _Model, data: Measurements, sigma: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                 loss: str):
        self.model, self.data, self.sigma, self.lo, self.hi, self.loss = model, data, sigma, lo, hi, loss
        self.n, self.p = len(data), len(lo)
        self.h = max(JACOBIAN_STEPS[kind] for kind in data.kind)
        #: every evaluated vector: key -> (x, cost)
        self.archive: dict[bytes, tuple[np.ndarray, float]] = {}

    # -- evaluation -------------------------------------------------------------------------

    def evaluate(self, xs: Sequence[np.ndarray]) -> list[np.ndarray]:
        """Predictions (SI) at each vector, one sweep; their costs join the archive."""
        xs = [np.asarray(x, float) for x in xs]
        preds = self.model.evaluate(xs)
        for x, pred in zip(xs, preds, strict=True):
            key = x.tobytes()
            if key not in self.archive:
                self.archive[key] = (x, float(np.sum(self.residual(pred) ** 2)))
        return preds

    def residual(self, pred: np.ndarray) -> np.ndarray:
        return (pred - self.data.value) / self.sigma

    def costs(self, xs: Sequence[np.ndarray]) -> list[float]:
        """Sum of squared residuals at each vector (one sweep)."""
        return [float(np.sum(self.residual(v) ** 2)) for v in self.evaluate(xs)]

    def best(self) -> tuple[np.ndarray, float]:
        """The lowest-cost vector evaluated so far, and its cost."""
        x, c = min(self.archive.values(), key=lambda item: item[1])
        return x.copy(), c

    def prediction(self, x: np.ndarray) -> np.ndarray:
        """Predictions at one vector (from memory when evaluated before)."""
        return self.evaluate([x])[0]

    # -- derivatives ------------------------------------------------------------------------

    def _steps(self, x: np.ndarray, cols) -> list[np.ndarray]:
        """x stepped by +h in each column of ``cols`` (by -h where +h leaves the box)."""
        out = []
        for j in cols:
            e = np.zeros(self.p)
            e[j] = self.h if x[j] + self.h <= self.hi[j] else -self.h
            out.append(x + e)
        return out

    def fun_jac(self, x, cols=None) -> tuple[np.ndarray, np.ndarray]:
        """Residual and Jacobian (d r / d log θ; columns ``cols``), base and steps in one sweep."""
        x = np.asarray(x, float)
        steps = self._steps(x, range(self.p) if cols is None else cols)
        base, *others = self.evaluate([x, *steps])
        r = self.residual(base)
        if not steps:
            return r, np.zeros((self.n, 0))
        return r, np.column_stack([(self.residual(o) - r) / (s - x).sum()
                                   for o, s in zip(others, steps, strict=True)])

    # -- searches ---------------------------------------------------------------------------

    def local(self, x0: np.ndarray, max_nfev: int = LOCAL_EVALUATIONS) -> tuple[np.ndarray, float]:
        """A bounded least-squares search from x0 (trust-region reflective): (x, cost)."""
        from scipy import optimize

        memo = {}  # the Jacobian of each residual evaluation, so jac(x) needs no second sweep

        def f(x):
            r, jac = self.fun_jac(x)
            memo[np.asarray(x, float).tobytes()] = jac
            return r

        def jf(x):
            key = np.asarray(x, float).tobytes()
            return memo[key] if key in memo else self.fun_jac(x)[1]

        x0 = np.clip(np.asarray(x0, float), self.lo, self.hi)
        sol = optimize.least_squares(f, x0, jac=jf, bounds=(self.lo, self.hi), loss=self.loss, method="trf",
                                     x_scale=1.0, xtol=1e-6, ftol=1e-8, gtol=1e-8, max_nfev=max_nfev)
        x = np.clip(sol.x, self.lo, self.hi)
        c = float(np.sum(f(x) ** 2))
        return (x, c) if c <= self.archive[x0.tobytes()][1] else (x0, self.archive[x0.tobytes()][1])

    def conditional(self, tasks: Sequence[tuple[int | None, float, np.ndarray]]
                    ) -> list[tuple[np.ndarray, float]]:
        """One Gauss–Newton step of the free parameters other than a fixed one, for many tasks at once.

        Each task is ``(j, t, x0)``: parameter ``j`` fixed at ``t`` (log; ``j`` None: none fixed),
        the others starting from ``x0``'s. Two sweeps for all tasks: the start and its Jacobian
        columns, then the Gauss–Newton point (a move of at most :data:`GN_STEP_LIMIT` per
        parameter, clipped to the box). Returns, per task, the lower of the two points and its
        cost.
        """
        starts, cols = [], []
        for j, t, x0 in tasks:
            x = np.array(x0, float)
            if j is not None:
                x[j] = t
            starts.append(np.clip(x, self.lo, self.hi))
            cols.append([k for k in range(self.p) if k != j])
        batch = []
        for x, c in zip(starts, cols, strict=True):
            batch += [x, *self._steps(x, c)]
        values = self.evaluate(batch)
        moved, at = [], 0
        for x, c in zip(starts, cols, strict=True):
            r = self.residual(values[at])
            if c:
                steps = batch[at + 1: at + 1 + len(c)]
                jac = np.column_stack([(self.residual(values[at + 1 + a]) - r) / (steps[a] - x).sum()
                                       for a in range(len(c))])
                delta = np.linalg.lstsq(jac, -r, rcond=None)[0]
                y = np.array(x)
                y[c] = np.clip(x[c] + np.clip(delta, -GN_STEP_LIMIT, GN_STEP_LIMIT), self.lo[c], self.hi[c])
                moved.append(y)
            else:
                moved.append(x)
            at += 1 + len(c)
        self.evaluate(moved)
        out = []
        for x, y in zip(starts, moved, strict=True):
            cx, cy = self.archive[x.tobytes()][1], self.archive[y.tobytes()][1]
            out.append((y, cy) if cy < cx else (x, cx))
        return out
