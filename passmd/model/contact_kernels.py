"""Numba kernels of the MDR contact with memory (Eqs. 4–6); public names live in :mod:`passmd.model.contact`.

Every kernel takes two plain 1-D float64 arrays, ``params`` (constants) and ``state``
(memory), and a relative tangential displacement ``u = x_a − x_r`` (hemisphere minus
runner). The returned force ``T(u)`` acts ``+T`` on the runner and ``−T`` on the actuator.

Layout of ``params`` (both models)::

    [0] model code (EXACT = 0, DISCRETE = 1)   [5] normal force F_N
    [1] sliding force μF_N                     [6] Hertz contact radius a
    [2] full-slip displacement u_max           [7] indentation d (discrete: solved, see below)
    [3] largest tangent stiffness              [8] spring tangential stiffness G*Δx (discrete)
    [4] stack capacity (exact) / springs N     [9] spring spacing Δx (discrete)
    discrete only: [10 : 10+N] spring slip limits w_i, [10+N : 10+2N] spring positions x_i

Layout of ``state``::

    [0] reversal points on the stack (exact)   [4] committed force T
    [1] base: 0 virgin, ±1 full sliding        [5] stack overflows (exact)
    [2] direction of the current branch ±1     [6] reversals recorded (exact)
    [3] committed displacement u               [7] deepest stack reached (exact)
    exact: [8 + 2k], [9 + 2k] = (u_k, T_k) of reversal point k
    discrete: [8 : 8+N] = slip p_i of each spring (its tangential deflection is u − p_i)

Rows may be padded with trailing zeros: no kernel looks at the array length.

Speed: the kernels never allocate, so they are compiled without numba's reference
counting (``_nrt=False``) and with NumPy's error model (no zero-division branches; every
divisor is a validated positive constant). A call from another numba function then
costs a plain function call, about 8 ns for the exact model instead of about 25 ns with
the atomic reference-count updates on the two array arguments (see
``benchmarks/bench_contact.py``). For the same reason the ``*_row`` kernels take the
stacked 2-D arrays and a row index: a view ``P[g]`` made inside a caller's hot loop
costs those reference-count updates again in the caller.
"""

from __future__ import annotations

import numpy as np
from numba import njit

EXACT = 0
DISCRETE = 1

#: numba options of every kernel (see the module docstring).
KERNEL_OPTIONS = {"cache": True, "error_model": "numpy", "_nrt": False}

P_MODEL, P_SLIDING, P_UMAX, P_STIFFNESS, P_SIZE = 0, 1, 2, 3, 4
P_NORMAL, P_RADIUS, P_INDENT, P_SPRING_K, P_SPACING = 5, 6, 7, 8, 9
PARAMS_HEADER = 10

S_DEPTH, S_BASE, S_DIR, S_U, S_FORCE, S_OVERFLOW, S_REVERSALS, S_MAXDEPTH = range(8)
STATE_HEADER = 8

#: relative tolerance for "spring at its slip limit" in the discrete slip share: the
#: committed slip p = u ∓ w is rounded, so |u − p| may miss w by a few ulps.
LIMIT_RTOL = 1e-9


@njit(**KERNEL_OPTIONS)
def _virgin_fraction(x):
    """1 − (1 − x)^{3/2} for 0 ≤ x ≤ 1, without cancellation at small x.

    1 − t³ᐟ² = (1 − t³)/(1 + t^{3/2}) and 1 − t³ = x (1 + t + t²) with t = 1 − x.
    """
    if x >= 1.0:
        return 1.0
    t = 1.0 - x
    return x * (1.0 + t + t * t) / (1.0 + t * np.sqrt(t))


@njit(**KERNEL_OPTIONS)
def _exact_eval(params, state, u, commit):
    """Force of the exact (N → ∞) contact at ``u``; writes the memory only if ``commit``."""
    return _exact_core(params, state, u, commit)[0]


