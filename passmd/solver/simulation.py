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

import math
import sys
import time as _time

import numpy as np

from passmd.model.contact import memory_diagnostics
from passmd.model.contact_kernels import P_SLIDING, P_STIFFNESS
from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import Drive
from passmd.model.waveforms import Waveform
from passmd.runtime.validation import check_choice, check_count
from passmd.solver import kernels
from passmd.solver.periodicity import BoundaryState
from passmd.solver.results import SimulationError, SimulationResult, measures, settled_positions
from passmd.solver.setup import contact_rows, linear_stiffness, scheme_steps
from passmd.solver.steps import (
    DEFAULT_SCHEME,
    LOCAL_ERROR_TOLERANCE,
    Scheme,
    check_work,
    piece_work,
    refused,
    resolve_scheme,
    segments,
    step_plan,
)

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


def _progress_bar(work: float, periods: int, show: bool | str | None):
    """Progress over simulated periods on stderr (:func:`passmd.runtime.progress.bar`), or None.

    ``work``: the run's expected work in steps of the exact contact. ``show`` None: runs of more than
    :data:`PROGRESS_MIN_WORK` when stderr is a terminal; ``"long"``: those runs whatever stderr
    is (off a terminal, a line every few seconds); True: every run at once; False: none.
    """
    from passmd.runtime import progress

    if show is False or sys.stderr is None:
        return None
    if show is not True:
        if work < PROGRESS_MIN_WORK or progress.in_worker():
            return None
        if show is None and not progress.is_terminal(sys.stderr):
            return None
    return progress.bar(periods, unit="period", desc="simulation", fractional=True,
                        delay=0.0 if show is True else None)


