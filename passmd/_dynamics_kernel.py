"""numba kernel of the hybrid simulation (Eqs. 2–3 with the MDR contacts in the loop).

Only :mod:`passmd.dynamics` calls this; it validates, allocates and interprets. The
kernel takes plain arrays and scalars.

Scheme: velocity Verlet (kick–drift–kick) on runner and actuators; the actuator's
viscous term −c_p ẋ_a is treated with the trapezoidal rule in the velocity update
(implicit in v, still explicit overall). The contact memory is updated exactly once
per step, with the drifted positions, and the contact force is otherwise evaluated
purely. Every corner of x_p(t) falls on a step boundary. With flexible actuators the step
adapts: fine (resolving the ≈ 3 MHz actuator mode) while the actuators ring, coarse
(a fraction of the explicit stability limit) while they follow quasi-statically.
"""

from __future__ import annotations

from numba import njit

from passmd.contact import contact_force_row, contact_slip_share_row, contact_update_row

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
CARRY_SIZE = 23


#: numba options: the kernel allocates nothing (work arrays come from the caller), so it is
#: compiled without reference counting; with it, every call into the contact kernels paid
#: atomic reference-count updates on the array arguments (≈ 30 ns per step).
KERNEL_OPTIONS = {"cache": True, "error_model": "numpy", "_nrt": False}

#: rows of the work array (shape (WORK_ROWS, groups)) the caller allocates
WORK_ROWS = 8
#: quasi-static step: the actuator's force balance is solved to this fraction of S/K
#: (≈ 6e-15 m; a force error ≤ 1e-6 μF_N)
QUASI_TOLERANCE = 1e-6


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
    for it in range(200):
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