@njit(**KERNEL_OPTIONS)
def _exact_core(params, state, u, commit):
    """(force, v) of the exact (N → ∞) contact at ``u``; writes the memory only if ``commit``.

    ``v`` is the φ-argument of the branch reached (|u| on the virgin curve,
    |u − u_k|/2 on a Masing branch, u_max in full sliding).

    Masing/Mindlin–Deresiewicz branches T = T_k + s·2φ(|u − u_k|/2) from the top
    reversal point (u_k, T_k) of a stack, φ(v) = μF_N[1 − (1 − v/u_max)^{3/2}] the
    virgin Cattaneo–Mindlin curve. A branch that passes the older reversal point below
    its start closes that loop (both points are popped); from the first reversal the
    branch joins the virgin curve's mirror point −u_1 (virgin base) or full sliding
    after 2u_max (sliding base). Decisions compare displacements only, never forces,
    so round-off cannot reorder the stack.

    One function of ≈ 120 lines on purpose: it runs once per contact group and integrator
    step, and the stack walk, the branch choice and the commit share a dozen local values
    that helpers would pass back and forth on every call.
    """
    f_s = params[P_SLIDING]
    u_max = params[P_UMAX]
    cap = int(params[P_SIZE])
    n = int(state[S_DEPTH])
    base = state[S_BASE]
    s = state[S_DIR]
    u_prev = state[S_U]
    f_prev = state[S_FORCE]
    du = u - u_prev
    if du == 0.0:
        if n > 0:
            v = 0.5 * abs(u - state[STATE_HEADER + 2 * (n - 1)])
        elif base == 0.0:
            v = abs(u)
        else:
            v = u_max
        return f_prev, v
    if n == 0:
        if base == 0.0:  # on the virgin curve the branch runs away from the origin
            if u_prev > 0.0:
                s = 1.0
            elif u_prev < 0.0:
                s = -1.0
            else:
                s = 1.0 if du > 0.0 else -1.0
        else:
            s = base
    # A reversal at u_prev becomes a virtual top point (x_u, x_f) at index n.
    has_x = False
    x_u = 0.0
    x_f = 0.0
    overflow = 0.0
    if s * du < 0.0:
        if n < cap:
            has_x = True
            x_u = u_prev
            x_f = f_prev
        else:
            # Full stack: forget the newest, smallest loop (u_{n-1} → u_prev) and go
            # on along the branch that started at u_{n-2} (same direction as the new one).
            top = state[STATE_HEADER + 2 * (n - 1)]
            if -s * (u - top) < 0.0:  # u did not close that loop itself
                overflow = 1.0
            n -= 1
        s = -s
    m = n + 1 if has_x else n
    force = 0.0
    v = 0.0
    while True:
        if m == 0:
            if base == 0.0:
                a = abs(u)
                sign = 1.0 if u > 0.0 else -1.0
                v = a
                if a >= u_max:
                    force = sign * f_s
                    base = sign
                else:
                    force = sign * f_s * _virgin_fraction(a / u_max)
            else:
                force = base * f_s
                v = u_max
            break
        k = m - 1
        if has_x and k == n:
            t_u = x_u
            t_f = x_f
        else:
            t_u = state[STATE_HEADER + 2 * k]
            t_f = state[STATE_HEADER + 2 * k + 1]
        if m >= 2:
            threshold = state[STATE_HEADER + 2 * (k - 1)]  # k − 1 < n: always stored
        elif base == 0.0:
            threshold = -t_u
        else:
            threshold = t_u + s * 2.0 * u_max
        if s * (u - threshold) >= 0.0:
            if m >= 2:
                m -= 2
            else:
                m = 0
                if base != 0.0:
                    base = s
            continue
        v = 0.5 * abs(u - t_u)
        force = t_f + s * 2.0 * f_s * _virgin_fraction(v / u_max)
        if force > f_s:
            force = f_s
        elif force < -f_s:
            force = -f_s
        break
    if commit:
        if has_x:
            state[S_REVERSALS] += 1.0
            if m == n + 1:
                state[STATE_HEADER + 2 * n] = x_u
                state[STATE_HEADER + 2 * n + 1] = x_f
        if m > state[S_MAXDEPTH]:
            state[S_MAXDEPTH] = m
        state[S_DEPTH] = m
        state[S_BASE] = base
        state[S_DIR] = s
        state[S_U] = u
        state[S_FORCE] = force
        state[S_OVERFLOW] += overflow
    return force, v


@njit(**KERNEL_OPTIONS)
def _exact_slip_share(params, state, u):
    """1 − √(1 − v/u_max) on the branch reached at u (v its φ-argument); 1 in full sliding."""
    force, v = _exact_core(params, state, u, False)
    if abs(force) >= params[P_SLIDING]:
        return 1.0
    x = v / params[P_UMAX]
    if x >= 1.0:
        return 1.0
    return 1.0 - np.sqrt(1.0 - x)


@njit(**KERNEL_OPTIONS)
def _exact_force_tangent(params, state, u):
    """(T, dT/du) of the exact contact at ``u`` on the branch it reaches (pure).

    Every branch is T_k ± 2φ(|u − u_k|/2) (or φ(|u|) on the virgin curve), so its slope is
    φ'(v) = 2aG* √(1 − v/u_max) with v the φ-argument :func:`_exact_core` returns; 0 in full
    sliding. At a reversal point the slope is that of the branch u moves onto.
    """
    force, v = _exact_core(params, state, u, False)
    if abs(force) >= params[P_SLIDING]:
        return force, 0.0
    rest = 1.0 - v / params[P_UMAX]
    return force, params[P_STIFFNESS] * np.sqrt(rest) if rest > 0.0 else 0.0