def simulate(drive: Drive, waveform: Waveform, **options) -> SimulationResult:
    """Simulate the drive under a piezo waveform from rest with virgin contacts.

    A :class:`Simulation` run through all periods at once: ``options`` are its keyword
    arguments (``contact_model``, ``springs``, ``scheme``, ``max_points``,
    ``share_side_state``, ``energy``, ``progress``; documented there), e.g.
    ``simulate(drive, waveform, scheme="fixed")``.

    Raises
    ------
    ValueError
        Bad input, or a scheme's ``dt`` the integrator cannot resolve.
    passmd.solver.steps.WorkLimitError
        (a ValueError) The step falls below the float resolution of the simulated time, or
        the run would need more than :data:`passmd.solver.steps.MAX_STEPS` steps.
    passmd.solver.results.SimulationError
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
    scheme : {"controlled", "reference", "adaptive", "quasi-static", "fixed"} or Scheme
        Integration scheme (:data:`passmd.solver.steps.SCHEMES`). "controlled" (default):
        error-controlled steps for rigid actuators, and for flexible ones once their ringing
        after a corner of x_p(t) has decayed (quasi-static actuator); "reference": the same
        error control with bracketed balance solves and a fresh start at every breakpoint of
        x_p(t) (the integrator the default is tested against); "adaptive": explicit
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
    energy : bool
        Accumulate the terms of the energy balance (``SimulationResult.energy``,
        :meth:`~passmd.solver.results.SimulationResult.energy_balance`). Off by default: they never
        feed back into the motion, and their quadrature costs about a fifth of an error-controlled
        run.
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
        energy: bool = False,
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
        if not isinstance(energy, bool):
            raise ValueError(f"energy = {energy!r} is not allowed: must be True or False")
        if not (progress is None or isinstance(progress, bool) or (isinstance(progress, str)
                                                                  and progress == "long")):
            raise ValueError(f"progress = {progress!r} is not allowed: must be True, False, None or 'long'")

        params, state, multiplicity = contact_rows(drive, contact_model, springs, share_side_state)
        k_contacts = params[:, P_STIFFNESS].copy()  # (contact_stiffness of each row)
        self._total_stiffness = float(np.sum(multiplicity * k_contacts))
        self._plan = plan = step_plan(drive, float(k_contacts.max()), self._total_stiffness, scheme.refine)
        steps = scheme_steps(drive, plan, scheme)
        self._fine_step, self._coarse_step = steps.fine, steps.quiet
        self._user_step = scheme.dt is not None
        self.drive, self.waveform, self.contact_model = drive, waveform, contact_model
        self._multiplicity, self._params, self._state = multiplicity, params, state
        self._progress = progress
        G = multiplicity.size
        # work of one step in steps of the exact contact: every spring of a discrete contact counts
        self._step_work = 1.0 + (G * springs / SPRINGS_PER_STEP if contact_model == "discrete" else 0.0)
        self._buffers = kernels.Buffers(y=np.zeros(2 + 2 * G), work=np.zeros((kernels.WORK_ROWS, G)),
                                        carry=np.zeros(kernels.CARRY_SIZE),
                                        record=np.empty((int(max_points), 4 + 3 * G)),
                                        per=np.zeros((waveform.periods, kernels.PER_COLUMNS)),
                                        peak=np.zeros((waveform.periods, G)),
                                        energy=np.zeros(kernels.EN_COLUMNS))
        self._segments = segments(waveform, steps.fine, steps.coarse, steps.quiet, steps.longest)
        # pieces of the first n periods: the first _ends[n − 1] (a piece's period never decreases)
        self._ends = np.searchsorted(self._segments.period, np.arange(1, waveform.periods + 1), side="left")
        # what check_work decides for the first n periods, from these pieces once
        self._resolved, self._expected = piece_work(self._segments, plan, self._fine_step, self._coarse_step)
        self._mechanics = kernels.Mechanics(
            drive.runner_mass,
            drive.effective_load_cell_stiffness,
            multiplicity.astype(float),
            drive.actuator_model == "rigid",
            drive.actuator.mass,
            drive.actuator.stiffness,
            drive.actuator.viscosity,
            linear_stiffness(drive, multiplicity, k_contacts) if steps.controlled else 0.0,
        )
        self._control = kernels.StepControl(
            plan.activity_threshold, plan.quiet_steps, steps.quasi_static,
            waveform.duration / (max_points - 1),
            LOCAL_ERROR_TOLERANCE / scheme.refine**4 if steps.controlled else 0.0,
            steps.newton_balance,
            steps.smooth_breakpoints,
            energy,
        )
        self._energy = energy
        sliding = params[:, P_SLIDING].copy()  # (sliding_force of each row)
        self._contacts = kernels.Contacts(params, state, sliding)
        self.periods_done = 0
        self.wall_time = 0.0
        self._counts = (0, 0, 0)  # integrator steps, rows recorded, fine steps
        self._failed = False
        self._checked = False

    def _check_periods(self, periods) -> int:
        """``periods`` as a count of the waveform's periods (ValueError beyond them)."""
        n = check_count("periods", periods)
        if n > self.waveform.periods:
            raise ValueError(f"periods = {periods!r} is out of range: the waveform has "
                             f"{self.waveform.periods} periods")
        return n

    def leading_periods(self, periods: int) -> Waveform:
        """The waveform cut after its first ``periods`` periods (the whole one for all of them)."""
        periods = self._check_periods(periods)
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
        passmd.solver.results.SimulationError
            The integration diverged (the simulation cannot go on).
        """
        if self._failed:
            raise SimulationError("the simulation diverged earlier and cannot go on")
        n = self._check_periods(periods)
        if n <= self.periods_done:
            return
        end = int(self._ends[n - 1])
        expected = float(self._expected[end - 1])
        if refused(self._resolved, self._expected, end):  # check_work raises, naming the cause
            expected = check_work(
                self.drive, self.leading_periods(n), self._plan, self._fine_step, self._coarse_step,
                self._total_stiffness, user_step=self._user_step,
            )
        b = self._buffers
        arguments = (
            kernels.Segments(*(column[:end] for column in self._segments)),
            self._mechanics,
            self._control,
            self._contacts,
            b._replace(per=b.per[:n], peak=b.peak[:n]),
        )
        if not self._checked:  # the kernel's arguments, once: every later call slices the same arrays
            kernels.check_arguments(kernels.Segments(*self._segments), self._mechanics, self._control,
                                    self._contacts, b)
            self._checked = True
        start = _time.perf_counter()
        try:
            status, steps, n_rec, fine_steps = _integrate_in_chunks(
                arguments, n, self.waveform.period, expected, self._step_work, self._progress
            )
        finally:
            self.wall_time += _time.perf_counter() - start
        if status != kernels.STATUS_OK:
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

    def boundary_state(self) -> BoundaryState:
        """The state at the end of the last integrated period (a copy), for
        :func:`passmd.solver.periodicity.mismatch`."""
        if self.periods_done < 1:
            raise ValueError("boundary_state() needs at least one integrated period: call run_to first")
        drive, k = self.drive, self._params[:, P_STIFFNESS]
        runner = math.sqrt((self._total_stiffness + drive.effective_load_cell_stiffness) / drive.runner_mass)
        actuator = (math.sqrt((drive.actuator.stiffness + float(k.max())) / drive.actuator.mass)
                    if drive.actuator_model == "flexible" else 0.0)
        return BoundaryState(self._buffers.y.copy(), self._state.copy(), self._params, runner, actuator,
                             drive.effective_load_cell_stiffness == 0.0)

    def settled_positions(self) -> np.ndarray:
        """The settled positions of the periods integrated so far (m): ``result().settled_positions``
        without the rest of the result (a protocol that decides period by period reads only these)."""
        if self.periods_done < 1:
            raise ValueError("settled_positions() needs at least one integrated period: call run_to first")
        return settled_positions(self._buffers.per[: self.periods_done])

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
            **measures(self._buffers, self.periods_done, n_rec, self._energy),
            steps=int(steps),
            fine_steps=int(fine_steps),
            fine_step=float(self._fine_step),
            coarse_step=float(self._coarse_step),
            wall_time=self.wall_time,
            contact_memory=[memory_diagnostics(self._params[g], self._state[g]) for g in range(G)],
            rejected_steps=int(self._buffers.carry[kernels.C_REJECTED]),
        )


def _integrate_in_chunks(arguments: tuple, periods: int, period: float, expected: float, step_work: float,
                         progress: bool | str | None):
    """Run the kernel over the first ``periods`` periods (each ``period`` s long) in chunks of
    :data:`CHUNK_STEPS` work (Ctrl-C is honoured between chunks).

    ``expected`` steps of ``step_work`` each (:data:`SPRINGS_PER_STEP`). Returns the kernel's
    (status, steps, rows recorded, fine steps) of the last call.
    """
    carry = arguments[-1].carry
    bar = _progress_bar(expected * step_work, periods, progress)
    chunk = max(1, int(CHUNK_STEPS / step_work))
    try:
        limit = chunk
        while True:
            status, steps, n_rec, fine_steps = kernels.integrate(*arguments, limit, True)  # (checked)
            if status != kernels.STATUS_PAUSED:
                return status, steps, n_rec, fine_steps
            limit = steps + chunk
            if bar is not None:
                bar.update(min(carry[kernels.C_TIME] / period, periods) - bar.n)
    finally:
        if bar is not None:
            bar.close()

