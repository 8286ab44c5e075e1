"""Hybrid dynamic simulation of the drive: runner, actuators and MDR contacts (Section 3).

Macroscopic model (Eqs. 2–3), per contact group g with multiplicity n_g
(one contact: one group, n = 1; six contacts: side 1 with n = 2 at F_N1, side 2 with
n = 4 at F_N2, Eq. 1)::

    m_r ẍ_r = −k x_r + Σ_g n_g T_g(u_g),        u_g = x_a,g − x_r
    m_a ẍ_a,g = k_p (x_p − x_a,g) − c_p ẋ_a,g − T_g(u_g)      (flexible)
    x_a,g = x_p(t)                                           (rigid)

T_g is the MDR friction force of one contact of group g (Eqs. 4–6, :mod:`passmd.model.contact`)
with memory. Sign convention: u = x_a − x_r; +T acts on the runner, −T on the actuator
(the paper's Eq. 2 writes the same with F_f = T).

Integrator (see :mod:`passmd.solver.kernels`; the schemes are
:data:`passmd.solver.steps.SCHEMES`). While flexible actuators ring (after each corner of
x_p(t)): velocity Verlet with a trapezoidal damping term at a fixed number of steps per
period of the stiff mode (actuator on k_p plus the contact's 2aG*, ≈ 3 MHz), which an
explicit symplectic scheme neither damps artificially nor lets drift in energy. In the
default scheme ("controlled") everywhere else (rigid actuators throughout; flexible ones
once the ringing has decayed, with m_a neglected and the actuator's force balance solved
per step) the step is error-controlled:
the runner's linear oscillation on its contacts (≈ 11 kHz) is integrated exactly, only the
rest of the force limits the step, a step whose local error estimate exceeds
:data:`passmd.solver.steps.LOCAL_ERROR_TOLERANCE` is rejected and retried shorter, and a
reversal of a contact's displacement inside a step is committed at its interpolated
extremum. Every corner of x_p(t) falls on a step boundary, and the contact memory is
committed once per accepted step. The other schemes ("adaptive", "quasi-static", "fixed")
step explicitly; the convergence studies compare them.
"""

from __future__ import annotations

import sys
import time as _time
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from passmd.model.contact import (
    contact_stiffness,
    drive_contact_arrays,
    memory_diagnostics,
    sliding_force,
    stack_contacts,
)
from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import Drive
from passmd.model.theory import contact_layout
from passmd.model.waveforms import Waveform
from passmd.runtime.validation import check_choice, check_count
from passmd.solver import kernels as kern
from passmd.solver.steps import (
    DEFAULT_SCHEME,
    LOCAL_ERROR_TOLERANCE,
    Scheme,
    StepPlan,
    check_work,
    resolve_scheme,
    segments,
    step_plan,
)

#: Verlet is stable for ω dt < 2; a given step (:attr:`passmd.solver.steps.Scheme.dt`) must keep
#: this margin below it.
STABILITY_MARGIN = 0.9
#: Work per kernel call, in steps of the exact contact (:data:`SPRINGS_PER_STEP` springs of a
#: discrete contact count as one more): the kernel returns to Python between calls, so Ctrl-C
#: and SIGTERM are honoured within one call (≈ 0.02–0.4 s) and the progress bar advances.
#: Results do not depend on it (the kernel resumes exactly).
CHUNK_STEPS = 500_000
#: Springs of a discrete MDR contact that cost about as much per step as the rest of a step
#: (measured: ≈ 5 ns per spring and step against ≈ 0.4 µs per step of the exact contact).
SPRINGS_PER_STEP = 100
#: Runs expected to take more work than this (steps of the exact contact, ≈ 1 s) may show their
#: progress on stderr (:mod:`passmd.runtime.progress`: nothing for runs ending within 2 s).
PROGRESS_MIN_WORK = 2e6


class SimulationError(RuntimeError):
    """A simulation diverged or could not be carried out."""


