"""numba kernel of the hybrid simulation (Eqs. 2–3 with the MDR contacts in the loop).

Only :mod:`passmd.solver.simulation` calls this; it allocates and interprets. The compiled kernel
takes five NamedTuples of scalars and arrays (numba compiles NamedTuples, not
dataclasses): :class:`Segments` (the linear pieces of x_p(t) and their steps),
:class:`Mechanics` (masses, stiffnesses, damping), :class:`StepControl` (step adaptation
and recording), :class:`Contacts` (the contact rows of :mod:`passmd.model.contact`) and
:class:`Buffers` (state and outputs, written in place). :func:`integrate`, a Python
wrapper, checks their shapes and types before it enters the compiled loop.

The array layouts (column and slot indices), the argument records and the compiled loop
stay in this one module on purpose: numba compiles the indices into the loop as
constants and its on-disk cache (``cache=True``) is invalidated only when this file
changes, so a layout kept in another module could change without the cached loop
noticing.

Schemes. Fine and coarse steps: velocity Verlet (kick–drift–kick) on runner and
actuators; the actuator's viscous term −c_p ẋ_a is treated with the trapezoidal rule in
the velocity update (implicit in v, still explicit overall). With flexible actuators the
step adapts: fine (resolving the ≈ 3 MHz actuator mode) while the actuators ring, coarse
(a fraction of the explicit stability limit) or quasi-static (m_a neglected, the
actuator's force balance solved per step) while they follow.

Error-controlled steps (``StepControl.error_tolerance`` > 0; rigid actuators, and the
quasi-static phases of flexible ones): the runner's force splits into a linear spring K
(``Mechanics.linear_stiffness``: the contacts' initial tangent stiffness, in series with
k_p for flexible actuators) to x_p, plus the load cell, and the rest g. The linear part is
integrated exactly by the variation-of-constants formula (an exponential or
"trigonometric" integrator; Hairer, Lubich & Wanner, Geometric Numerical Integration,
Ch. XIII), g with its rate extrapolated from the last step in the position, and in the
velocity quadratic in time through its values at the step's end, its start and the previous
step's start (g linear over the step would leave the velocity an O(dt³) local error against
the position's O(dt⁴), and the energy balance an O(dt²) drift). So the ≈ 11 kHz
micro-vibration sets no step; what does is the
local position error estimate dt²/6 |Δg − ġ dt|, checked against the tolerance with the
forces at the drifted position (pure evaluations): a step above it is rejected and retried
shorter, and the next step follows the usual controller (fourth root, safety factor,
bounded growth). A reversal of a contact's displacement u inside a step is an event: the
extremum of the quadratic through u's value and rate at the start and its value at the end
is committed first, so the Masing branch turns there and not at a step boundary. Samples
inside such a step are interpolated (cubic Hermite in x_r).

Two switches (``StepControl``) make the default scheme cheaper without changing what it
computes beyond the balance solve's tolerance; the scheme "reference" has both off. ``newton``:
each quasi-static balance is one Newton step on the exact contact's slope
(:func:`_newton_position`, the bracketed solve where that step is not provably converged), and
the trigonometric coefficients come from their series (:func:`_series_coefficients`: no sine or
cosine call). ``smooth_breakpoints``: a breakpoint of x_p(t) where its rate does not change
(:func:`_smooth_breakpoint`) does not restart the step control.

In every scheme the contact memory is updated exactly once per accepted step (twice when
a reversal falls inside it), with the drifted positions, and the contact force is
otherwise evaluated purely. Every corner of x_p(t) falls on a step boundary.

Energy terms (``Buffers.energy``): the explicit steps sum the work of the drive, the
damping and the contacts with the trapezoidal rule per step. An error-controlled step
crosses the runner's ringing in a few steps, and across one T(t) and the path curve, so
the trapezoidal rule would miss the dissipation of a micro-slip loop by a fraction of order
(Ω dt)²; these steps use Simpson's rule in time instead. Its middle node is the drift
formula at half the step (runner), the contact force there evaluated purely with the memory
at the step's start (rigid actuators), or for a quasi-static actuator its force balance over
the first half step, one Newton step from the chord's midpoint with the contact force there
from the cubic Hermite in u through the step's ends (values, and tangents from the balance
solves; evaluated instead when u turns inside the step or the start's tangent is not known);
the actuator's velocity at the three nodes is that of the quadratic through its three
positions. (A reversal inside a rigid step is not split for the middle node: the error is of
second order in the distance from the reversal.) These terms never feed back into the motion,
and are summed only with ``StepControl.energy``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from passmd.model.contact import (
    contact_force_row,
    contact_force_tangent_row,
    contact_slip_share_row,
    contact_update_row,
)
from passmd.model.contact_kernels import EXACT, P_MODEL, P_STIFFNESS, P_UMAX, S_U

# columns of the per-period accumulator array
PER_WINDOW_INTEGRAL = 0  # ∫ (x_r − x_p) dt over the settle window
PER_WINDOW_LENGTH = 1  # window length (s)
PER_WINDOW_END_XP = 2  # x_p at the window's end
PER_MARK_XR = 3  # x_r at the slip mark
PER_MIN_XR = 4  # min x_r from the slip mark to the next window
PER_XR_INTEGRAL = 5  # ∫ x_r dt over the period
PER_FRICTION_INTEGRAL = 6  # ∫ Σ m_g T_g dt over the period (force on the runner)
PER_DURATION = 7  # Σ dt over the period
PER_COLUMNS = 8

# energy accumulators
EN_INPUT = 0  # work done by the piezo drive
EN_DAMPING = 1  # dissipated by c_p
EN_CONTACT = 2  # ∫ T du: stored in and dissipated by the contacts
EN_COLUMNS = 3

STATUS_OK = 0
STATUS_DIVERGED = 1
STATUS_PAUSED = 2  # the step limit was reached; call again with the same arrays to go on

# slots of the carry array: everything the integration loop keeps between steps besides
# ``y`` and ``work``, so that a paused integration resumes bit for bit where it stopped
C_STARTED = 0  # 0 before the first call (forces and accelerations not yet evaluated)
C_SEGMENT = 1  # segment in progress
C_MID = 2  # 1 when paused inside that segment
C_TIME = 3
C_XP = 4
C_AR = 5  # runner acceleration
C_FORCE = 6  # Σ n_g T_g
C_NEXT_RECORD = 7
C_TRACK = 8
C_RECORDED = 9
C_STEPS = 10
C_FINE_STEPS = 11
C_FINE = 12  # 1 while the fine step is in use
C_QUIET = 13
C_ACC_XR = 14  # segment-local accumulators
C_ACC_F = 15
C_ACC_WIN = 16
C_ACC_IN = 17
C_ACC_DAMP = 18
C_ACC_CONTACT = 19
C_ACC_T = 20
C_MIN_XR = 21
C_QUASI = 22  # 1 while the quasi-static actuator step is in use
C_CONTROLLED = 23  # 1 while the error-controlled step is in use
C_STEP = 24  # the error-controlled step (s)
C_REJECTED = 25  # error-controlled steps rejected (counted in the steps too)
C_GRATE = 26  # rate of g over the last error-controlled step (m/s³)
C_HPREV = 27  # length of that step (s; 0: g's rate not known, no curvature estimate)
CARRY_SIZE = 28


#: numba options: the kernel allocates nothing (work arrays come from the caller), so it is
#: compiled without reference counting, which would add atomic reference-count updates on
#: the array arguments of every call into the contact kernels.
KERNEL_OPTIONS = {"cache": True, "error_model": "numpy", "_nrt": False}

#: rows of the work array (shape (WORK_ROWS, groups)) the caller allocates
WORK_ROWS = 12
#: quasi-static step: the actuator's force balance is solved to this fraction of S/K
#: (≈ 6e-15 m; a force error ≤ 1e-6 μF_N)
QUASI_TOLERANCE = 1e-6
#: quasi-static step: most secant/bisection iterations of one force balance (the bracket
#: halves at least every other iteration, so 200 is far beyond the ≈ 50 that reach the
#: float resolution of S/K)
QUASI_MAX_ITERATIONS = 200
#: A step that would leave less than this fraction of itself before the end of a linear
#: piece of x_p(t) is stretched to end on the piece's corner (no sliver steps from rounding).
LAST_STEP_STRETCH = 1.000001
#: Divergence: the run stops (STATUS_DIVERGED) once |x_r| or an actuator's stretch
#: |x_a − x_p| reaches this (m). The drive's travel is a few µm, so 1 m is a runaway.
POSITION_LIMIT = 1.0
#: Divergence: the run stops once |v_r| or |v_a| reaches this (m/s). The amplifier moves the
#: hemispheres at most A_max·SR/V_pp ≈ 0.1 m/s, so 100 m/s is a runaway. (Comparisons with
#: NaN are False, so a NaN state stops the run too.)
VELOCITY_LIMIT = 100.0
#: Error-controlled step: the next step is this fraction of the one the estimate allows
#: (the safety factor of step-size controllers, Hairer, Nørsett & Wanner, Sect. II.4).
#: With 0.8 and the growth below, one step in 15 is rejected on a 100 Hz saw-tooth (0.9 and
#: 1.5 reject one in 5, and take more steps in all).
STEP_SAFETY = 0.8
#: Error-controlled step: largest growth and shrink factors from one step to the next.
STEP_GROWTH = 1.25
STEP_SHRINK = 0.2
#: Two pieces of x_p(t) whose rates differ by no more than this (relative) join smoothly
#: (``StepControl.smooth_breakpoints``): only rounding separates the rates of a ramp cut by a
#: window's start.
SMOOTH_BREAKPOINT_RTOL = 1e-9


class Segments(NamedTuple):
    """The linear pieces of x_p(t), one entry per piece (built by :mod:`passmd.solver.simulation`)."""

    t0: np.ndarray  # start time (s)
    t1: np.ndarray  # end time (s)
    x0: np.ndarray  # x_p at the start (m)
    x1: np.ndarray  # x_p at the end (m)
    fine: np.ndarray  # fine step (s)
    coarse: np.ndarray  # coarse step while the actuators do not ring (s)
    period: np.ndarray  # int64: period the piece belongs to
    window: np.ndarray  # int64: 1 when the piece lies in its period's settle window
    mark: np.ndarray  # int64: 1 when the piece starts at a slip mark
    quasi: np.ndarray  # step of the quasi-static actuator; first error-controlled step (s)
    longest: np.ndarray  # longest error-controlled step (s)


class Mechanics(NamedTuple):
    """Masses, stiffnesses and damping of Eqs. 2–3 (SI units)."""

    runner_mass: float  # m_r
    load_stiffness: float  # k of the load cell (0 without it)
    multiplicity: np.ndarray  # float: contacts n_g per group
    rigid: bool  # rigid actuators: x_a = x_p
    actuator_mass: float  # m_a
    actuator_stiffness: float  # k_p
    actuator_viscosity: float  # c_p
    linear_stiffness: float  # K: part of Σ n_g T_g the error-controlled step integrates exactly (N/m)


class StepControl(NamedTuple):
    """Step adaptation (flexible actuators) and recording."""

    activity_threshold: float  # |ẍ_a| above which the actuators ring (m/s²)
    quiet_steps: int  # fine steps below the threshold before the step grows
    quasi_static: bool  # quiet phases use the quasi-static actuator step
    record_interval: float  # time between recorded samples (s)
    error_tolerance: float  # local position error per step of the runner (m); 0: uniform steps
    newton: bool  # balances by a Newton step on the contact's slope, trigonometric terms by series
    smooth_breakpoints: bool  # the step goes on across a breakpoint where x_p keeps its rate
    energy: bool  # accumulate the energy terms (they never feed back into the motion)


class Contacts(NamedTuple):
    """The contact groups: rows of :func:`passmd.model.contact.stack_contacts` and μF_N per group."""

    params: np.ndarray
    state: np.ndarray  # contact memory, updated in place
    sliding: np.ndarray  # μF_N of one contact of each group (N)


class Buffers(NamedTuple):
    """State and outputs, all written in place (see :func:`integrate` for the layouts)."""

    y: np.ndarray  # (2 + 2G,): [x_r, v_r, x_a(0..G−1), v_a(0..G−1)]
    work: np.ndarray  # (WORK_ROWS, G): scratch carried between calls
    carry: np.ndarray  # (CARRY_SIZE,): loop state of a paused run, zeros before the first call
    record: np.ndarray  # (samples, 4 + 3G): [t, x_p, x_r, v_r, (x_a, T, slip share) per group]
    per: np.ndarray  # (periods, PER_COLUMNS): per-period accumulators
    peak: np.ndarray  # (periods, G): largest |T_g|/μF_N after each slip mark
    energy: np.ndarray  # (EN_COLUMNS,): energy accumulators


@njit(**KERNEL_OPTIONS)
def quasi_static_position(params, state, g, x_r, center, K, S, guess, slope, tolerance):
    """Actuator position x of group g in force balance with its contact (m_a neglected).

    Solves h(x) = K (center − x) − T_g(x − x_r) = 0 with the contact's memory as committed
    (pure evaluations). T_g is non-decreasing in u on every Masing branch and |T_g| ≤ S
    (μF_N), so h is strictly decreasing, −h' ∈ [K, K + 2aG*], and the root lies in
    [center − S/K, center + S/K]. From ``guess``, a step with ``slope`` (the previous
    step's −h', or K), then secant steps kept inside the shrinking bracket (bisection when
    a step leaves it), until a step is below ``tolerance`` (m). Returns (x, −h' estimate).
    """
    lo = center - S / K
    hi = center + S / K
    x = min(max(guess, lo), hi)
    h = K * (center - x) - contact_force_row(params, state, g, x - x_r)
    x_prev = x
    h_prev = h
    for it in range(QUASI_MAX_ITERATIONS):
        if h == 0.0:
            return x, slope
        if h > 0.0:
            lo = x
        else:
            hi = x
        if it > 0 and h != h_prev:
            secant = (h_prev - h) / (x - x_prev)
            if secant >= K:
                slope = secant
        x_new = x + h / slope
        if not (lo <= x_new <= hi):  # (the root is at an end of the bracket in full sliding)
            x_new = 0.5 * (lo + hi)
        if abs(x_new - x) <= tolerance or hi - lo <= tolerance:
            return x_new, slope
        x_prev = x
        h_prev = h
        x = x_new
        h = K * (center - x) - contact_force_row(params, state, g, x - x_r)
    return x, slope


@njit(inline="always", **KERNEL_OPTIONS)
def _newton_position(params, state, g, x_r, center, K, S, guess, guess_slope, tolerance):
    """:func:`quasi_static_position` by one Newton step from ``guess`` with the exact contact's
    slope k_t (:func:`passmd.model.contact.contact_force_tangent_row`), accepted when it is
    provably within ``tolerance`` of the root; otherwise (a discrete contact, full sliding, the
    step crossing the committed displacement, where the branch turns) the bracketed solve goes
    on from there. On a branch |d²T/du²| ≤ (2aG*)²/(2 u_max k_t) (from φ' = 2aG* √(1 − v/u_max),
    v = |u − u_k|/2 or |u|), so the Newton step δ leaves an error ≤ (2aG*)² δ² / (4 u_max k_t
    (K + k_t)). ``guess_slope``: the slope the discrete contact's solve starts from. Returns (x, K + k_t)."""
    if params[g, P_MODEL] != EXACT:
        return quasi_static_position(params, state, g, x_r, center, K, S, guess, guess_slope, tolerance)
    T, k_t = contact_force_tangent_row(params, state, g, guess - x_r)
    slope = K + k_t
    step = (K * (center - guess) - T) / slope
    x = guess + step
    u_c = state[g, S_U]
    k0 = params[g, P_STIFFNESS]
    if ((guess - x_r - u_c) * (x - x_r - u_c) > 0.0 and k_t > 0.0
            and k0 * k0 * step * step <= 4.0 * params[g, P_UMAX] * k_t * slope * tolerance):
        return x, slope
    return quasi_static_position(params, state, g, x_r, center, K, S, x, slope, tolerance)


def integrate(segments: Segments, mechanics: Mechanics, control: StepControl, contacts: Contacts,
              buffers: Buffers, step_limit: int, checked: bool = False):
    """Check the kernel's arguments, then integrate over the segments (:func:`_integrate`).

    Returns (status, steps done, rows recorded, fine steps).

    Work is bounded: once ``step_limit`` steps (counted from the start of the run) are
    done, the kernel stores its loop state in ``buffers.carry`` (zeros before the first
    call) and returns STATUS_PAUSED; calling it again with the same arrays continues
    exactly where it stopped, with the same floating-point operations in the same order as
    an uninterrupted run (the contact memory lives in ``contacts.state``). A run that has
    integrated all its segments stores its loop state the same way (between two segments) and
    returns STATUS_OK; calling it again with the segments extended by more pieces (and ``per``
    and ``peak`` by their periods, the same arrays longer) continues the run with the new
    pieces, as if they had been there from the start.

    ``contacts.sliding`` holds μF_N of each group; ``peak[k, g]`` receives the largest
    |T_g|/μF_N from period k's slip mark to the next settle window (1 exactly when the group
    slid fully). ``y`` = [x_r, v_r, x_a(0..G−1), v_a(0..G−1)]: the actuator entries are read
    on the first call and written when the run ends (in between they live in ``work``,
    scratch of shape (WORK_ROWS, G)); x_r and v_r are written whenever the kernel returns.
    ``record`` rows are [t, x_p, x_r, v_r, (x_a, T, slip share) per group].

    Step control (flexible actuators): every segment starts with the fine step
    ``segments.fine`` (a corner of x_p(t) excites the actuator mode). Once the largest
    actuator acceleration |ẍ_a| has stayed below ``control.activity_threshold`` for
    ``control.quiet_steps`` fine steps, the step grows to ``segments.coarse``; it falls back to fine
    as soon as |ẍ_a| exceeds the threshold again. Rigid actuators: ``segments.fine`` only.

    With ``control.quasi_static`` the quiet phases instead neglect m_a: each step of
    ``segments.quasi`` (set by the runner's mode) solves the actuator's force balance
    k_p (x_p − x_a) = c_p ẋ_a + T(x_a − x_r) implicitly (backward Euler in the damping
    term, :func:`quasi_static_position`), then commits the contact memory once, as the
    explicit step does. The implied actuator acceleration is checked against the same
    threshold; above it, the fine explicit step takes over again.

    With ``control.error_tolerance`` > 0 the quasi-static phases (flexible) and every step (rigid)
    are error-controlled (module docstring): the first such step of a quasi-static phase is
    ``segments.quasi``, then each step follows from the last one's error estimate, at most
    ``segments.longest``; rigid actuators carry the step from piece to piece. Rejected steps count
    in ``steps`` (and in ``carry[C_REJECTED]``).

    ``checked``: the caller has passed these arrays, or leading slices of them (the first pieces
    of ``segments`` and the first periods of ``buffers.per`` and ``buffers.peak``), through
    :func:`check_arguments` already (:class:`passmd.solver.simulation.Simulation` does, once per
    run: the checks cost more than a short call into the loop).

    Raises
    ------
    ValueError
        An argument of the wrong type, dtype or shape, naming it: the compiled loop does
        no bounds checks, so a wrong shape would read or write outside an array.
    """
    if not checked:
        check_arguments(segments, mechanics, control, contacts, buffers)
    if int(step_limit) != step_limit or step_limit < 0:
        raise ValueError(f"step_limit = {step_limit!r} is out of range: must be an integer >= 0")
    return _integrate(segments, mechanics, control, contacts, buffers, int(step_limit))


def _check_array(name, value, shape, dtype=np.float64):
    """ValueError unless ``value`` is a C-contiguous array of ``dtype`` and ``shape`` (None: any)."""
    if not isinstance(value, np.ndarray) or value.dtype != dtype or not value.flags.c_contiguous:
        raise ValueError(f"{name} must be a C-contiguous {np.dtype(dtype).name} array, got {value!r:.80}")
    wanted = tuple("*" if n is None else n for n in shape)
    if len(value.shape) != len(shape) or any(
        n is not None and m != n for m, n in zip(value.shape, shape, strict=True)
    ):
        raise ValueError(f"{name} has shape {value.shape}, must be {wanted}")


def check_arguments(segments, mechanics, control, contacts, buffers):
    """Types and shapes of :func:`integrate`'s arguments (ValueError naming the first bad one)."""
    for name, value, kind in (("segments", segments, Segments), ("mechanics", mechanics, Mechanics),
                              ("control", control, StepControl), ("contacts", contacts, Contacts),
                              ("buffers", buffers, Buffers)):
        if not isinstance(value, kind):
            raise ValueError(f"{name} = {value!r:.80} is not a {kind.__name__}")
    n = segments.t0.shape[0] if isinstance(segments.t0, np.ndarray) else -1
    if n < 1:
        raise ValueError("segments.t0 must be a non-empty array")
    for field in Segments._fields:
        dtype = np.int64 if field in ("period", "window", "mark") else np.float64
        _check_array(f"segments.{field}", getattr(segments, field), (n,), dtype)
    G = mechanics.multiplicity.shape[0] if isinstance(mechanics.multiplicity, np.ndarray) else 0
    if G < 1:
        raise ValueError("mechanics.multiplicity must be a non-empty array")
    _check_array("mechanics.multiplicity", mechanics.multiplicity, (G,))
    _check_array("contacts.params", contacts.params, (G, None))
    _check_array("contacts.state", contacts.state, (G, None))
    _check_array("contacts.sliding", contacts.sliding, (G,))
    periods = int(segments.period.max()) + 1
    _check_array("buffers.y", buffers.y, (2 + 2 * G,))
    _check_array("buffers.work", buffers.work, (WORK_ROWS, G))
    _check_array("buffers.carry", buffers.carry, (CARRY_SIZE,))
    _check_array("buffers.record", buffers.record, (None, 4 + 3 * G))
    _check_array("buffers.per", buffers.per, (periods, PER_COLUMNS))
    _check_array("buffers.peak", buffers.peak, (periods, G))
    _check_array("buffers.energy", buffers.energy, (EN_COLUMNS,))
    if buffers.record.shape[0] < 1:
        raise ValueError("buffers.record must have at least one row")


@njit(inline="always", **KERNEL_OPTIONS)
def _save_position(carry, segment, mid, t, x_p, a_r, F, next_rec, track, n_rec, steps, fine_steps, dt_ctrl):
    """Where the loop stands (segment, time, piezo position, runner acceleration, force,
    recording and step counters, error-controlled step) into ``carry``: at a pause and at the
    end of a call alike, so that a later call resumes or extends the run bit for bit."""
    carry[C_SEGMENT] = segment
    carry[C_MID] = mid
    carry[C_TIME] = t
    carry[C_XP] = x_p
    carry[C_AR] = a_r
    carry[C_FORCE] = F
    carry[C_NEXT_RECORD] = next_rec
    carry[C_TRACK] = track
    carry[C_RECORDED] = n_rec
    carry[C_STEPS] = steps
    carry[C_FINE_STEPS] = fine_steps
    carry[C_STEP] = dt_ctrl


@njit(inline="always", **KERNEL_OPTIONS)
def _note_peak(peak, track, g, force, sliding_force):
    """Keep the largest |T_g|/μF_N since the tracked period's slip mark (no period tracked: track < 0)."""
    if track >= 0 and abs(force) > peak[track, g] * sliding_force:  # (no division on every step)
        peak[track, g] = abs(force) / sliding_force


@njit(inline="always", **KERNEL_OPTIONS)
def _start_increment(rigid, rate, dt, actuator_stiffness, tangent_stiffness):
    """Rate of u = x_a − x_r at the start of a step, times dt, from the rate v_p − v_r
    (``rate``): as it is for rigid actuators; for a quasi-static one, from its balance
    k_p (v_p − v_a) = k_t (v_a − v_r) with k_t the contact's tangent stiffness."""
    if rigid:
        return rate * dt
    return actuator_stiffness * rate * dt / max(tangent_stiffness + actuator_stiffness, actuator_stiffness)


@njit(inline="always", **KERNEL_OPTIONS)
def _turns_inside(du0, du):
    """Whether u turns inside the step: the quadratic through u's increment ``du`` over the
    step and its rate at the start (times dt, ``du0``) has its extremum inside."""
    return du0 * (2.0 * du - du0) < 0.0


@njit(inline="always", **KERNEL_OPTIONS)
def _save_segment(carry, y, x_r, v_r, fine, quasi, controlled, g_rate, h_prev, quiet, acc):
    """Runner state into ``y``, step control and segment-local accumulators ``acc`` = (∫x_r,
    ∫F, ∫window, W_in, W_damp, W_contact, Σdt, min x_r) into ``carry`` at a pause inside a
    segment and at the end of a call (:func:`_restore_segment`; a later call goes on with the
    step control across a smooth breakpoint)."""
    y[0] = x_r
    y[1] = v_r
    carry[C_FINE] = 1.0 if fine else 0.0
    carry[C_QUASI] = 1.0 if quasi else 0.0
    carry[C_CONTROLLED] = 1.0 if controlled else 0.0
    carry[C_GRATE] = g_rate
    carry[C_HPREV] = h_prev
    carry[C_QUIET] = quiet
    carry[C_ACC_XR] = acc[0]
    carry[C_ACC_F] = acc[1]
    carry[C_ACC_WIN] = acc[2]
    carry[C_ACC_IN] = acc[3]
    carry[C_ACC_DAMP] = acc[4]
    carry[C_ACC_CONTACT] = acc[5]
    carry[C_ACC_T] = acc[6]
    carry[C_MIN_XR] = acc[7]


@njit(inline="always", **KERNEL_OPTIONS)
def _restore_segment(carry):
    """What :func:`_save_segment` stored: (fine, quasi, controlled, g_rate, h_prev, quiet, acc...)."""
    return (carry[C_FINE] != 0.0, carry[C_QUASI] != 0.0, carry[C_CONTROLLED] != 0.0, carry[C_GRATE],
            carry[C_HPREV], int(carry[C_QUIET]), carry[C_ACC_XR], carry[C_ACC_F], carry[C_ACC_WIN],
            carry[C_ACC_IN], carry[C_ACC_DAMP], carry[C_ACC_CONTACT], carry[C_ACC_T], carry[C_MIN_XR])


@njit(inline="always", **KERNEL_OPTIONS)
def _begin_run(mechanics, contacts, y, rows, carry, seg_t0, seg_x0, seg_fine, inv_ma, inv_mr):
    """Loop state at the start of a call: from rest (first call: actuators from ``y``, forces
    evaluated) or from ``carry``. Returns (t, x_p, a_r, F, n_rec, next_rec, track, steps,
    fine_steps, first segment, resume inside it, error-controlled step)."""
    if carry[C_STARTED] != 0.0:
        return (carry[C_TIME], carry[C_XP], carry[C_AR], carry[C_FORCE], int(carry[C_RECORDED]),
                carry[C_NEXT_RECORD], int(carry[C_TRACK]), int(carry[C_STEPS]), int(carry[C_FINE_STEPS]),
                int(carry[C_SEGMENT]), carry[C_MID] != 0.0, carry[C_STEP])
    multiplicity = mechanics.multiplicity
    params, state, _ = contacts
    x_a, v_a, T, u_old, a_nd = rows[0], rows[1], rows[2], rows[3], rows[4]
    G = multiplicity.shape[0]
    x_r = y[0]
    for g in range(G):
        x_a[g] = y[2 + g]
        v_a[g] = y[2 + G + g]
    t = seg_t0[0]
    x_p = seg_x0[0]
    F = 0.0
    for g in range(G):
        u = x_a[g] - x_r
        T[g] = contact_force_row(params, state, g, u)
        u_old[g] = u
        F += multiplicity[g] * T[g]
        a_nd[g] = (mechanics.actuator_stiffness * (x_p - x_a[g]) - T[g]) * inv_ma
    a_r = (F - mechanics.load_stiffness * x_r) * inv_mr
    carry[C_STARTED] = 1.0
    return t, x_p, a_r, F, 0, t, -1, 0, 0, 0, False, seg_fine[0]


@njit(inline="always", **KERNEL_OPTIONS)
def _trig_coefficients(dt, omega, omega2):
    """Coefficients of the variation-of-constants step of length dt (and of half of it):
    (sin, cos at half the step; cos, sin at the step; (1 − cos hΩ)/Ω², (hΩ − sin hΩ)/Ω³;
    the last two at half the step), without cancellation."""
    sh = np.sin(0.5 * dt * omega)
    ch = np.cos(0.5 * dt * omega)
    cs = 1.0 - 2.0 * sh * sh
    sn = 2.0 * sh * ch
    one_minus_cos = 2.0 * sh * sh / omega2
    sine_excess = (dt * omega - sn) / (omega2 * omega)
    half_one_minus_cos = sh * sh / (omega2 * (1.0 + ch))  # 1 − cos x = sin²x/(1 + cos x)
    half_sine_excess = (0.5 * dt * omega - sh) / (omega2 * omega)
    return sh, ch, cs, sn, one_minus_cos, sine_excess, half_one_minus_cos, half_sine_excess


@njit(inline="always", **KERNEL_OPTIONS)
def _s_series(x):
    """(S_1, S_2, S_3) of 0 ≤ x ≤ 2, S_n(x) = Σ_j (−1)^j x^(n+2j)/(n+2j)!: S_1 = sin x,
    S_2 = 1 − cos x, S_3 = x − sin x. S_4 and S_5 from their series (eight nested terms, exact to
    rounding for x ≤ 2; the steps keep Ωh ≤ LONGEST_OMEGA_DT = 1.5), the others down from them
    (S_n = x^n/n! − S_(n+2)): no library call, and no S_n loses digits to cancellation at small x."""
    x2 = x * x
    s5 = x2 * x2 * x * (1.0 / 120.0) * (1.0 - x2 * (1.0 / 42.0) * (1.0 - x2 * (1.0 / 72.0) * (
        1.0 - x2 * (1.0 / 110.0) * (1.0 - x2 * (1.0 / 156.0) * (1.0 - x2 * (1.0 / 210.0) * (
            1.0 - x2 * (1.0 / 272.0) * (1.0 - x2 * (1.0 / 342.0))))))))
    s4 = x2 * x2 * (1.0 / 24.0) * (1.0 - x2 * (1.0 / 30.0) * (1.0 - x2 * (1.0 / 56.0) * (
        1.0 - x2 * (1.0 / 90.0) * (1.0 - x2 * (1.0 / 132.0) * (1.0 - x2 * (1.0 / 182.0) * (
            1.0 - x2 * (1.0 / 240.0) * (1.0 - x2 * (1.0 / 306.0))))))))
    s3 = x2 * x * (1.0 / 6.0) - s5
    return x - s3, 0.5 * x2 - s4, s3


@njit(inline="always", **KERNEL_OPTIONS)
def _series_coefficients(dt, omega, inv_omega):
    """:func:`_trig_coefficients` from the series :func:`_s_series` (no sine or cosine call, the
    divisions by Ω replaced by its reciprocal): the same numbers to rounding."""
    io2 = inv_omega * inv_omega
    io3 = io2 * inv_omega
    s1, s2, s3 = _s_series(omega * dt)
    h1, h2, h3 = _s_series(0.5 * omega * dt)
    return h1, 1.0 - h2, 1.0 - s2, s1, s2 * io2, s3 * io3, h2 * io2, h3 * io3


@njit(inline="always", **KERNEL_OPTIONS)
def _trig_drift(trig, omega, omega2, beta, x_r, v_r, a_r, x_p, xp_new, vp, dt, g_rate):
    """Drift of the error-controlled step (module docstring): x_r at the step's end and the
    mid-step nodes of the energy quadrature. Returns (x_r, y0, w0, ag0, x_p, x_r, v_r at mid-step)."""
    sh, ch, cs, sn, one_minus_cos, sine_excess, half_one_minus_cos, half_sine_excess = trig
    y0 = x_r - beta * x_p
    w0 = v_r - beta * vp
    ag0 = a_r + omega2 * y0
    x_end = cs * y0 + sn / omega * w0 + one_minus_cos * ag0 + sine_excess * g_rate + beta * xp_new
    hh = 0.5 * dt
    xp_mid = x_p + vp * hh
    xr_mid = (ch * y0 + sh / omega * w0 + half_one_minus_cos * ag0 + half_sine_excess * g_rate
              + beta * xp_mid)
    vr_mid = (-omega * sh * y0 + ch * w0 + sh / omega * ag0 + half_one_minus_cos * g_rate
              + beta * vp)
    return x_end, y0, w0, ag0, xp_mid, xr_mid, vr_mid


@njit(inline="always", **KERNEL_OPTIONS)
def _trig_kick(trig, omega, omega2, beta, a_r_new, x_r, xp_new, vp, y0, w0, ag0, dt, g_rate, h_prev):
    """Velocity of the error-controlled step, with the rest force g quadratic in time through
    its values at the end, the start and the start of the previous step (curvature 0 after a
    reset of its rate). Returns (v_r, g's rate over this step, this step's length)."""
    cs, sn, one_minus_cos, sine_excess = trig[2], trig[3], trig[4], trig[5]
    ag1 = a_r_new + omega2 * (x_r - beta * xp_new)
    rate = (ag1 - ag0) / dt
    curvature = (rate - g_rate) / (dt + h_prev) if h_prev > 0.0 else 0.0
    v_r = (-omega * sn * y0 + cs * w0 + sn / omega * ag0 + one_minus_cos * (rate - curvature * dt)
           + 2.0 * sine_excess * curvature + beta * vp)
    return v_r, rate, dt


@njit(inline="always", **KERNEL_OPTIONS)
def _quasi_midpoint(mechanics, contacts, rows, g, balance_terms, x_r, nodes, quad):
    """Simpson middle node of group g in a quasi-static error-controlled step: x_a at mid-step
    from the balance over the first half step, one Newton step from the chord's midpoint
    (within O(dt²) of it), into ``rows[10]`` (``rows``: the rows of ``Buffers.work``); adds
    the group's start and mid-step terms to ``quad`` = (input, damping, contact), returned."""
    actuator_stiffness = mechanics.actuator_stiffness
    actuator_viscosity = mechanics.actuator_viscosity
    params, state, _ = contacts
    x_a, T, u_old, stretch_old, xa_old, slope = rows[0], rows[2], rows[3], rows[5], rows[6], rows[7]
    xa_mid, tangent = rows[10], rows[11]
    K, K_half, c_half, inv_K_half, inv_dt, center, dt = balance_terms
    xp_mid, xr_mid, vr_mid, vp, vr_old = nodes
    quad_in, quad_damp, quad_contact = quad
    center_mid = (actuator_stiffness * xp_mid + c_half * xa_old[g]) * inv_K_half
    chord = 0.5 * (xa_old[g] + x_a[g])
    u_chord = chord - xr_mid
    # the contact force there: the cubic Hermite in u through both ends (values and tangents:
    # the start's from the last step, the end's from the balance solve) when u is monotone over
    # the step and the start's tangent is known, else evaluated (a reversal turns the branch
    # inside the step)
    k_end = slope[g] - K
    u_start = u_old[g]
    du = x_a[g] - x_r - u_start
    du0 = _start_increment(False, vp - vr_old, dt, actuator_stiffness, k_end)
    if tangent[g] >= 0.0 and du != 0.0 and not _turns_inside(du0, du):
        sv = (u_chord - u_start) / du
        T_end = K * (center - x_a[g])
        rv = 1.0 - sv
        T_chord = ((1.0 + 2.0 * sv) * rv * rv * T[g] + sv * sv * (3.0 - 2.0 * sv) * T_end
                   + du * sv * rv * (rv * tangent[g] - sv * k_end))
    else:
        T_chord = contact_force_row(params, state, g, u_chord)
    balance = K_half * (center_mid - chord) - T_chord
    xa_mid[g] = chord + balance / max(k_end + K_half, K_half)
    T_mid = K_half * (center_mid - xa_mid[g])
    # velocities of the quadratic through x_a at start, mid-step and end
    q0 = (4.0 * xa_mid[g] - 3.0 * xa_old[g] - x_a[g]) * inv_dt
    q_mid = (x_a[g] - xa_old[g]) * inv_dt
    n_g = mechanics.multiplicity[g]
    quad_in += n_g * actuator_stiffness * (stretch_old[g] + 4.0 * (xp_mid - xa_mid[g]))
    quad_damp += n_g * actuator_viscosity * (q0 * q0 + 4.0 * q_mid * q_mid)
    quad_contact += n_g * (T[g] * (q0 - vr_old) + 4.0 * T_mid * (q_mid - vr_mid))
    return quad_in, quad_damp, quad_contact


@njit(inline="always", **KERNEL_OPTIONS)
def _quasi_balance(mechanics, contacts, rows, x_p, xp_new, x_r, xr_old, dt, simpson, nodes, newton):
    """Drift of quasi-static actuators: each group's force balance solved at the step's end
    (:func:`quasi_static_position`, backward Euler in the damping term; with ``newton`` by a Newton
    step on the contact's exact slope, :func:`_newton_position`, and one reciprocal of K instead of
    divisions by it), and with ``simpson`` its mid-step node (:func:`_quasi_midpoint`). Returns
    (K = k_p + c_p/dt, 1/dt, Σ n_g T_g at the balance, and the start and mid-step quadrature terms
    of input, damping and contact)."""
    multiplicity = mechanics.multiplicity
    actuator_stiffness = mechanics.actuator_stiffness
    params, state, sliding = contacts
    x_a, T, stretch_old, xa_old, slope = rows[0], rows[2], rows[5], rows[6], rows[7]
    inv_dt = 1.0 / dt
    c_dt = mechanics.actuator_viscosity * inv_dt
    K = actuator_stiffness + c_dt
    c_half = 2.0 * c_dt  # (the balance over half the step)
    K_half = actuator_stiffness + c_half
    inv_K_half = 1.0 / K_half
    inv_K = 1.0 / K
    F_trial = 0.0  # Σ n_g T_g at the solved balance, T_g = K (center − x_a,g)
    quad = (0.0, 0.0, 0.0)
    for g in range(multiplicity.shape[0]):
        stretch_old[g] = x_p - x_a[g]
        xa_old[g] = x_a[g]
        pull = actuator_stiffness * xp_new + c_dt * x_a[g]
        center = pull * inv_K if newton else pull / K
        # Newton predictor from the last solution: T moves by k_t Δu, k_t = slope − K
        sg = max(slope[g], K)
        guess = x_a[g] + (K * (center - x_a[g]) - T[g] - (sg - K) * (xr_old - x_r)) / sg
        if newton:
            x_a[g], slope[g] = _newton_position(params, state, g, x_r, center, K, sliding[g], guess, sg,
                                                QUASI_TOLERANCE * sliding[g] * inv_K)
        else:
            x_a[g], slope[g] = quasi_static_position(
                params, state, g, x_r, center, K, sliding[g], guess, sg, QUASI_TOLERANCE * sliding[g] / K,
            )
        F_trial += multiplicity[g] * K * (center - x_a[g])
        if simpson:
            terms = (K, K_half, c_half, inv_K_half, inv_dt, center, dt)
            quad = _quasi_midpoint(mechanics, contacts, rows, g, terms, x_r, nodes, quad)
    return K, inv_dt, F_trial, quad[0], quad[1], quad[2]


@njit(inline="always", **KERNEL_OPTIONS)
def _step_factor(mechanics, contacts, rows, rigid, F_trial, x_r, a_r, xp_new, y0, dt, g_rate, omega, omega2,
                 beta, inv_mr, error_tolerance, small_error):
    """Local position error of the drift, dt³ x'''/6 with x''' ≈ Δa/dt, from the forces at the
    drifted positions with the memory as committed (pure; the quasi-static balance has them
    already in ``F_trial``), and the factor for the next step. Returns (error, factor)."""
    if rigid:
        multiplicity = mechanics.multiplicity
        params, state, _ = contacts
        x_a = rows[0]
        F_trial = 0.0
        for g in range(multiplicity.shape[0]):
            F_trial += multiplicity[g] * contact_force_row(params, state, g, x_a[g] - x_r)
    # (the trigonometric step: of g only, its linear part is exact)
    da = (F_trial - mechanics.load_stiffness * x_r) * inv_mr - a_r
    if omega > 0.0:
        # g extrapolated at its last rate: the error is of its change of rate, O(dt⁴)
        da += omega2 * (x_r - beta * xp_new - y0) - g_rate * dt
    err = abs(da) * dt * dt / 6.0
    factor = STEP_GROWTH
    if err > small_error:
        allowed = STEP_SAFETY * np.sqrt(np.sqrt(error_tolerance / err))  # local error ∝ dt⁴
        factor = min(STEP_GROWTH, max(STEP_SHRINK, allowed))
    return err, factor


@njit(inline="always", **KERNEL_OPTIONS)
def _rigid_mid_force(mechanics, contacts, xp_mid, xr_mid):
    """Σ n_g T_g at mid-step of a rigid error-controlled step (pure), the Simpson middle node."""
    multiplicity = mechanics.multiplicity
    params, state, _ = contacts
    F_mid = 0.0
    for g in range(multiplicity.shape[0]):
        F_mid += multiplicity[g] * contact_force_row(params, state, g, xp_mid - xr_mid)
    return F_mid


@njit(inline="always", **KERNEL_OPTIONS)
def _commit_contacts(mechanics, contacts, rows, peak, track, x_r, v_r, vp, dt, K, controlled, simpson, x_p,
                     xp_new, acc_contact, acc_in, energy):
    """Contact forces at the step's end, the memory committed once (twice when u turns inside an
    error-controlled step: first at the extremum). Returns (Σ n_g T_g, acc_contact, acc_in); the
    trapezoidal energy terms only with ``energy`` (Simpson's are the caller's)."""
    multiplicity = mechanics.multiplicity
    rigid = mechanics.rigid
    params, state, sliding = contacts
    x_a, T, u_old, slope, T_old = rows[0], rows[2], rows[3], rows[7], rows[8]
    F = 0.0
    for g in range(multiplicity.shape[0]):
        u = x_a[g] - x_r
        T_start = T[g]
        T_old[g] = T_start
        if controlled:
            # a reversal of u inside the step is an event: the extremum of the quadratic through
            # u at the start (value and rate) and at the end is committed first, so the Masing
            # branch turns at it, not at the last step boundary (k_t: the tangent stiffness
            # that the last balance solve found)
            du0 = _start_increment(rigid, vp - v_r, dt, mechanics.actuator_stiffness, slope[g] - K)
            if _turns_inside(du0, u - u_old[g]):
                excess = u - u_old[g] - du0  # curvature term of the quadratic, times dt²
                u_ext = u_old[g] - du0 * du0 / (4.0 * excess)
                T_ext = contact_update_row(params, state, g, u_ext)
                if energy and not simpson:
                    acc_contact += multiplicity[g] * 0.5 * (T[g] + T_ext) * (u_ext - u_old[g])
                T[g] = T_ext
                u_old[g] = u_ext
                _note_peak(peak, track, g, T_ext, sliding[g])
        Tn = contact_update_row(params, state, g, u)
        if energy and not simpson:
            acc_contact += multiplicity[g] * 0.5 * (T[g] + Tn) * (u - u_old[g])
            if rigid:
                acc_in += multiplicity[g] * 0.5 * (T_start + Tn) * (xp_new - x_p)
        T[g] = Tn
        u_old[g] = u
        F += multiplicity[g] * Tn
        _note_peak(peak, track, g, Tn, sliding[g])
    return F, acc_contact, acc_in


@njit(inline="always", **KERNEL_OPTIONS)
def _quasi_kick(mechanics, rows, x_p, xp_new, v_r, vp, dt, K, inv_dt, inv_ma, simpson, quad, acc_in, acc_damp,
                acc_contact, energy):
    """Actuator velocities and accelerations after a quasi-static step and its energy terms
    (Simpson's rule when ``simpson``, else backward Euler in the damping and trapezoidal input
    work; none without ``energy``). Returns (largest implied |ẍ_a|, acc_in, acc_damp, acc_contact)."""
    multiplicity = mechanics.multiplicity
    actuator_stiffness = mechanics.actuator_stiffness
    actuator_viscosity = mechanics.actuator_viscosity
    half_kp = 0.5 * actuator_stiffness
    x_a, v_a, T, a_nd, stretch_old, xa_old = rows[0], rows[1], rows[2], rows[4], rows[5], rows[6]
    slope, xa_mid, tangent = rows[7], rows[10], rows[11]
    quad_in, quad_damp, quad_contact = quad
    activity = 0.0
    for g in range(multiplicity.shape[0]):
        v_old = v_a[g]
        v_a[g] = (x_a[g] - xa_old[g]) / dt
        a_nd[g] = (actuator_stiffness * (xp_new - x_a[g]) - T[g]) * inv_ma
        tangent[g] = slope[g] - K  # (the next step's start: this step's end)
        if not energy:
            pass
        elif simpson:
            # end terms of the quadrature (start and mid-step ones: at the drift)
            q1 = (xa_old[g] - 4.0 * xa_mid[g] + 3.0 * x_a[g]) * inv_dt
            quad_in += multiplicity[g] * actuator_stiffness * (xp_new - x_a[g])
            quad_damp += multiplicity[g] * actuator_viscosity * q1 * q1
            quad_contact += multiplicity[g] * T[g] * (q1 - v_r)
        else:
            # backward Euler: c_p v_a (x_a − x_a,old) = c_p v_a² dt
            acc_damp += multiplicity[g] * actuator_viscosity * v_a[g] * v_a[g] * dt
            stretch_sum = stretch_old[g] + xp_new - x_a[g]
            acc_in += multiplicity[g] * half_kp * stretch_sum * (xp_new - x_p)
        acc = abs(v_a[g] - v_old) / dt
        if acc > activity:
            activity = acc
    if energy and simpson:
        acc_in += vp * dt / 6.0 * quad_in
        acc_damp += dt / 6.0 * quad_damp
        acc_contact += dt / 6.0 * quad_contact
    return activity, acc_in, acc_damp, acc_contact


@njit(inline="always", **KERNEL_OPTIONS)
def _actuator_kick(mechanics, rows, x_p, xp_new, dt, gam, inv_ma, acc_damp, acc_in, energy, damp):
    """Velocity Verlet kick of flexible actuators (damping trapezoidal, implicit in v; ``damp`` =
    1/(1 + γ dt/2)) and, with ``energy``, its damping and input work. Returns (largest |ẍ_a|,
    acc_damp, acc_in)."""
    multiplicity = mechanics.multiplicity
    actuator_stiffness = mechanics.actuator_stiffness
    half_kp = 0.5 * actuator_stiffness
    half_cp = 0.5 * mechanics.actuator_viscosity
    x_a, v_a, T, a_nd, stretch_old = rows[0], rows[1], rows[2], rows[4], rows[5]
    activity = 0.0
    for g in range(multiplicity.shape[0]):
        a_new = (actuator_stiffness * (xp_new - x_a[g]) - T[g]) * inv_ma
        v_old = v_a[g]
        v_a[g] = (v_old + 0.5 * dt * (a_nd[g] - gam * v_old + a_new)) * damp
        a_nd[g] = a_new
        if energy:
            acc_damp += multiplicity[g] * half_cp * (v_old * v_old + v_a[g] * v_a[g]) * dt
            # work of the moving piezo base: k_p (x_p − x_a) dx_p, trapezoidal in (x_p − x_a)
            acc_in += multiplicity[g] * half_kp * (stretch_old[g] + xp_new - x_a[g]) * (xp_new - x_p)
        acc = abs(a_new - gam * v_a[g])
        if acc > activity:
            activity = acc
    return activity, acc_damp, acc_in


@njit(inline="always", **KERNEL_OPTIONS)
def _adapt(activity, activity_threshold, quiet_steps, quasi_static, control_on, fine, quasi, controlled,
           quiet, dt_ctrl, dt_quasi, g_rate, h_prev, tangent):
    """Step control of flexible actuators after an explicit step: back to the fine step when
    |ẍ_a| reaches the threshold; after ``quiet_steps`` fine steps below it, the quiet phase
    (coarse, or quasi-static and error-controlled from ``dt_quasi``). Returns the new (fine,
    quasi, controlled, quiet, dt_ctrl, g_rate, h_prev)."""
    if fine:
        if activity < activity_threshold:
            quiet += 1
            if quiet >= quiet_steps:
                fine = False
                quasi = quasi_static
                controlled = quasi_static and control_on
                dt_ctrl = dt_quasi
                g_rate = 0.0
                h_prev = 0.0
                for g in range(tangent.shape[0]):
                    tangent[g] = -1.0
        else:
            quiet = 0
    elif activity >= activity_threshold:
        fine = True
        quiet = 0
    return fine, quasi, controlled, quiet, dt_ctrl, g_rate, h_prev


@njit(inline="always", **KERNEL_OPTIONS)
def _runaway(rigid, x_r, v_r, x_a, v_a, x_p):
    """Whether the state has diverged: |x_r|, |x_a − x_p| or a velocity beyond its limit (NaN
    too: comparisons with NaN are False)."""
    ok = abs(x_r) < POSITION_LIMIT and abs(v_r) < VELOCITY_LIMIT
    if not rigid:
        for g in range(x_a.shape[0]):
            ok = ok and abs(x_a[g] - x_p) < POSITION_LIMIT and abs(v_a[g]) < VELOCITY_LIMIT
    return not ok


@njit(inline="always", **KERNEL_OPTIONS)
def _record_inside(contacts, rows, record, rigid, n_rec, next_rec, record_interval, t_old, t, dt, xp_old, x_p,
                   xr_old, x_r, vr_old, v_r):
    """Samples at their own times inside a long step: cubic Hermite in x_r (from the positions
    and velocities at both ends), linear in x_p, x_a and T; the slip share of the step's end.
    Returns (rows recorded, next sample time)."""
    params, state, _ = contacts
    x_a, T, xa_old, T_old, share = rows[0], rows[2], rows[6], rows[8], rows[9]
    G = x_a.shape[0]
    max_rec = record.shape[0]
    for g in range(G):
        share[g] = contact_slip_share_row(params, state, g, x_a[g] - x_r)
    while next_rec <= t and n_rec < max_rec:
        th = (next_rec - t_old) / dt
        th2 = th * th
        th3 = th2 * th
        record[n_rec, 0] = next_rec
        record[n_rec, 1] = xp_old + th * (x_p - xp_old)
        record[n_rec, 2] = ((2.0 * th3 - 3.0 * th2 + 1.0) * xr_old + (3.0 * th2 - 2.0 * th3) * x_r
                            + ((th3 - 2.0 * th2 + th) * vr_old + (th3 - th2) * v_r) * dt)
        record[n_rec, 3] = (6.0 * (th2 - th) * (xr_old - x_r) / dt + (3.0 * th2 - 4.0 * th + 1.0)
                            * vr_old + (3.0 * th2 - 2.0 * th) * v_r)
        for g in range(G):
            xa0 = xp_old if rigid else xa_old[g]
            record[n_rec, 4 + 3 * g] = xa0 + th * (x_a[g] - xa0)
            record[n_rec, 5 + 3 * g] = T_old[g] + th * (T[g] - T_old[g])
            record[n_rec, 6 + 3 * g] = share[g]
        n_rec += 1
        next_rec += record_interval
    return n_rec, next_rec


@njit(inline="always", **KERNEL_OPTIONS)
def _record_step_end(contacts, rows, record, n_rec, next_rec, record_interval, t, x_p, x_r, v_r):
    """One sample at the step's end (the next sample time is at or before it). Returns (rows
    recorded, next sample time)."""
    params, state, _ = contacts
    x_a, T = rows[0], rows[2]
    record[n_rec, 0] = t
    record[n_rec, 1] = x_p
    record[n_rec, 2] = x_r
    record[n_rec, 3] = v_r
    for g in range(x_a.shape[0]):
        record[n_rec, 4 + 3 * g] = x_a[g]
        record[n_rec, 5 + 3 * g] = T[g]
        record[n_rec, 6 + 3 * g] = contact_slip_share_row(params, state, g, x_a[g] - x_r)
    n_rec += 1
    while next_rec <= t:
        next_rec += record_interval
    return n_rec, next_rec


@njit(inline="always", **KERNEL_OPTIONS)
def _smooth_breakpoint(segments, s, vp):
    """Whether x_p(t) keeps its rate across the start of piece s (a breakpoint that only marks a
    window, as the settle window's start on a saw-tooth ramp: nothing there excites the
    actuators or changes g's rate)."""
    if s == 0:
        return False
    before = (segments.x1[s - 1] - segments.x0[s - 1]) / (segments.t1[s - 1] - segments.t0[s - 1])
    return abs(vp - before) <= SMOOTH_BREAKPOINT_RTOL * max(abs(vp), abs(before))


@njit(inline="always", **KERNEL_OPTIONS)
def _open_segment(per, mark, in_window, k, track, x_r, rigid, control_on):
    """Start of a segment: slip-mark tracking and the initial step control. Every piece starts
    with the fine step (its corner excites the actuator mode); rigid actuators under error
    control go on with the controlled step (a corner changes the rate of g, and the error
    estimate adapts to it). Returns (track, fine, quasi, controlled, g_rate, h_prev, quiet,
    acc) with the segment-local accumulators ``acc`` zero (see :func:`_save_segment`)."""
    if mark:
        track = k
        per[k, PER_MARK_XR] = x_r
        per[k, PER_MIN_XR] = x_r
    if in_window and track >= 0 and k > track:
        track = -1
    min_xr = per[track, PER_MIN_XR] if track >= 0 else 0.0
    # (g's rate is not known after the corner: x_p's rate changes there)
    return (track, not (rigid and control_on), False, rigid and control_on, 0.0, 0.0, 0,
            (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, min_xr))


@njit(inline="always", **KERNEL_OPTIONS)
def _step_length(fine, controlled, quasi, dt_ctrl, segments, s, t, vp):
    """The next step: its length, end time, x_p there, and whether it ends the segment (a step
    that would leave a sliver of the piece is stretched to its corner)."""
    if fine:
        dt = segments.fine[s]
    elif controlled:
        dt = min(dt_ctrl, segments.longest[s])
    elif quasi:
        dt = segments.quasi[s]
    else:
        dt = segments.coarse[s]
    t_end = segments.t1[s]
    if t_end - t <= dt * LAST_STEP_STRETCH:
        return t_end - t, t_end, segments.x1[s], True
    t_new = t + dt
    return dt, t_new, segments.x0[s] + vp * (t_new - segments.t0[s]), False


@njit(inline="always", **KERNEL_OPTIONS)
def _linear_mode(linear_stiffness, load_stiffness, runner_mass):
    """(Ω², Ω, β) of the error-controlled step: the runner on the linear spring K to x_p (and the
    load cell) oscillates at Ω about z = β x_p; that part is integrated exactly."""
    omega2 = (linear_stiffness + load_stiffness) / runner_mass
    beta = linear_stiffness / (linear_stiffness + load_stiffness) if linear_stiffness > 0.0 else 0.0
    return omega2, np.sqrt(omega2), beta


@njit(inline="always", **KERNEL_OPTIONS)
def _reject(carry, x_a, xa_old, rigid, x_p, xr_old, shorter, dt_fine):
    """A rejected error-controlled step: positions back to the step's start, counted in
    ``carry``. Returns (x_r, the step to retry with, not done)."""
    for g in range(x_a.shape[0]):
        x_a[g] = x_p if rigid else xa_old[g]
    carry[C_REJECTED] += 1.0
    return xr_old, max(shorter, dt_fine), False


@njit(inline="always", **KERNEL_OPTIONS)
def _measure(acc_xr, acc_f, acc_t, acc_win, min_xr, in_window, xr_old, x_r, F_old, F, x_p, xp_new, dt):
    """The step's share of the per-period measures (trapezoidal; the window integral of
    x_r − x_p only inside the settle window) and the lowest x_r."""
    acc_xr += (xr_old + x_r) * dt
    acc_f += (F_old + F) * dt
    acc_t += dt
    if in_window:
        acc_win += ((xr_old - x_p) + (x_r - xp_new)) * dt
    if x_r < min_xr:
        min_xr = x_r
    return acc_xr, acc_f, acc_t, acc_win, min_xr


@njit(inline="always", **KERNEL_OPTIONS)
def _save_state(y, x_r, v_r, x_a, v_a):
    """The state into ``y`` = [x_r, v_r, x_a(0..G−1), v_a(0..G−1)] at the end of a run."""
    G = x_a.shape[0]
    y[0] = x_r
    y[1] = v_r
    for g in range(G):
        y[2 + g] = x_a[g]
        y[2 + G + g] = v_a[g]


@njit(inline="always", **KERNEL_OPTIONS)
def _close_segment(per, energy, k, track, in_window, x1, acc):
    """Segment-local accumulators ``acc`` (see :func:`_save_segment`) into the per-period and
    energy accumulators."""
    acc_xr, acc_f, acc_win, acc_in, acc_damp, acc_contact, acc_t, min_xr = acc
    per[k, PER_XR_INTEGRAL] += 0.5 * acc_xr
    per[k, PER_FRICTION_INTEGRAL] += 0.5 * acc_f
    per[k, PER_DURATION] += acc_t
    if in_window:
        per[k, PER_WINDOW_INTEGRAL] += 0.5 * acc_win
        per[k, PER_WINDOW_LENGTH] += acc_t
        per[k, PER_WINDOW_END_XP] = x1
    if track >= 0:
        per[track, PER_MIN_XR] = min_xr
    energy[EN_CONTACT] += acc_contact
    energy[EN_INPUT] += acc_in
    energy[EN_DAMPING] += acc_damp


@njit(**KERNEL_OPTIONS)
def _integrate(segments, mechanics, control, contacts, buffers, step_limit):
    """Integrate over the segments (see :func:`integrate`); returns (status, steps done, rows
    recorded, fine steps). Each step: choose its length, drift (runner, actuators), estimate
    its error (error control; a rejected step starts over shorter), commit the contacts, kick,
    adapt the step, accumulate the period's measures, check for divergence, record. A piece of
    x_p(t) starts the step control afresh (:func:`_open_segment`) unless ``smooth_breakpoints``
    and x_p keeps its rate across its start."""
    (seg_t0, seg_t1, seg_x0, seg_x1, seg_fine, seg_coarse, seg_period, seg_window, seg_mark, seg_quasi,
     seg_longest) = segments
    runner_mass, load_stiffness, multiplicity, rigid = mechanics[:4]
    actuator_mass, actuator_viscosity, linear_stiffness = mechanics[4], mechanics[6], mechanics[7]
    omega2, omega, beta = _linear_mode(linear_stiffness, load_stiffness, runner_mass)
    inv_omega = 1.0 / omega if omega > 0.0 else 0.0
    dt_damp = damp = -1.0
    dt_trig = -1.0
    trig = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    y0 = w0 = ag0 = xp_mid = xr_mid = vr_mid = F_mid = 0.0  # drift terms and mid-step nodes
    K = inv_dt = 0.0  # the quasi-static balance's stiffness k_p + c_p/dt and 1/dt (its steps)
    (activity_threshold, quiet_steps, quasi_static, record_interval, error_tolerance, newton, smooth,
     track_energy) = control
    control_on = error_tolerance > 0.0
    # error estimates below this need no root: the step grows by the largest factor
    small_error = error_tolerance * (STEP_SAFETY / STEP_GROWTH) ** 4
    y, work, carry, record, per, peak, energy = buffers
    # the rows of ``work`` as a tuple of views, made once: the helpers index it with constants
    rows = (work[0], work[1], work[2], work[3], work[4], work[5], work[6], work[7], work[8], work[9],
            work[10], work[11])
    x_r = y[0]
    v_r = y[1]
    x_a, v_a, a_nd, stretch_old, xa_old, tangent = rows[0], rows[1], rows[4], rows[5], rows[6], rows[11]
    gam = actuator_viscosity / actuator_mass
    inv_ma = 1.0 / actuator_mass
    inv_mr = 1.0 / runner_mass
    # the step control where the last call stopped (zeros before the first call)
    (fine, quasi, controlled, g_rate, h_prev, quiet, acc_xr, acc_f, acc_win, acc_in, acc_damp, acc_contact,
     acc_t, min_xr) = _restore_segment(carry)
    (t, x_p, a_r, F, n_rec, next_rec, track, steps, fine_steps, first_segment, resume,
     dt_ctrl) = _begin_run(mechanics, contacts, y, rows, carry, seg_t0, seg_x0, seg_fine, inv_ma, inv_mr)
    for s in range(first_segment, seg_t0.shape[0]):
        k = seg_period[s]
        t_end = seg_t1[s]
        vp = (seg_x1[s] - seg_x0[s]) / (t_end - seg_t0[s])
        in_window = seg_window[s] != 0
        dt_fine = seg_fine[s]
        adaptive = (not rigid) and seg_coarse[s] > dt_fine
        if resume:
            resume = False
        else:
            track, fine_o, quasi_o, controlled_o, g_rate_o, h_prev_o, quiet_o, acc = _open_segment(
                per, seg_mark[s], in_window, k, track, x_r, rigid, control_on)
            acc_xr, acc_f, acc_win, acc_in, acc_damp, acc_contact, acc_t, min_xr = acc
            if not (smooth and _smooth_breakpoint(segments, s, vp)):
                fine, quasi, controlled, g_rate, h_prev, quiet = (fine_o, quasi_o, controlled_o, g_rate_o,
                                                                  h_prev_o, quiet_o)
        done = False
        while not done:
            if steps >= step_limit:  # pause: everything the loop carries goes to carry, y and work
                _save_position(carry, s, 1.0, t, x_p, a_r, F, next_rec, track, n_rec, steps, fine_steps,
                               dt_ctrl)
                _save_segment(carry, y, x_r, v_r, fine, quasi, controlled, g_rate, h_prev, quiet,
                              (acc_xr, acc_f, acc_win, acc_in, acc_damp, acc_contact, acc_t, min_xr))
                return STATUS_PAUSED, steps, n_rec, fine_steps
            dt, t_new, xp_new, done = _step_length(fine, controlled, quasi, dt_ctrl, segments, s, t, vp)
            if fine:
                fine_steps += 1
            xr_old = x_r
            vr_old = v_r
            F_old = F
            exact_linear = controlled and omega > 0.0  # the runner's linear part integrated exactly
            simpson = exact_linear and track_energy  # energy terms by Simpson's rule
            if exact_linear:  # drift
                if dt != dt_trig:  # (steps repeat at the longest step: their sines are kept)
                    dt_trig = dt
                    if newton:
                        trig = _series_coefficients(dt, omega, inv_omega)
                    else:
                        trig = _trig_coefficients(dt, omega, omega2)
                x_r, y0, w0, ag0, xp_mid, xr_mid, vr_mid = _trig_drift(
                    trig, omega, omega2, beta, x_r, v_r, a_r, x_p, xp_new, vp, dt, g_rate)
            else:
                x_r += dt * v_r + 0.5 * dt * dt * a_r
            quad_in = quad_damp = quad_contact = 0.0  # start and mid-step terms of the quadrature
            F_trial = 0.0
            if rigid:
                for g in range(x_a.shape[0]):
                    x_a[g] = xp_new
            elif quasi:
                K, inv_dt, F_trial, quad_in, quad_damp, quad_contact = _quasi_balance(
                    mechanics, contacts, rows, x_p, xp_new, x_r, xr_old, dt, simpson,
                    (xp_mid, xr_mid, vr_mid, vp, vr_old), newton)
            else:
                for g in range(x_a.shape[0]):
                    stretch_old[g] = x_p - x_a[g]
                    x_a[g] += dt * v_a[g] + 0.5 * dt * dt * (a_nd[g] - gam * v_a[g])
            if controlled:
                err, factor = _step_factor(mechanics, contacts, rows, rigid, F_trial, x_r, a_r, xp_new, y0,
                                           dt, g_rate, omega, omega2, beta, inv_mr, error_tolerance,
                                           small_error)
                if err > error_tolerance and dt > dt_fine:
                    # rejected: back to the start of the step, to retry with a shorter one
                    x_r, dt_ctrl, done = _reject(carry, x_a, xa_old, rigid, x_p, xr_old, dt * factor, dt_fine)
                    steps += 1
                    continue
                if not done:
                    dt_ctrl = min(dt * factor, seg_longest[s])
            if simpson and rigid:
                F_mid = _rigid_mid_force(mechanics, contacts, xp_mid, xr_mid)
            F, acc_contact, acc_in = _commit_contacts(mechanics, contacts, rows, peak, track, x_r, v_r, vp,
                                                      dt, K, controlled, simpson, x_p, xp_new, acc_contact,
                                                      acc_in, track_energy)
            a_r_new = (F - load_stiffness * x_r) * inv_mr  # kick
            if exact_linear:
                v_r, g_rate, h_prev = _trig_kick(trig, omega, omega2, beta, a_r_new, x_r, xp_new, vp, y0, w0,
                                                 ag0, dt, g_rate, h_prev)
            else:
                v_r += 0.5 * dt * (a_r + a_r_new)
            a_r = a_r_new
            if simpson and rigid:
                acc_in += vp * dt / 6.0 * (F_old + 4.0 * F_mid + F)
                acc_contact += dt / 6.0 * ((vp - vr_old) * F_old + 4.0 * (vp - vr_mid) * F_mid
                                           + (vp - v_r) * F)
            if quasi:
                activity, acc_in, acc_damp, acc_contact = _quasi_kick(
                    mechanics, rows, x_p, xp_new, v_r, vp, dt, K, inv_dt, inv_ma, simpson,
                    (quad_in, quad_damp, quad_contact), acc_in, acc_damp, acc_contact, track_energy)
                if activity >= activity_threshold:
                    fine = True
                    quasi = False
                    controlled = False
                    quiet = 0
            elif not rigid:
                if dt != dt_damp:  # (the fine step repeats: its damping factor is kept)
                    dt_damp = dt
                    damp = 1.0 / (1.0 + 0.5 * dt * gam)
                activity, acc_damp, acc_in = _actuator_kick(mechanics, rows, x_p, xp_new, dt, gam, inv_ma,
                                                            acc_damp, acc_in, track_energy, damp)
                if adaptive:
                    fine, quasi, controlled, quiet, dt_ctrl, g_rate, h_prev = _adapt(
                        activity, activity_threshold, quiet_steps, quasi_static, control_on, fine, quasi,
                        controlled, quiet, dt_ctrl, seg_quasi[s], g_rate, h_prev, tangent)
            acc_xr, acc_f, acc_t, acc_win, min_xr = _measure(acc_xr, acc_f, acc_t, acc_win, min_xr, in_window,
                                                             xr_old, x_r, F_old, F, x_p, xp_new, dt)
            t_old = t
            xp_old = x_p
            t = t_new
            x_p = xp_new
            steps += 1
            if _runaway(rigid, x_r, v_r, x_a, v_a, x_p):
                y[0] = x_r
                y[1] = v_r
                return STATUS_DIVERGED, steps, n_rec, fine_steps
            if controlled and next_rec <= t and n_rec < record.shape[0]:
                n_rec, next_rec = _record_inside(contacts, rows, record, rigid, n_rec, next_rec,
                                                 record_interval, t_old, t, dt, xp_old, x_p, xr_old, x_r,
                                                 vr_old, v_r)
            elif t >= next_rec and n_rec < record.shape[0]:
                n_rec, next_rec = _record_step_end(contacts, rows, record, n_rec, next_rec, record_interval,
                                                   t, x_p, x_r, v_r)
        _close_segment(per, energy, k, track, in_window, seg_x1[s],
                       (acc_xr, acc_f, acc_win, acc_in, acc_damp, acc_contact, acc_t, min_xr))
    # done: the loop state goes to carry as at a pause between two segments, so that a call
    # with these segments followed by more (the same arrays, longer) continues the run
    _save_position(carry, seg_t0.shape[0], 0.0, t, x_p, a_r, F, next_rec, track, n_rec, steps, fine_steps,
                   dt_ctrl)
    _save_segment(carry, y, x_r, v_r, fine, quasi, controlled, g_rate, h_prev, quiet,
                  (acc_xr, acc_f, acc_win, acc_in, acc_damp, acc_contact, acc_t, min_xr))
    _save_state(y, x_r, v_r, x_a, v_a)
    return STATUS_OK, steps, n_rec, fine_steps