@njit(**KERNEL_OPTIONS)
def integrate(
    seg_t0,
    seg_t1,
    seg_x0,
    seg_x1,
    seg_fine,
    seg_coarse,
    seg_period,
    seg_window,
    seg_mark,
    seg_quasi,
    activity_threshold,
    quiet_steps,
    quasi_static,
    runner_mass,
    load_stiffness,
    multiplicity,
    rigid,
    actuator_mass,
    actuator_stiffness,
    actuator_viscosity,
    params,
    state,
    sliding,
    y,
    work,
    carry,
    step_limit,
    record_interval,
    record,
    per,
    peak,
    energy,
    position_limit,
    velocity_limit,
):
    """Integrate over the segments; returns (status, steps done, rows recorded, fine steps).

    Work is bounded: once ``step_limit`` steps (counted from the start of the run) are
    done, the kernel stores its loop state in ``carry`` (shape (CARRY_SIZE,), zeros
    before the first call) and returns STATUS_PAUSED; calling it again with the same
    arrays continues exactly where it stopped, with the same floating-point operations
    in the same order as an uninterrupted run (the contact memory lives in ``state``).

    ``sliding`` holds μF_N of each group; ``peak[k, g]`` receives the largest |T_g|/μF_N from
    period k's slip mark to the next settle window (1 exactly when the group slid fully).
    ``y`` = [x_r, v_r, x_a(0..G−1), v_a(0..G−1)] is updated in place; ``work`` is scratch
    of shape (WORK_ROWS, G). ``record`` rows are
    [t, x_p, x_r, v_r, (x_a, T, slip share) per group].

    Step control (flexible actuators): every segment starts with the fine step
    ``seg_fine`` (a corner of x_p(t) excites the actuator mode). Once the largest
    actuator acceleration |ẍ_a| has stayed below ``activity_threshold`` for
    ``quiet_steps`` fine steps, the step grows to ``seg_coarse``; it falls back to fine
    as soon as |ẍ_a| exceeds the threshold again. Rigid actuators: ``seg_fine`` only.

    With ``quasi_static`` the quiet phases instead neglect m_a: each step of
    ``seg_quasi`` (set by the runner's mode) solves the actuator's force balance
    k_p (x_p − x_a) = c_p ẋ_a + T(x_a − x_r) implicitly (backward Euler in the damping
    term, :func:`quasi_static_position`), then commits the contact memory once, as the
    explicit step does. The implied actuator acceleration is checked against the same
    threshold; above it, the fine explicit step takes over again.
    """
    G = multiplicity.shape[0]
    x_r = y[0]
    v_r = y[1]
    x_a = work[0]
    v_a = work[1]
    T = work[2]
    u_old = work[3]
    a_nd = work[4]  # actuator acceleration without the damping term
    stretch_old = work[5]  # x_p − x_a at the previous step
    xa_old = work[6]  # x_a at the previous step (quasi-static step)
    slope = work[7]  # last −h' of the quasi-static balance (0: none yet)
    gam = actuator_viscosity / actuator_mass
    inv_ma = 1.0 / actuator_mass
    inv_mr = 1.0 / runner_mass
    if carry[C_STARTED] == 0.0:
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
            a_nd[g] = (actuator_stiffness * (x_p - x_a[g]) - T[g]) * inv_ma
        a_r = (F - load_stiffness * x_r) * inv_mr
        n_rec = 0
        next_rec = t
        track = -1
        steps = 0
        fine_steps = 0
        first_segment = 0
        resume = False
        carry[C_STARTED] = 1.0
    else:
        t = carry[C_TIME]
        x_p = carry[C_XP]
        a_r = carry[C_AR]
        F = carry[C_FORCE]
        n_rec = int(carry[C_RECORDED])
        next_rec = carry[C_NEXT_RECORD]
        track = int(carry[C_TRACK])
        steps = int(carry[C_STEPS])
        fine_steps = int(carry[C_FINE_STEPS])
        first_segment = int(carry[C_SEGMENT])
        resume = carry[C_MID] != 0.0
    max_rec = record.shape[0]
    for s in range(first_segment, seg_t0.shape[0]):
        k = seg_period[s]
        t_end = seg_t1[s]
        vp = (seg_x1[s] - seg_x0[s]) / (t_end - seg_t0[s])
        in_window = seg_window[s] != 0
        dt_fine = seg_fine[s]
        dt_coarse = seg_coarse[s]
        dt_quasi = seg_quasi[s]
        adaptive = (not rigid) and dt_coarse > dt_fine
        if resume:
            resume = False
            fine = carry[C_FINE] != 0.0
            quasi = carry[C_QUASI] != 0.0
            quiet = int(carry[C_QUIET])
            acc_xr = carry[C_ACC_XR]
            acc_f = carry[C_ACC_F]
            acc_win = carry[C_ACC_WIN]
            acc_in = carry[C_ACC_IN]
            acc_damp = carry[C_ACC_DAMP]
            acc_contact = carry[C_ACC_CONTACT]
            acc_t = carry[C_ACC_T]
            min_xr = carry[C_MIN_XR]
        else:
            if seg_mark[s]:
                track = k
                per[k, PER_MARK_XR] = x_r
                per[k, PER_MIN_XR] = x_r
            if in_window and track >= 0 and k > track:
                track = -1
            fine = True
            quasi = False
            quiet = 0
            # segment-local accumulators (kept in registers, written back after the segment)
            acc_xr = 0.0
            acc_f = 0.0
            acc_win = 0.0
            acc_in = 0.0
            acc_damp = 0.0
            acc_contact = 0.0
            acc_t = 0.0
            min_xr = per[track, PER_MIN_XR] if track >= 0 else 0.0
        done = False
        while not done:
            if steps >= step_limit:
                # pause: everything the loop carries goes to carry, y and work
                carry[C_SEGMENT] = s
                carry[C_MID] = 1.0
                carry[C_TIME] = t
                carry[C_XP] = x_p
                carry[C_AR] = a_r
                carry[C_FORCE] = F
                carry[C_NEXT_RECORD] = next_rec
                carry[C_TRACK] = track
                carry[C_RECORDED] = n_rec
                carry[C_STEPS] = steps
                carry[C_FINE_STEPS] = fine_steps
                carry[C_FINE] = 1.0 if fine else 0.0
                carry[C_QUASI] = 1.0 if quasi else 0.0
                carry[C_QUIET] = quiet
                carry[C_ACC_XR] = acc_xr
                carry[C_ACC_F] = acc_f
                carry[C_ACC_WIN] = acc_win
                carry[C_ACC_IN] = acc_in
                carry[C_ACC_DAMP] = acc_damp
                carry[C_ACC_CONTACT] = acc_contact
                carry[C_ACC_T] = acc_t
                carry[C_MIN_XR] = min_xr
                y[0] = x_r
                y[1] = v_r
                for g in range(G):
                    y[2 + g] = x_a[g]
                    y[2 + G + g] = v_a[g]
                return STATUS_PAUSED, steps, n_rec, fine_steps
            if fine:
                dt = dt_fine
            elif quasi:
                dt = dt_quasi
            else:
                dt = dt_coarse
            remaining = t_end - t
            if remaining <= dt * 1.000001:
                dt = remaining
                t_new = t_end
                xp_new = seg_x1[s]
                done = True
            else:
                t_new = t + dt
                xp_new = seg_x0[s] + vp * (t_new - seg_t0[s])
            if fine:
                fine_steps += 1
            half_dt2 = 0.5 * dt * dt
            xr_old = x_r
            F_old = F
            # drift
            x_r += dt * v_r + half_dt2 * a_r
            if rigid:
                for g in range(G):
                    x_a[g] = xp_new
            elif quasi:
                c_dt = actuator_viscosity / dt
                K = actuator_stiffness + c_dt
                for g in range(G):
                    stretch_old[g] = x_p - x_a[g]
                    xa_old[g] = x_a[g]
                    center = (actuator_stiffness * xp_new + c_dt * x_a[g]) / K
                    # Newton predictor from the last solution: T moves by k_t Δu, k_t = slope − K
                    sg = max(slope[g], K)
                    guess = x_a[g] + (K * (center - x_a[g]) - T[g] - (sg - K) * (xr_old - x_r)) / sg
                    x_a[g], slope[g] = quasi_static_position(
                        params, state, g, x_r, center, K, sliding[g], guess, sg,
                        QUASI_TOLERANCE * sliding[g] / K,
                    )
            else:
                for g in range(G):
                    stretch_old[g] = x_p - x_a[g]
                    x_a[g] += dt * v_a[g] + half_dt2 * (a_nd[g] - gam * v_a[g])
            # contact forces, memory committed once per step
            F = 0.0
            for g in range(G):
                u = x_a[g] - x_r
                Tn = contact_update_row(params, state, g, u)
                w = multiplicity[g] * 0.5 * (T[g] + Tn)
                acc_contact += w * (u - u_old[g])
                if rigid:
                    acc_in += w * (xp_new - x_p)
                T[g] = Tn
                u_old[g] = u
                F += multiplicity[g] * Tn
                if track >= 0:
                    ratio = abs(Tn) / sliding[g]
                    if ratio > peak[track, g]:
                        peak[track, g] = ratio
            # kick
            a_r_new = (F - load_stiffness * x_r) * inv_mr
            v_r += 0.5 * dt * (a_r + a_r_new)
            a_r = a_r_new
            if quasi:
                activity = 0.0
                for g in range(G):
                    v_old = v_a[g]
                    v_a[g] = (x_a[g] - xa_old[g]) / dt
                    a_nd[g] = (actuator_stiffness * (xp_new - x_a[g]) - T[g]) * inv_ma
                    # backward Euler: c_p v_a (x_a − x_a,old) = c_p v_a² dt (halved below)
                    acc_damp += multiplicity[g] * 2.0 * v_a[g] * v_a[g] * dt
                    acc_in += multiplicity[g] * (stretch_old[g] + xp_new - x_a[g]) * (xp_new - x_p)
                    acc = abs(v_a[g] - v_old) / dt
                    if acc > activity:
                        activity = acc
                if activity >= activity_threshold:
                    fine = True
                    quasi = False
                    quiet = 0
            elif not rigid:
                damp = 1.0 / (1.0 + 0.5 * dt * gam)
                activity = 0.0
                for g in range(G):
                    a_new = (actuator_stiffness * (xp_new - x_a[g]) - T[g]) * inv_ma
                    v_old = v_a[g]
                    v_a[g] = (v_old + 0.5 * dt * (a_nd[g] - gam * v_old + a_new)) * damp
                    a_nd[g] = a_new
                    acc_damp += multiplicity[g] * (v_old * v_old + v_a[g] * v_a[g]) * dt
                    # work of the moving piezo base: k_p (x_p − x_a) dx_p, trapezoidal in (x_p − x_a)
                    acc_in += multiplicity[g] * (stretch_old[g] + xp_new - x_a[g]) * (xp_new - x_p)
                    acc = abs(a_new - gam * v_a[g])
                    if acc > activity:
                        activity = acc
                if adaptive:
                    if fine:
                        if activity < activity_threshold:
                            quiet += 1
                            if quiet >= quiet_steps:
                                fine = False
                                quasi = quasi_static
                        else:
                            quiet = 0
                    elif activity >= activity_threshold:
                        fine = True
                        quiet = 0
            # per-period measures
            acc_xr += (xr_old + x_r) * dt
            acc_f += (F_old + F) * dt
            acc_t += dt
            if in_window:
                acc_win += ((xr_old - x_p) + (x_r - xp_new)) * dt
            if x_r < min_xr:
                min_xr = x_r
            t = t_new
            x_p = xp_new
            steps += 1
            # divergence (also catches NaN: comparisons with NaN are False)
            ok = abs(x_r) < position_limit and abs(v_r) < velocity_limit
            if not rigid:
                for g in range(G):
                    ok = ok and abs(x_a[g] - x_p) < position_limit and abs(v_a[g]) < velocity_limit
            if not ok:
                y[0] = x_r
                y[1] = v_r
                return STATUS_DIVERGED, steps, n_rec, fine_steps
            if t >= next_rec and n_rec < max_rec:
                record[n_rec, 0] = t
                record[n_rec, 1] = x_p
                record[n_rec, 2] = x_r
                record[n_rec, 3] = v_r
                for g in range(G):
                    record[n_rec, 4 + 3 * g] = x_a[g]
                    record[n_rec, 5 + 3 * g] = T[g]
                    record[n_rec, 6 + 3 * g] = contact_slip_share_row(params, state, g, x_a[g] - x_r)
                n_rec += 1
                while next_rec <= t:
                    next_rec += record_interval
        per[k, PER_XR_INTEGRAL] += 0.5 * acc_xr
        per[k, PER_FRICTION_INTEGRAL] += 0.5 * acc_f
        per[k, PER_DURATION] += acc_t
        if in_window:
            per[k, PER_WINDOW_INTEGRAL] += 0.5 * acc_win
            per[k, PER_WINDOW_LENGTH] += acc_t
            per[k, PER_WINDOW_END_XP] = seg_x1[s]
        if track >= 0:
            per[track, PER_MIN_XR] = min_xr
        energy[EN_CONTACT] += acc_contact
        if rigid:
            energy[EN_INPUT] += acc_in
        else:
            energy[EN_INPUT] += actuator_stiffness * 0.5 * acc_in
            energy[EN_DAMPING] += actuator_viscosity * 0.5 * acc_damp
    y[0] = x_r
    y[1] = v_r
    for g in range(G):
        y[2 + g] = x_a[g]
        y[2 + G + g] = v_a[g]
    return STATUS_OK, steps, n_rec, fine_steps