def contact_groups(drive: Drive, share_side_state: bool = True):
    """Normal force and multiplicity of each contact group (Eq. 1; any arrangement,
    :func:`passmd.model.theory.contact_layout`).

    With ``share_side_state=False`` every contact is a group of one, so that results do not
    rely on the by-symmetry sharing of one state per group.
    """
    forces, multiplicity, _ = contact_layout(drive)
    if share_side_state:
        return forces, multiplicity
    return np.repeat(forces, multiplicity.astype(int)), np.ones(int(multiplicity.sum()))


@dataclass
class SimulationResult:
    """Time series (down-sampled) and per-period measures of one simulation, SI units.

    Attributes
    ----------
    time, piezo_position, runner_position, runner_velocity : ndarray
        Recorded samples (s, m, m, m/s).
    actuator_position, friction_force, slip_share : ndarray, shape (groups, samples)
        Hemisphere position (m), friction force of one contact (N, on the runner) and the
        fraction of its MDR springs slipping, per contact group.
    multiplicity : ndarray
        Contacts per group.
    settled_positions : ndarray, shape (periods,)
        Runner position at the end of each stick phase, vibration averaged out over the
        settle window (see :mod:`passmd.model.waveforms`).
    back_steps : ndarray, shape (periods,)
        Largest backward excursion of the runner after each slip edge, ≥ 0.
    peak_force_ratio : ndarray, shape (periods, groups)
        Largest |T|/μF_N of one contact of each group from the period's slip edge to the
        next settle window; exactly 1 when that group slid fully (every integrator step
        is inspected, not only the recorded samples).
    period_mean_position, period_mean_friction : ndarray, shape (periods,)
        Means over each period of x_r and of the total friction force on the runner.
    energy : dict
        Work and energy terms of the balance (J); see :meth:`energy_balance`.
    """

    drive: Drive
    waveform: Waveform
    contact_model: str
    time: np.ndarray
    piezo_position: np.ndarray
    runner_position: np.ndarray
    runner_velocity: np.ndarray
    actuator_position: np.ndarray
    friction_force: np.ndarray
    slip_share: np.ndarray
    multiplicity: np.ndarray
    settled_positions: np.ndarray
    back_steps: np.ndarray
    peak_force_ratio: np.ndarray
    period_mean_position: np.ndarray
    period_mean_friction: np.ndarray
    energy: dict
    steps: int  # integrator steps, rejected error-controlled steps included
    fine_steps: int
    fine_step: float
    coarse_step: float
    wall_time: float
    contact_memory: list = field(repr=False)  # per group: reversals, deepest stack, overflows
    final_state: np.ndarray = field(repr=False)
    rejected_steps: int = 0  # error-controlled steps rejected and retried shorter

    @property
    def step_sizes(self) -> np.ndarray:
        """Net runner step across each slip edge: settled position of period k+1 minus k (m)."""
        return np.diff(self.settled_positions)

    @property
    def final_position(self) -> float:
        """Settled runner position in the last period (m); with a saw-tooth it includes the ramp."""
        return float(self.settled_positions[-1])

    @property
    def mean_velocity(self) -> float:
        """Mean runner velocity from the settled positions of the first and last period (m/s)."""
        n = self.settled_positions.size
        if n < 2:
            raise ValueError("mean_velocity needs a run of at least 2 periods")
        return float(
            (self.settled_positions[-1] - self.settled_positions[0]) / ((n - 1) * self.waveform.period)
        )

    @property
    def generated_force(self) -> float:
        """Force on the load cell k·x̄_r, x̄_r the runner's mean position over the last period (N)."""
        return float(self.drive.effective_load_cell_stiffness * self.period_mean_position[-1])

    def energy_balance(self) -> dict:
        """Terms of the energy balance W_in = E_kin + E_el + W_contact + W_damp (J).

        ``residual`` is W_in minus the right-hand side; ``relative_residual`` divides it by
        the largest term. W_contact = Σ ∫T du is what the contacts stored plus dissipated.
        """
        y = self.final_state
        G = self.multiplicity.size
        d = self.drive
        x_r, v_r, x_a, v_a = y[0], y[1], y[2 : 2 + G], y[2 + G :]
        x_p = float(self.waveform.positions[-1])
        kinetic = 0.5 * d.runner_mass * v_r**2
        elastic = 0.5 * d.effective_load_cell_stiffness * x_r**2
        if d.actuator_model == "flexible":
            kinetic += float(np.sum(self.multiplicity * 0.5 * d.actuator.mass * v_a**2))
            elastic += float(np.sum(self.multiplicity * 0.5 * d.actuator.stiffness * (x_p - x_a) ** 2))
        terms = {
            "input_work": self.energy["input"],
            "kinetic": kinetic,
            "elastic": elastic,
            "contact_work": self.energy["contact"],
            "damping": self.energy["damping"],
        }
        rhs = kinetic + elastic + terms["contact_work"] + terms["damping"]
        terms["residual"] = terms["input_work"] - rhs
        scale = max(abs(v) for v in terms.values())
        terms["relative_residual"] = terms["residual"] / scale if scale > 0 else 0.0
        return terms

    def summary(self) -> dict:
        """Measures in SI units, keys carrying the unit (JSON-ready)."""
        out = {
            "final_position_m": self.final_position,
            "settled_positions_m": self.settled_positions.tolist(),
            "step_sizes_m": self.step_sizes.tolist(),
            "back_steps_m": self.back_steps.tolist(),
            "periods": int(self.waveform.periods),
            "frequency_Hz": float(self.waveform.frequency),
            "amplitude_m": float(self.waveform.amplitude),
            "integrator_steps": int(self.steps),
            "fine_steps": int(self.fine_steps),
            "contact_memory_overflows": int(sum(m["overflows"] for m in self.contact_memory)),
            "fine_time_step_s": float(self.fine_step),
            "coarse_time_step_s": float(self.coarse_step),
        }
        if self.settled_positions.size >= 2:
            out["mean_velocity_m_per_s"] = self.mean_velocity
        if self.drive.load_cell:
            out["generated_force_N"] = self.generated_force
        return out

    def to_frame(self):
        """Recorded time series as a pandas DataFrame (SI units, one column per group quantity)."""
        import pandas as pd

        data = {
            "time_s": self.time,
            "piezo_position_m": self.piezo_position,
            "runner_position_m": self.runner_position,
            "runner_velocity_m_per_s": self.runner_velocity,
        }
        for g in range(self.multiplicity.size):
            data[f"actuator_position_{g}_m"] = self.actuator_position[g]
            data[f"friction_force_{g}_N"] = self.friction_force[g]
            data[f"slip_share_{g}"] = self.slip_share[g]
        return pd.DataFrame(data)


