"""Integration schemes and time steps of the hybrid simulation, and the work a run needs.

A :class:`Scheme` says how :mod:`passmd.solver.simulation` steps through each linear piece of x_p(t);
:data:`SCHEMES` names the four (see there). All of them take a fixed number of steps per
period of the stiffest mode while flexible actuators ring (the actuator on k_p plus the
contact's 2aG*, ≈ 3 MHz; the runner-on-contacts mode for rigid actuators) and a minimum
number of steps on every waveform edge. :func:`step_plan` derives the steps from the
drive's parameters. Before a run starts, :func:`check_work` refuses one whose step is below
the float resolution of the simulated time or that would take more than :data:`MAX_STEPS`
steps.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from passmd.model.parameters import Drive
from passmd.model.waveforms import Waveform
from passmd.runtime.validation import check_choice, check_positive
from passmd.solver.kernels import Segments

#: Accuracy the default steps are chosen for: the settled runner position after three 100 Hz
#: periods within this of a run with much finer steps (m); the model-numerics chapter shows it.
CONVERGED_ACCURACY = 0.05e-9

#: Fine steps per period of the stiffest linearised mode (flexible actuators).
STEPS_PER_STIFF_PERIOD = 96
#: Coarse step (flexible actuators, while they follow quasi-statically) as ω_max·dt.
#: Verlet is stable up to 2; 1.5 keeps a 25 % margin (the contact stiffness never exceeds 2aG*).
COARSE_OMEGA_DT = 1.5
#: Actuator ringing amplitude (m) below which the coarse (or quasi-static) step is used; the
#: switch tests the actuator acceleration against ω_max² times this. 10 pm is 1/5 of
#: CONVERGED_ACCURACY; 1 pm took a fifth more fine steps and changed no settled position of
#: the error-controlled step by more than 0.0005 nm (100 Hz saw-tooth, 150 and 202 nm).
RINGING_TOLERANCE = 1e-11
#: Quiet stiff-mode periods (at the fine step) before the step grows.
QUIET_PERIODS = 2
#: Steps per period of the runner-on-contacts mode (rigid actuators).
STEPS_PER_RUNNER_PERIOD = 400
#: Quasi-static actuator step (schemes "quasi-static" and "controlled"): steps per period of
#: the runner-on-contacts mode, as for rigid actuators (the actuator in series only softens it).
#: The error-controlled step starts each quiet phase with it.
STEPS_PER_QUASI_RUNNER_PERIOD = 400
#: Error-controlled step (rigid actuators, or the quasi-static actuator step): local position
#: error of the runner allowed per step (m).
LOCAL_ERROR_TOLERANCE = 3e-14
#: Longest error-controlled step as ω_runner·dt: Verlet is stable up to 2 on the runner mode
#: (the runner on all contacts at their largest tangent stiffness, and the load cell).
LONGEST_OMEGA_DT = 1.5
#: Minimum number of steps on every linear piece of x_p(t) (resolves the fly-back).
MIN_SEGMENT_STEPS = 40
#: Work budget of one simulation in integrator steps (a quarter to half an hour at the ns per
#: step that ``benchmarks/bench_dynamics.py`` measures). A run whose step plan needs more is
#: refused before it starts, with the option responsible named.
MAX_STEPS = 2e10
#: Smallest step, in units of the float spacing of the simulated time t: below it t + dt
#: rounds to a different step than planned (at 1 spacing, t stops advancing). 2¹⁰ keeps the
#: rounding of each step below 0.1 % of it.
MIN_STEP_SPACINGS = 2.0**10


class WorkLimitError(ValueError):
    """A run refused before it starts: its step is below the time resolution or it needs more
    than :data:`MAX_STEPS` steps. The message names the parameter (and command-line option)
    responsible."""


#: What flexible actuators step with once their ringing has decayed (``Scheme.quiet_step``).
QUIET_STEPS = ("fine", "coarse", "quasi-static")


@dataclass(frozen=True)
class Scheme:
    """How the integrator steps: one of :data:`SCHEMES`, possibly refined or with a fixed ``dt``.

    Every scheme takes the fine step of :func:`step_plan` while flexible actuators ring (after
    each corner of x_p(t)). The fields say what happens elsewhere.

    Attributes
    ----------
    name : str
        The key of :data:`SCHEMES` the scheme derives from.
    quiet_step : {"fine", "coarse", "quasi-static"}
        Flexible actuators once their ringing has decayed: the fine step throughout, the
        coarse explicit step (velocity Verlet at :data:`COARSE_OMEGA_DT`), or the quasi-static
        actuator (m_a neglected, its force balance solved per step,
        :func:`passmd.solver.kernels.quasi_static_position`) at the runner-mode step
        :data:`STEPS_PER_QUASI_RUNNER_PERIOD`.
    error_control : bool
        The quasi-static phases (flexible actuators) and every step (rigid ones) are chosen by
        a local error estimate of the runner's position (:data:`LOCAL_ERROR_TOLERANCE`), with
        the runner's linear oscillation on its contacts integrated exactly (see
        :mod:`passmd.solver.kernels`). Without it rigid actuators take the fine step.
    newton_balance : bool
        (quasi-static actuators) Each actuator's force balance by a Newton step on the exact
        contact's slope, accepted where its error is provably below the solve's tolerance
        (:func:`passmd.solver.kernels.quasi_static_position` otherwise), and the trigonometric
        coefficients of the error-controlled step by their series: the same solution to the
        tolerance, at about half the arithmetic.
    smooth_breakpoints : bool
        The step control goes on across a breakpoint of x_p(t) where its rate does not change
        (the settle window's start on a saw-tooth ramp) instead of starting afresh with the fine
        step.
    refine : float
        Divides every step (convergence studies); under error control it divides the
        tolerance by the fourth power of ``refine`` instead (the controlled step scales as its fourth root).
    dt : float or None
        Scheme "fixed" only: this step (s) throughout instead of the fine step; it must stay
        below the Verlet stability limit of the stiffest mode (``refine`` must then be 1).
    """

    name: str
    quiet_step: str
    error_control: bool
    refine: float = 1.0
    dt: float | None = None
    newton_balance: bool = False
    smooth_breakpoints: bool = False

    def __post_init__(self):
        check_choice("quiet_step", self.quiet_step, QUIET_STEPS)
        object.__setattr__(self, "refine", check_positive("refine", self.refine))
        if self.error_control and self.quiet_step != "quasi-static":
            raise ValueError(f"error_control = True is not allowed with quiet_step = {self.quiet_step!r}: "
                             "it needs 'quasi-static'")
        if self.dt is not None:
            object.__setattr__(self, "dt", check_positive("dt", self.dt, "s"))
            if self.quiet_step != "fine" or self.error_control:
                raise ValueError(f"dt = {self.dt!r} is not allowed with scheme {self.name!r}: only scheme "
                                 "'fixed' takes a given step")
            if self.refine != 1.0:
                raise ValueError(f"refine = {self.refine!r} is not allowed with dt = {self.dt!r}: the "
                                 "step is given; refine it by dividing dt")

    def replace(self, **changes) -> Scheme:
        """A copy with some fields changed (validated again), e.g. ``refine=2.0`` or ``dt=1e-9``."""
        return replace(self, **changes)


#: The schemes by name (``simulate(..., scheme=name)``); "controlled" is the default.
SCHEMES = {
    # error-controlled steps: rigid actuators throughout, flexible ones once quasi-static
    "controlled": Scheme("controlled", "quasi-static", True, newton_balance=True, smooth_breakpoints=True),
    # the same error control with bracketed balance solves and every breakpoint starting afresh: the
    # scheme the default is tested against (tests/test_reference_scheme.py)
    "reference": Scheme("reference", "quasi-static", True),
    # explicit adaptive Verlet: fine while flexible actuators ring, coarse after; rigid: fine
    "adaptive": Scheme("adaptive", "coarse", False),
    # fine while flexible actuators ring, then the quasi-static actuator at a fixed runner step
    "quasi-static": Scheme("quasi-static", "quasi-static", False),
    # the fine step (or a given dt) throughout: the reference of the convergence studies
    "fixed": Scheme("fixed", "fine", False),
}
#: The scheme of :func:`passmd.solver.simulation.simulate` unless one is given.
DEFAULT_SCHEME = "controlled"


def resolve_scheme(scheme: str | Scheme) -> Scheme:
    """The :class:`Scheme` a ``scheme`` argument names (a key of :data:`SCHEMES`, or a Scheme)."""
    if isinstance(scheme, Scheme):
        return scheme
    if isinstance(scheme, str) and scheme in SCHEMES:
        return SCHEMES[scheme]
    allowed = ", ".join(repr(name) for name in SCHEMES)
    raise ValueError(f"scheme = {scheme!r} is not allowed: must be one of {allowed} or a "
                     "passmd.solver.steps.Scheme")


@dataclass(frozen=True)
class StepPlan:
    """How the integrator discretises time for one drive."""

    fine_step: float  # fine step: resolves the stiffest mode (s)
    coarse_step: float  # step while the actuators do not ring (s); = fine_step for rigid actuators
    stiffest_frequency: float  # frequency of the stiffest linearised mode (Hz)
    stability_limit: float  # Verlet stability limit 2/ω of that mode (s)
    activity_threshold: float  # actuator acceleration that counts as ringing (m/s²)
    quiet_steps: int  # fine steps below the threshold before the step grows
    quasi_step: float = 0.0  # step of the quasi-static actuator (flexible actuators) (s)
    longest_step: float = 0.0  # longest error-controlled step (s)


def step_plan(
    drive: Drive, contact_stiffness_max: float, total_contact_stiffness: float, refine: float = 1.0
) -> StepPlan:
    """Time steps from the parameters (flexible: actuator mode; rigid: runner mode).

    Parameters
    ----------
    drive : Drive
        The drive.
    contact_stiffness_max : float
        Largest tangential stiffness 2aG* of one contact (N/m).
    total_contact_stiffness : float
        Σ n_g 2aG*_g over all contacts (N/m).
    refine : float
        Refinement factor: the steps are divided by it (``Scheme.refine``).
    """
    act = drive.actuator
    runner_stiffness = total_contact_stiffness + drive.effective_load_cell_stiffness
    omega_runner = np.sqrt(runner_stiffness / drive.runner_mass)
    if drive.actuator_model == "flexible":
        omega = np.sqrt((act.stiffness + contact_stiffness_max) / act.mass)
        dt = 2 * np.pi / omega / STEPS_PER_STIFF_PERIOD / refine
        # never beyond COARSE_OMEGA_DT/ω: a refine < 1 coarsens the fine step only
        coarse = COARSE_OMEGA_DT / omega / max(refine, 1.0)
        threshold = omega**2 * RINGING_TOLERANCE
        quiet = int(np.ceil(QUIET_PERIODS * STEPS_PER_STIFF_PERIOD * refine))
    else:
        omega = omega_runner
        dt = 2 * np.pi / omega / STEPS_PER_RUNNER_PERIOD / refine
        coarse, threshold, quiet = dt, 0.0, 0
    quasi = 2 * np.pi / omega_runner / STEPS_PER_QUASI_RUNNER_PERIOD / refine
    return StepPlan(float(dt), float(max(coarse, dt)), float(omega / (2 * np.pi)), float(2.0 / omega),
                    float(threshold), quiet, float(max(quasi, dt)), float(LONGEST_OMEGA_DT / omega_runner))


def segments(
    waveform: Waveform, fine_step: float, coarse_step: float, quasi_step: float | None = None,
    longest_step: float | None = None,
) -> Segments:
    """The linear pieces of x_p(t) with their steps (capped at 1/MIN_SEGMENT_STEPS of the piece)."""
    t, x = waveform.times, waveform.positions
    t0, t1, x0, x1 = t[:-1], t[1:], x[:-1], x[1:]
    shortest = (t1 - t0) / MIN_SEGMENT_STEPS
    fine = np.minimum(fine_step, shortest)
    coarse = np.minimum(coarse_step, shortest)
    # period of each piece: its start over T, nudged up by 1e-9 so that a start k·T that
    # rounds to just below k still counts as period k
    period = np.minimum((t0 / waveform.period + 1e-9).astype(np.int64), waveform.periods - 1)
    # a piece is in a settle window when it lies inside one; the windows are disjoint, so
    # only the last window starting at or before the piece can hold it (O(n log n))
    order = np.argsort(waveform.settle_windows[:, 0], kind="stable")
    starts = waveform.settle_windows[order, 0]
    ends = waveform.settle_windows[order, 1]
    last = np.searchsorted(starts, t0, side="right") - 1
    inside = (last >= 0) & (t1 <= ends[np.maximum(last, 0)])
    window = inside.astype(np.int64)
    mark = np.isin(t0, waveform.slip_marks).astype(np.int64)
    quasi = np.minimum(coarse_step if quasi_step is None else quasi_step, shortest)
    longest = np.minimum(coarse_step if longest_step is None else max(longest_step, fine_step), shortest)
    return Segments(t0, t1, x0, x1, fine, coarse, period, window, mark, quasi, longest)


def expected_steps(waveform: Waveform, plan: StepPlan, fine_step: float, coarse_step: float) -> np.ndarray:
    """Integrator steps each linear piece of x_p(t) takes under a step plan (estimate).

    Every piece starts with ``plan.quiet_steps`` fine steps (the corner rings the actuator
    mode) and continues with the coarse step; rigid actuators and runs without adaptation
    (``coarse_step == fine_step``) take the fine step throughout. Ringing after slips adds
    fine steps, so the sum is a lower bound of the work, close to it for saw-tooth runs.
    Error-controlled runs are estimated with the steps they would take without the control
    (the fine step for rigid actuators, the quasi-static step for flexible ones): an upper
    estimate, which their controlled steps undercut several-fold on saw-tooth runs.
    """
    seg = segments(waveform, fine_step, coarse_step)
    return _expected(seg.t0, seg.t1, seg.fine, plan, fine_step, coarse_step)


def _expected(t0, t1, fine, plan: StepPlan, fine_step: float, coarse_step: float) -> np.ndarray:
    """:func:`expected_steps` of the pieces from t0 to t1 whose fine steps are ``fine``."""
    duration = t1 - t0
    coarse = np.minimum(coarse_step, duration / MIN_SEGMENT_STEPS)
    n_fine = np.minimum(np.ceil(duration / fine), plan.quiet_steps if coarse_step > fine_step else 0)
    rest = np.maximum(duration - n_fine * fine, 0.0)
    return n_fine + np.ceil(rest / coarse)


def piece_work(pieces: Segments, plan: StepPlan, fine_step: float, coarse_step: float):
    """What :func:`check_work` checks, piece by piece of x_p(t) (``pieces`` from :func:`segments`
    with ``fine_step``): whether each piece's fine step resolves the simulated time, and the
    expected steps up to the end of each piece (cumulative). A run of the first n pieces is
    refused exactly when one of them is not resolved or the cumulative steps of the n-th exceed
    :data:`MAX_STEPS`; a simulation run period by period
    (:class:`passmd.solver.simulation.Simulation`) decides this once per waveform."""
    resolved = pieces.fine >= MIN_STEP_SPACINGS * np.spacing(pieces.t1)
    return resolved, np.cumsum(_expected(pieces.t0, pieces.t1, pieces.fine, plan, fine_step, coarse_step))


def refused(resolved: np.ndarray, cumulative: np.ndarray, pieces: int) -> bool:
    """Whether :func:`check_work` refuses the run of the first ``pieces`` pieces, from
    :func:`piece_work`'s arrays."""
    return bool(cumulative[pieces - 1] > MAX_STEPS or not resolved[:pieces].all())


def _step_setter(drive: Drive, plan: StepPlan, total_contact_stiffness: float) -> str:
    """Which parameters set the step of a plan, named as in the API and on the command line."""
    if drive.actuator_model == "flexible":
        act = drive.actuator
        return (
            f"the actuator mode ({plan.stiffest_frequency:.3g} Hz) from actuator_mass (--actuator-mass) = "
            f"{act.mass!r} kg and actuator_stiffness (--actuator-stiffness) = {act.stiffness!r} N/m"
        )
    return (
        f"the runner mode ({plan.stiffest_frequency:.3g} Hz) from runner_mass (--runner-mass) = "
        f"{drive.runner_mass!r} kg, load_cell_stiffness (--load-cell-stiffness) = "
        f"{drive.effective_load_cell_stiffness!r} N/m and the contacts' {total_contact_stiffness:.3g} N/m"
    )


def check_work(
    drive: Drive,
    waveform: Waveform,
    plan: StepPlan,
    fine_step: float,
    coarse_step: float,
    total_contact_stiffness: float,
    user_step: bool = False,
) -> float:
    """Refuse a run that cannot advance time or would exceed :data:`MAX_STEPS`; return its steps.

    Raises
    ------
    WorkLimitError
        A step below :data:`MIN_STEP_SPACINGS` float spacings of the simulated time, or an
        expected number of steps (:func:`expected_steps`) above :data:`MAX_STEPS`; the
        message names the parameter responsible.
    """
    seg = segments(waveform, fine_step, coarse_step)
    t0, t1, fine = seg.t0, seg.t1, seg.fine
    resolution = MIN_STEP_SPACINGS * np.spacing(t1)
    worst = int(np.argmin(fine / resolution))
    if fine[worst] < resolution[worst]:
        piece = t1[worst] - t0[worst]
        if user_step:
            cause = f"dt = {fine_step!r} s"
        elif piece / MIN_SEGMENT_STEPS < fine_step:
            cause = (
                f"the waveform's piece from t = {t0[worst]:.6g} s lasting {piece:.3g} s "
                f"({MIN_SEGMENT_STEPS} steps per piece; a saw-tooth's fly-back lasts A/A_max·V_pp/SR: "
                "raise amplitude (--amplitude) or lower slew_rate (--slew-rate))"
            )
        else:
            cause = _step_setter(drive, plan, total_contact_stiffness)
        raise WorkLimitError(
            f"time step {fine[worst]:.3g} s is out of range: it must be >= {resolution[worst]:.3g} s "
            f"({MIN_STEP_SPACINGS:g} float spacings of t = {t1[worst]:.6g} s) for time to advance "
            f"accurately; it is set by {cause}"
        )
    steps = float(np.sum(expected_steps(waveform, plan, fine_step, coarse_step)))
    if steps > MAX_STEPS:
        per_period = steps / waveform.periods
        fit = int(MAX_STEPS // per_period)
        hint = f"periods (--periods) = {waveform.periods} must be <= {fit}" if fit >= 1 else (
            f"the step of {fine_step:.3g} s is set by "
            + (f"dt = {fine_step!r} s" if user_step else _step_setter(drive, plan, total_contact_stiffness))
        )
        raise WorkLimitError(
            f"the run needs ≈ {steps:.3g} integrator steps ({per_period:.3g} per period), more than the "
            f"budget of {MAX_STEPS:.3g} steps (passmd.solver.steps.MAX_STEPS): {hint}"
        )
    return steps