@njit(**KERNEL_OPTIONS)
def _discrete_force_tangent(params, state, u):
    """(T, dT/du) of the discrete contact at ``u`` (pure): G*Δx times the springs that stick
    there (a spring exactly at its slip limit counts as sliding on)."""
    n = int(params[P_SIZE])
    k = params[P_SPRING_K]
    total = 0.0
    sticking = 0
    for i in range(n):
        w = params[PARAMS_HEADER + i]
        e = u - state[STATE_HEADER + i]
        if e >= w:
            e = w
        elif e <= -w:
            e = -w
        else:
            sticking += 1
        total += e
    return k * total, k * sticking


@njit(**KERNEL_OPTIONS)
def _discrete_eval(params, state, u, commit):
    """Eq. 6: T = Σ G*Δx · clip(u − p_i, −w_i, w_i); sliding springs move their slip p_i."""
    n = int(params[P_SIZE])
    k = params[P_SPRING_K]
    total = 0.0
    for i in range(n):
        w = params[PARAMS_HEADER + i]
        e = u - state[STATE_HEADER + i]
        if e > w:
            e = w
            if commit:
                state[STATE_HEADER + i] = u - w
        elif e < -w:
            e = -w
            if commit:
                state[STATE_HEADER + i] = u + w
        total += e
    force = k * total
    if commit:
        state[S_U] = u
        state[S_FORCE] = force
    return force


@njit(**KERNEL_OPTIONS)
def _discrete_slip_share(params, state, u):
    """Springs at their slip limit after moving to u, over springs in contact (w_i > 0)."""
    n = int(params[P_SIZE])
    slipping = 0
    touching = 0
    for i in range(n):
        w = params[PARAMS_HEADER + i]
        if w <= 0.0:
            continue
        touching += 1
        if abs(u - state[STATE_HEADER + i]) >= w * (1.0 - LIMIT_RTOL):
            slipping += 1
    if touching == 0:
        return 0.0
    return slipping / touching


@njit(**KERNEL_OPTIONS)
def contact_force(params, state, u):
    """Friction force T(u) on the runner given the memory; pure (writes nothing)."""
    if params[P_MODEL] == EXACT:
        return _exact_eval(params, state, u, False)
    return _discrete_eval(params, state, u, False)


@njit(**KERNEL_OPTIONS)
def contact_update(params, state, u):
    """Commit u into the memory and return T(u) (the value ``contact_force`` gives)."""
    if params[P_MODEL] == EXACT:
        return _exact_eval(params, state, u, True)
    return _discrete_eval(params, state, u, True)


@njit(**KERNEL_OPTIONS)
def contact_force_tangent(params, state, u):
    """Friction force T(u) and its slope dT/du on the branch u reaches; pure (writes nothing)."""
    if params[P_MODEL] == EXACT:
        return _exact_force_tangent(params, state, u)
    return _discrete_force_tangent(params, state, u)


@njit(**KERNEL_OPTIONS)
def contact_slip_share(params, state, u):
    """Fraction (0..1) of the MDR springs in contact that slip at u; pure."""
    if params[P_MODEL] == EXACT:
        return _exact_slip_share(params, state, u)
    return _discrete_slip_share(params, state, u)


@njit(**KERNEL_OPTIONS)
def contact_reset(params, state):
    """Back to the virgin state: u = 0, every spring unstrained, empty stack."""
    if params[P_MODEL] == EXACT:
        end = STATE_HEADER + 2 * int(params[P_SIZE])
    else:
        end = STATE_HEADER + int(params[P_SIZE])
    for i in range(end):
        state[i] = 0.0


@njit(**KERNEL_OPTIONS)
def contact_stiffness(params):
    """Largest tangent stiffness: 2aG* (exact) or Σ G*Δx over springs in contact (discrete)."""
    return params[P_STIFFNESS]


@njit(**KERNEL_OPTIONS)
def sliding_force(params):
    """Full-sliding friction force μF_N."""
    return params[P_SLIDING]


@njit(**KERNEL_OPTIONS)
def contact_force_row(P, S, g, u):
    """:func:`contact_force` of row ``g`` of stacked arrays (no view made by the caller)."""
    return contact_force(P[g], S[g], u)


@njit(**KERNEL_OPTIONS)
def contact_update_row(P, S, g, u):
    """:func:`contact_update` of row ``g`` of stacked arrays."""
    return contact_update(P[g], S[g], u)


@njit(**KERNEL_OPTIONS)
def contact_force_tangent_row(P, S, g, u):
    """:func:`contact_force_tangent` of row ``g`` of stacked arrays."""
    return contact_force_tangent(P[g], S[g], u)


@njit(**KERNEL_OPTIONS)
def contact_slip_share_row(P, S, g, u):
    """:func:`contact_slip_share` of row ``g`` of stacked arrays."""
    return contact_slip_share(P[g], S[g], u)