def _progress_bar(work: float, waveform: Waveform, progress: bool | str | None):
    """Progress over simulated periods on stderr (:func:`passmd.runtime.progress.bar`), or None.

    ``work``: the run's expected work in steps of the exact contact. None: runs of more than
    :data:`PROGRESS_MIN_WORK` when stderr is a terminal; ``"long"``: those runs whatever stderr
    is (off a terminal, a line every few seconds); True: every run at once; False: none.
    """
    from passmd.runtime import progress as _progress

    if progress is False or sys.stderr is None:
        return None
    if progress is not True:
        if work < PROGRESS_MIN_WORK or _progress.in_worker():
            return None
        if progress is None and not _progress.is_terminal(sys.stderr):
            return None
    return _progress.bar(waveform.periods, unit="period", desc="simulation", fractional=True,
                         delay=0.0 if progress is True else None)


def simulate(drive: Drive, waveform: Waveform, **options) -> SimulationResult:
    """Simulate the drive under a piezo waveform from rest with virgin contacts.

    A :class:`Simulation` run through all periods at once: ``options`` are its keyword
    arguments (``contact_model``, ``springs``, ``scheme``, ``max_points``,
    ``share_side_state``, ``progress``; documented there), e.g.
    ``simulate(drive, waveform, scheme="fixed")``.

    Raises
    ------
    ValueError
        Bad input, or a scheme's ``dt`` the integrator cannot resolve.
    passmd.solver.steps.WorkLimitError
        (a ValueError) The step falls below the float resolution of the simulated time, or
        the run would need more than :data:`passmd.solver.steps.MAX_STEPS` steps.
    SimulationError
        The integration diverged (non-finite or runaway state).
    """
    run = Simulation(drive, waveform, **options)
    run.run_to(waveform.periods)
    return run.result()


