"""Records of a simulation: :class:`~passmd.solver.results.SimulationResult` (the recorded series and
per-period measures of one run, in SI units) and :class:`~passmd.solver.results.SimulationError` (a run that
diverged), and :func:`~passmd.solver.results.measures`, which turns the integrator's buffers
(``passmd.solver.kernels.Buffers``) into a result's fields. :class:`passmd.solver.simulation.Simulation` makes
the results; everything that reads a run (protocols, experiments, the command line) reads these records.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from passmd.model.parameters import Drive
from passmd.model.waveforms import Waveform
from passmd.solver import kernels


class SimulationError(RuntimeError):
    """A simulation diverged or could not be carried out."""


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
    energy : dict or None
        Work and energy terms of the balance (J); see :meth:`energy_balance`. None unless the
        run accumulated them (``simulate(..., energy=True)``).
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
    energy: dict | None
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

        Raises
        ------
        ValueError
            The run did not accumulate the energy terms (``simulate(..., energy=True)`` does).
        """
        if self.energy is None:
            raise ValueError("energy is not known: the run did not accumulate the energy terms; "
                             "simulate with energy=True")
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


def settled_positions(per: np.ndarray) -> np.ndarray:
    """Settled position of each period from its per-period accumulators (``Buffers.per`` rows): the
    mean of x_r − x_p over its settle window plus x_p at the window's end."""
    window_len = per[:, kernels.PER_WINDOW_LENGTH]
    if np.any(window_len <= 0):
        raise SimulationError(
            "a period has an empty settle window; the waveform's phase marks are inconsistent"
        )
    return per[:, kernels.PER_WINDOW_INTEGRAL] / window_len + per[:, kernels.PER_WINDOW_END_XP]


def measures(buffers: kernels.Buffers, periods: int, n_rec: int, energy: bool = True) -> dict:
    """The recorded series, measures of the first ``periods`` periods, energies (``energy``: the
    run accumulated them; else None) and state of a run stopped after them (fields of
    :class:`SimulationResult`)."""
    per, terms = buffers.per[:periods], buffers.energy
    rec = buffers.record[:n_rec]
    settled = settled_positions(per)
    duration = per[:, kernels.PER_DURATION]
    return dict(
        time=rec[:, 0].copy(),
        piezo_position=rec[:, 1].copy(),
        runner_position=rec[:, 2].copy(),
        runner_velocity=rec[:, 3].copy(),
        actuator_position=rec[:, 4::3].T.copy(),
        friction_force=rec[:, 5::3].T.copy(),
        slip_share=rec[:, 6::3].T.copy(),
        settled_positions=settled,
        back_steps=per[:, kernels.PER_MARK_XR] - per[:, kernels.PER_MIN_XR],
        peak_force_ratio=buffers.peak[:periods].copy(),
        period_mean_position=per[:, kernels.PER_XR_INTEGRAL] / duration,
        period_mean_friction=per[:, kernels.PER_FRICTION_INTEGRAL] / duration,
        energy={
            "input": float(terms[kernels.EN_INPUT]),
            "damping": float(terms[kernels.EN_DAMPING]),
            "contact": float(terms[kernels.EN_CONTACT]),
        } if energy else None,
        final_state=buffers.y.copy(),
    )