class Simulation:
    """The drive under a piezo waveform from rest with virgin contacts, integrated period by period.

    :meth:`run_to` integrates up to the end of a given period, :meth:`result` returns the
    measures of the periods integrated so far. Running the first n periods of ``waveform``
    and stopping is the same floating-point computation as :func:`simulate` on those n
    periods alone (:meth:`leading_periods`) whenever the step pieces of the n-period
    waveform are the first pieces of the longer one (true of :func:`passmd.model.waveforms.sawtooth`,
    whose breakpoints of period k do not depend on the number of periods): the result is
    then that run's, but for the recorded samples, which are spaced over the whole
    ``waveform``. So a protocol that decides after n periods whether it needs more continues
    the run instead of repeating it from rest.

    Parameters
    ----------
    drive : Drive
        Drive configuration (contacts, rigid/flexible actuators, load cell, materials).
    waveform : Waveform
        Desired piezo position x_p(t) (:mod:`passmd.model.waveforms`).
    contact_model : {"exact", "discrete"}
        Exact continuum MDR contact (default) or ``springs`` discrete MDR springs.
    springs : int
        Number of MDR springs for the discrete model.
    scheme : {"controlled", "adaptive", "quasi-static", "fixed"} or Scheme
        Integration scheme (:data:`passmd.solver.steps.SCHEMES`). "controlled" (default):
        error-controlled steps for rigid actuators, and for flexible ones once their ringing
        after a corner of x_p(t) has decayed (quasi-static actuator); "adaptive": explicit
        Verlet, fine while flexible actuators ring and coarse after; "quasi-static": the
        quasi-static actuator at a fixed runner step after the ringing; "fixed": the fine step
        throughout. A :class:`passmd.solver.steps.Scheme` refines one
        (``SCHEMES["fixed"].replace(refine=2.0)``) or fixes the step
        (``SCHEMES["fixed"].replace(dt=1e-9)``, below the Verlet stability limit of the
        stiffest mode).
    max_points : int
        Number of recorded samples (evenly spaced in time).
    share_side_state : bool
        Six contacts: one state per side (default) or six independent contacts.
    progress : bool or "long", optional
        Progress on stderr (:mod:`passmd.runtime.progress`). Default: for runs of more than
        :data:`PROGRESS_MIN_WORK` (expected steps, a discrete contact's springs counted,
        :data:`SPRINGS_PER_STEP`) when stderr is a terminal, shown once the run has lasted
        2 s; ``"long"``: the same whatever stderr is (off a terminal, a line every few
        seconds: the command line); True: at once, for any run; False: never.

    The kernel runs in chunks of :data:`CHUNK_STEPS` steps (fewer with many springs) and
    returns to Python between them, so a KeyboardInterrupt stops the run within one chunk;
    results are identical to an uninterrupted run. The run is refused
    (:func:`passmd.solver.steps.check_work`) period count by period count, as :func:`simulate`
    would refuse the shorter waveform.
    """

    def __init__(
        self,
        drive: Drive,
        waveform: Waveform,
        *,
        contact_model: str = "exact",
        springs: int = PROTOCOL.springs,
        scheme: str | Scheme = DEFAULT_SCHEME,
        max_points: int = 20000,
        share_side_state: bool = True,
        progress: bool | None = None,
    ):
        if not isinstance(drive, Drive):
            raise ValueError(f"drive = {drive!r} is not a Drive")
        if not isinstance(waveform, Waveform):
            raise ValueError(f"waveform = {waveform!r} is not a Waveform")
        check_choice("contact_model", contact_model, ("exact", "discrete"))
        scheme = resolve_scheme(scheme)
        if int(max_points) != max_points or max_points < 2:
            raise ValueError(f"max_points = {max_points!r} is out of range: must be an integer >= 2")
        if not (progress is None or isinstance(progress, bool) or (isinstance(progress, str)
                                                                  and progress == "long")):
            raise ValueError(f"progress = {progress!r} is not allowed: must be True, False, None or 'long'")

        params, state, multiplicity = _contact_rows(drive, contact_model, springs, share_side_state)
        k_contacts = np.array([contact_stiffness(params[g]) for g in range(multiplicity.size)])
        self._total_stiffness = float(np.sum(multiplicity * k_contacts))
        self._plan = plan = step_plan(drive, float(k_contacts.max()), self._total_stiffness, scheme.refine)
        steps = _steps(drive, plan, scheme)
        self._fine_step, self._coarse_step = steps.fine, steps.quiet
        self._user_step = scheme.dt is not None
        self.drive, self.waveform, self.contact_model = drive, waveform, contact_model
        self._multiplicity, self._params, self._state = multiplicity, params, state
        self._progress = progress
        G = multiplicity.size
        # work of one step in steps of the exact contact: every spring of a discrete contact counts
        self._step_work = 1.0 + (G * springs / SPRINGS_PER_STEP if contact_model == "discrete" else 0.0)
        self._buffers = kern.Buffers(
            y=np.zeros(2 + 2 * G),
            work=np.zeros((kern.WORK_ROWS, G)),
            carry=np.zeros(kern.CARRY_SIZE),
            record=np.empty((int(max_points), 4 + 3 * G)),
            per=np.zeros((waveform.periods, kern.PER_COLUMNS)),
            peak=np.zeros((waveform.periods, G)),
            energy=np.zeros(kern.EN_COLUMNS),
        )
        self._segments = segments(waveform, steps.fine, steps.coarse, steps.quiet, steps.longest)
        # pieces of the first n periods: the first _ends[n − 1] (a piece's period never decreases)
        self._ends = np.searchsorted(self._segments.period, np.arange(1, waveform.periods + 1), side="left")
        self._mechanics = kern.Mechanics(
            drive.runner_mass,
            drive.effective_load_cell_stiffness,
            multiplicity.astype(float),
            drive.actuator_model == "rigid",
            drive.actuator.mass,
            drive.actuator.stiffness,
            drive.actuator.viscosity,
            _linear_stiffness(drive, multiplicity, k_contacts) if steps.controlled else 0.0,
        )
        self._control = kern.StepControl(
            plan.activity_threshold, plan.quiet_steps, steps.quasi_static,
            waveform.duration / (max_points - 1),
            LOCAL_ERROR_TOLERANCE / scheme.refine**4 if steps.controlled else 0.0,
        )
        self._contacts = kern.Contacts(params, state, np.array([sliding_force(params[g]) for g in range(G)]))
        self.periods_done = 0
        self.wall_time = 0.0
        self._counts = (0, 0, 0)  # integrator steps, rows recorded, fine steps
        self._failed = False

    def leading_periods(self, periods: int) -> Waveform:
        """The waveform cut after its first ``periods`` periods (the whole one for all of them)."""
        periods = check_count("periods", periods)
        if periods > self.waveform.periods:
            raise ValueError(f"periods = {periods!r} is out of range: the waveform has "
                             f"{self.waveform.periods} periods")
        w = self.waveform
        if periods == w.periods:
            return w
        end = int(self._ends[periods - 1])
        return Waveform(w.times[: end + 1], w.positions[: end + 1], w.period, periods,
                        w.settle_windows[:periods], w.slip_marks[:periods], w.kind, w.amplitude)

    def run_to(self, periods: int) -> None:
        """Integrate up to the end of period ``periods`` (counted from 1; no-op if already there).

        Raises
        ------
        ValueError
            ``periods`` beyond the waveform's, or a simulation that already failed.
        passmd.solver.steps.WorkLimitError
            The first ``periods`` periods are a run :func:`simulate` would refuse.
        SimulationError
            The integration diverged (the simulation cannot go on).
        """
        if self._failed:
            raise SimulationError("the simulation diverged earlier and cannot go on")
        leading = self.leading_periods(periods)
        if leading.periods <= self.periods_done:
            return
        expected = check_work(
            self.drive, leading, self._plan, self._fine_step, self._coarse_step, self._total_stiffness,
            user_step=self._user_step,
        )
        n, end = leading.periods, int(self._ends[leading.periods - 1])
        b = self._buffers
        arguments = (
            kern.Segments(*(column[:end] for column in self._segments)),
            self._mechanics,
            self._control,
            self._contacts,
            b._replace(per=b.per[:n], peak=b.peak[:n]),
        )
        start = _time.perf_counter()
        try:
            status, steps, n_rec, fine_steps = _integrate_in_chunks(
                arguments, leading, expected, self._step_work, self._progress
            )
        finally:
            self.wall_time += _time.perf_counter() - start
        if status != kern.STATUS_OK:
            self._failed = True
            y, plan = b.y, self._plan
            raise SimulationError(
                f"simulation diverged at integrator step {steps}: "
                f"runner position {y[0]!r} m, velocity {y[1]!r} m/s. Likely cause: a time step too large for "
                f"the stiffest mode ({plan.stiffest_frequency:.3g} Hz, stable below "
                f"{plan.stability_limit:.3g} s; "
                f"steps used {self._fine_step:.3g} s to {self._coarse_step:.3g} s) or non-physical "
                "parameters."
            )
        self._counts = (steps, n_rec, fine_steps)
        self.periods_done = n

    def result(self) -> SimulationResult:
        """Measures of the periods integrated so far; ``waveform`` is :meth:`leading_periods` of them.

        The arrays are copies: running on does not change a result already returned.
        """
        if self.periods_done < 1:
            raise ValueError("result() needs at least one integrated period: call run_to first")
        steps, n_rec, fine_steps = self._counts
        G = self._multiplicity.size
        return SimulationResult(
            drive=self.drive,
            waveform=self.leading_periods(self.periods_done),
            contact_model=self.contact_model,
            multiplicity=self._multiplicity,
            **_measures(self._buffers, self.periods_done, n_rec),
            steps=int(steps),
            fine_steps=int(fine_steps),
            fine_step=float(self._fine_step),
            coarse_step=float(self._coarse_step),
            wall_time=self.wall_time,
            contact_memory=[memory_diagnostics(self._params[g], self._state[g]) for g in range(G)],
            rejected_steps=int(self._buffers.carry[kern.C_REJECTED]),
        )


def _contact_rows(drive: Drive, contact_model: str, springs: int, share_side_state: bool):
    """Contact parameters and state of every group (:func:`passmd.model.contact.stack_contacts`) and
    the groups' multiplicities (:func:`contact_groups`)."""
    forces, multiplicity = contact_groups(drive, share_side_state)
    _, counts, radii = contact_layout(drive)
    if not share_side_state:
        radii = np.repeat(radii, counts.astype(int))
    discrete = springs if contact_model == "discrete" else None
    rows = [drive_contact_arrays(drive, F, R, discrete) for F, R in zip(forces, radii, strict=True)]
    params, state = stack_contacts(rows)
    return params, state, multiplicity


def _linear_stiffness(drive: Drive, multiplicity: np.ndarray, k_contacts: np.ndarray) -> float:
    """Σ n_g k_g: the contacts' initial tangent stiffness, in series with k_p for flexible actuators
    (N/m); the part of the runner's force the error-controlled step integrates exactly."""
    if drive.actuator_model == "flexible":
        k_p = drive.actuator.stiffness
        k_contacts = k_p * k_contacts / (k_p + k_contacts)
    return float(np.sum(multiplicity * k_contacts))


class Steps(NamedTuple):
    """The steps a scheme takes on one drive (s), from :func:`_steps`."""

    fine: float  # while flexible actuators ring; rigid actuators without error control throughout
    coarse: float  # explicit step once flexible actuators stop ringing (= fine when it does not grow)
    quasi_static: bool  # flexible actuators turn quasi-static once their ringing has decayed
    quiet: float  # step once the ringing has decayed: the quasi-static (first controlled) or coarse one
    controlled: bool  # error-controlled steps (rigid actuators; flexible ones while quasi-static)
    longest: float | None  # longest error-controlled step (None without error control)


def _steps(drive: Drive, plan: StepPlan, scheme: Scheme) -> Steps:
    """The steps of ``scheme`` on ``drive`` under ``plan``.

    A scheme's ``dt`` replaces the fine step and must keep :data:`STABILITY_MARGIN` below the
    Verlet stability limit of the stiffest mode.
    """
    fine = coarse = plan.fine_step
    if scheme.dt is not None:
        limit = STABILITY_MARGIN * plan.stability_limit
        if scheme.dt > limit:
            raise ValueError(
                f"dt = {scheme.dt!r} is out of range: the stiffest mode "
                f"({plan.stiffest_frequency / 1e6:.3g} MHz) needs dt < {limit:.3g} s for the explicit "
                "integrator to stay stable"
            )
        fine = coarse = scheme.dt
    elif scheme.quiet_step != "fine":
        coarse = plan.coarse_step
    quasi_static = scheme.quiet_step == "quasi-static" and drive.actuator_model == "flexible"
    quiet = plan.quasi_step if quasi_static else coarse
    controlled = scheme.error_control
    return Steps(fine, coarse, quasi_static, quiet, controlled, plan.longest_step if controlled else None)


def _integrate_in_chunks(arguments: tuple, waveform: Waveform, expected: float, step_work: float,
                         progress: bool | str | None):
    """Run the kernel in chunks of :data:`CHUNK_STEPS` work (Ctrl-C is honoured between chunks).

    ``expected`` steps of ``step_work`` each (:data:`SPRINGS_PER_STEP`). Returns the kernel's
    (status, steps, rows recorded, fine steps) of the last call.
    """
    carry = arguments[-1].carry
    bar = _progress_bar(expected * step_work, waveform, progress)
    chunk = max(1, int(CHUNK_STEPS / step_work))
    try:
        limit = chunk
        while True:
            status, steps, n_rec, fine_steps = kern.integrate(*arguments, limit)
            if status != kern.STATUS_PAUSED:
                return status, steps, n_rec, fine_steps
            limit = steps + chunk
            if bar is not None:
                bar.update(min(carry[kern.C_TIME] / waveform.period, waveform.periods) - bar.n)
    finally:
        if bar is not None:
            bar.close()


def _measures(buffers: kern.Buffers, periods: int, n_rec: int) -> dict:
    """The recorded series, measures of the first ``periods`` periods, energies and state of a
    run stopped after them (fields of :class:`SimulationResult`)."""
    per, energy = buffers.per[:periods], buffers.energy
    rec = buffers.record[:n_rec]
    window_len = per[:, kern.PER_WINDOW_LENGTH]
    if np.any(window_len <= 0):
        raise SimulationError(
            "a period has an empty settle window; the waveform's phase marks are inconsistent"
        )
    settled = per[:, kern.PER_WINDOW_INTEGRAL] / window_len + per[:, kern.PER_WINDOW_END_XP]
    duration = per[:, kern.PER_DURATION]
    return dict(
        time=rec[:, 0].copy(),
        piezo_position=rec[:, 1].copy(),
        runner_position=rec[:, 2].copy(),
        runner_velocity=rec[:, 3].copy(),
        actuator_position=rec[:, 4::3].T.copy(),
        friction_force=rec[:, 5::3].T.copy(),
        slip_share=rec[:, 6::3].T.copy(),
        settled_positions=settled,
        back_steps=per[:, kern.PER_MARK_XR] - per[:, kern.PER_MIN_XR],
        peak_force_ratio=buffers.peak[:periods].copy(),
        period_mean_position=per[:, kern.PER_XR_INTEGRAL] / duration,
        period_mean_friction=per[:, kern.PER_FRICTION_INTEGRAL] / duration,
        energy={
            "input": float(energy[kern.EN_INPUT]),
            "damping": float(energy[kern.EN_DAMPING]),
            "contact": float(energy[kern.EN_CONTACT]),
        },
        final_state=buffers.y.copy(),
    )
