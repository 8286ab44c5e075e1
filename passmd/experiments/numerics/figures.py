"""Trust in the integrator: time-step convergence, energy balance, the rigid Coulomb limit, cost.

These are not paper figures; they back every figure's numbers. Each function returns a
tidy DataFrame in SI units.
"""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd

from passmd.model import theory, waveforms
from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import Amplifier, Drive, Material
from passmd.protocols import stall
from passmd.runtime import sweep
from passmd.runtime.config import RunConfig
from passmd.runtime.units import from_si
from passmd.runtime.validation import check_choice, check_count, check_range
from passmd.solver import simulation as dynamics
from passmd.solver import steps as time_steps
from passmd.solver.setup import contact_groups

#: Configurations the numerics are shown for: (label, contacts, actuator model).
CONFIGURATIONS = (
    ("one contact, rigid", 1, "rigid"),
    ("one contact, flexible", 1, "flexible"),
    ("six contacts, rigid", 6, "rigid"),
    ("six contacts, flexible", 6, "flexible"),
)

# Accuracy the default integrator guarantees for what the figures report. Each is checked by
# running the quick figure data again with the step halved (error-controlled tolerance ÷ 16):
# every reported value moves by well under its stated accuracy, so any integrator at least as
# accurate reproduces the figures within them (the regression snapshots compare with them).

#: Positions, steps and back-steps (m): :data:`passmd.solver.steps.CONVERGED_ACCURACY`, the
#: settled position's distance from a much finer run. Halving the step moved no quick step,
#: back-step or settled position (Figs. 5a, 7–10) by more than 0.012 nm.
POSITION_ACCURACY = time_steps.CONVERGED_ACCURACY
#: Stall forces (N): the stall criterion's absolute tolerance
#: (:data:`passmd.protocols.stall.STALL_ABS_TOLERANCE`) — a finer run may stop a few periods
#: earlier or later, anywhere within it — plus :data:`STALL_FORCE_RTOL` of the force. The
#: integrator's own share, k_l·POSITION_ACCURACY ≈ 1 µN, is far below; halving the step moved
#: no quick force of Fig. 7 by more than 0.018 mN.
FORCE_ACCURACY = stall.STALL_ABS_TOLERANCE
#: Relative part of the stall-force accuracy (:data:`passmd.protocols.stall.STALL_REL_TOLERANCE`).
STALL_FORCE_RTOL = stall.STALL_REL_TOLERANCE
#: Steady velocities (m/s): a step per period accurate to POSITION_ACCURACY at the fastest
#: step frequency of Figs. 9b–10 (130 kHz), 6.5 µm/s. Halving the step moved none by more
#: than 1.4 µm/s.
VELOCITY_ACCURACY = POSITION_ACCURACY * 130e3
#: Micro-vibration frequencies and times (Eq. 15's t_s, t_a; turning points; the stall cycle's
#: full-slip time), relative: read off the recorded samples, so quantised to the record
#: spacing, which follows the step. Halving the step moved f_s and Eq. 15's times by at most
#: 3.2e-6 and the full-slip time by one record spacing, 1.5e-4; 1e-3 leaves a factor 6.
FREQUENCY_RTOL = 1e-3
#: Slip shares (fraction of a contact's radius sliding): they change fastest at the turning
#: points where Fig. 8 reads them, by up to 0.006 when the step was halved (their means and
#: maxima over a phase by 0.0004); 0.02 leaves a factor 3.
SLIP_SHARE_ACCURACY = 0.02
#: Critical amplitudes and force onsets, in final bracket widths of their search (its
#: ``tolerance``) plus POSITION_ACCURACY: the integrator's error can flip a bisection decision
#: only at an amplitude within that error of the switch, which moves the reported midpoint by
#: one width. Halving the step changed no quick critical amplitude or onset (Figs. 5–7).
CRITICAL_AMPLITUDE_BRACKETS = 1.0


#: Refinement factors of the default step (1 = the default).
RESOLUTIONS = {"quick": (0.5, 1.0, 2.0, 4.0), "paper": (0.25, 0.5, 1.0, 2.0, 4.0, 8.0)}


#: Step controls of :func:`convergence_study` by name: the integration schemes
#: (:data:`passmd.solver.steps.SCHEMES`) it compares.
STEP_CONTROLS = {
    "controlled": time_steps.SCHEMES["controlled"],  # the default: error-controlled steps
    "adaptive": time_steps.SCHEMES["adaptive"],  # explicit adaptive step (fine while ringing, coarse after)
    "quasi-static": time_steps.SCHEMES["quasi-static"],  # m_a neglected, fixed runner step
    "fixed": time_steps.SCHEMES["fixed"],  # the fine step throughout: the reference scheme
}
#: Step controls that differ for rigid actuators (they have no actuator mode to adapt to: their
#: explicit adaptive and quasi-static steps are the fixed one).
RIGID_STEP_CONTROLS = ("controlled", "fixed")
#: The step control whose finest run is a configuration's reference, by actuator model: the fixed
#: fine step (rigid) and the explicit adaptive step (flexible: there the fixed fine step runs only
#: up to resolution 2; how closely the two agree is ``adaptive_vs_fixed_nm`` of
#: :func:`convergence_facts`).
REFERENCE_CONTROL = {"rigid": "fixed", "flexible": "adaptive"}


def convergence_point(contacts: int, actuator_model: str, step_control: str, resolution: float,
                      amplitude: float, frequency: float, periods: int, preload: float,
                      hemisphere_radius: float) -> dict:
    """One run of :func:`convergence_study`: the saw-tooth run's steps and final position (SI)."""
    drive = Drive(hemisphere_radius=hemisphere_radius, preload=preload, contacts=contacts,
                  actuator_model=actuator_model)
    wf = waveforms.sawtooth(amplitude, frequency, drive, periods=periods)
    scheme = STEP_CONTROLS[step_control].replace(refine=resolution)
    res = dynamics.simulate(drive, wf, scheme=scheme, max_points=2)
    return {"fine_step_s": res.fine_step, "coarse_step_s": res.coarse_step, "steps": res.steps,
            "rejected_steps": res.rejected_steps, "final_position_m": res.final_position}


def convergence_study(
    amplitude: float = 150e-9,
    frequency: float = PROTOCOL.drive_frequency,
    periods: int = 3,
    resolutions=RESOLUTIONS["quick"],
    preload: float = 0.4,
    hemisphere_radius: float = 1e-3,
    step_controls=("controlled", "adaptive", "fixed"),
    config: RunConfig | None = None,
) -> pd.DataFrame:
    """Runner position after ``periods`` saw-tooth periods against the time-step refinement.

    Each configuration runs the ``step_controls`` that apply to it (:data:`STEP_CONTROLS`;
    rigid actuators only :data:`RIGID_STEP_CONTROLS`) and always its reference control
    (:data:`REFERENCE_CONTROL`), at every resolution (the fixed fine step of flexible actuators
    only up to 2). ``resolution`` divides the explicit steps and, for ``"controlled"``, the
    error tolerance by its fourth power (:func:`passmd.solver.simulation.simulate`), so that its steps
    too are ≈ ``resolution`` times shorter. The reference is the finest run of the reference
    control; ``error_m`` is the difference to it. With a ``config`` the runs
    (:func:`convergence_point`) go through :func:`passmd.runtime.sweep.run`, in parallel and cached;
    without one they run here, one after the other.

    Returns
    -------
    DataFrame
        Columns ``configuration, step_control, resolution, fine_step_s, coarse_step_s,
        steps, rejected_steps, final_position_m, error_m``.
    """
    for control in step_controls:
        check_choice("step_controls", control, tuple(STEP_CONTROLS))
    labels, points = [], []
    for label, contacts, model in CONFIGURATIONS:
        reference = REFERENCE_CONTROL[model]
        applicable = tuple(STEP_CONTROLS) if model == "flexible" else RIGID_STEP_CONTROLS
        controls = [c for c in step_controls if c in applicable]
        controls += [] if reference in controls else [reference]
        for control in controls:
            for r in resolutions:
                if control == "fixed" and model == "flexible" and r > 2.0:
                    continue  # the fixed fine step at r > 2 costs minutes and adds nothing
                labels.append((label, control == reference))
                points.append({"contacts": contacts, "actuator_model": model, "step_control": control,
                               "resolution": float(r), "amplitude": amplitude, "frequency": frequency,
                               "periods": periods, "preload": preload,
                               "hemisphere_radius": hemisphere_radius})
    if config is None:
        runs = pd.DataFrame([{**p, **convergence_point(**p)} for p in points])
    else:
        runs = sweep.run(convergence_point, points, description="time-step convergence", config=config)
    df = pd.DataFrame({
        "configuration": [label for label, _ in labels],
        "step_control": runs["step_control"].to_numpy(),
        "resolution": runs["resolution"].to_numpy(dtype=float),
        **{c: runs[c].to_numpy() for c in ("fine_step_s", "coarse_step_s", "steps", "rejected_steps",
                                           "final_position_m")},
    })
    # reference: the finest run of each configuration's reference control
    is_reference = np.array([ref for _, ref in labels])
    reference_runs = df[is_reference]
    finest = reference_runs.loc[reference_runs.groupby("configuration")["resolution"].idxmax()]
    ref = finest.set_index("configuration")["final_position_m"]
    df["error_m"] = df["final_position_m"] - df["configuration"].map(ref)
    return df


def energy_balance_table(
    amplitude: float = 150e-9,
    frequency: float = 1000.0,
    periods: int = 3,
    resolution: float = 1.0,
    error_control: bool = True,
) -> pd.DataFrame:
    """Energy balance W_in = E_kin + E_el + W_contact + W_damp of each configuration.

    Runs :func:`passmd.solver.simulation.simulate` at ``resolution`` with the exact contact and with
    the discrete contact (:data:`passmd.model.defaults.PROTOCOL` ``.springs`` springs): the
    default, error-controlled scheme, or with ``error_control=False`` the explicit scheme
    "adaptive" (:data:`passmd.solver.steps.SCHEMES`: the fixed fine step for rigid actuators,
    adaptive for flexible ones).
    """
    scheme = time_steps.SCHEMES["controlled" if error_control else "adaptive"].replace(refine=resolution)
    rows = []
    for label, contacts, model in CONFIGURATIONS:
        drive = Drive(contacts=contacts, actuator_model=model)
        wf = waveforms.sawtooth(amplitude, frequency, drive, periods=periods)
        for contact in ("exact", "discrete"):
            res = dynamics.simulate(drive, wf, contact_model=contact, springs=PROTOCOL.springs,
                                    max_points=2, scheme=scheme)
            bal = res.energy_balance()
            rows.append({"configuration": label, "contact_model": contact, **bal})
    return pd.DataFrame(rows)


#: Benchmark results shipped with the package (``passmd/data/benchmarks/<name>.json``).
BENCHMARKS = ("contact", "driving_waveform", "dynamics", "fit", "fit_coverage")


def benchmark_results(name: str, path: str | Path | None = None) -> dict:
    """One benchmark script's last results (``benchmarks/bench_<name>.py``), as stored.

    Parameters
    ----------
    name : {"contact", "driving_waveform", "dynamics", "fit", "fit_coverage"}
        The benchmark (``fit_coverage``: ``benchmarks/bench_fit_coverage.py``).
    path : path-like, optional
        A results file to read instead of the one installed with the package
        (``passmd/data/benchmarks/<name>.json``, package data, which the benchmark
        scripts write by default when run from the repository).

    Returns
    -------
    dict
        As the script wrote it (``{"meta": {...}, "rows": [...]}`` for the speed benchmarks).
    """
    check_choice("name", name, BENCHMARKS)
    if path is None:
        resource = resources.files("passmd") / "data" / "benchmarks" / f"{name}.json"
        if not resource.is_file():
            raise FileNotFoundError(
                f"{resource} is missing: run `python benchmarks/bench_{name}.py` in the repository"
            )
        return json.loads(resource.read_text(encoding="utf-8"))
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"{path} is missing: run `python benchmarks/bench_{name}.py --out {path}`")
    return json.loads(path.read_text(encoding="utf-8"))


def benchmark_table(path: str | Path | None = None) -> pd.DataFrame:
    """The speed benchmark's last results (``benchmarks/bench_dynamics.py``), as a table.

    Reads :func:`benchmark_results` ``("dynamics", path)``; ``df.attrs["meta"]`` holds the
    machine and settings it was measured with, ``df.attrs["across_processes"]`` the headline
    configuration timed in several fresh processes (empty if the file predates it).
    """
    data = benchmark_results("dynamics", path)
    df = pd.DataFrame(data["rows"])
    df.attrs["meta"] = data.get("meta", {})
    df.attrs["across_processes"] = data.get("across_processes", {})
    return df


def settle_fraction_sensitivity(
    fractions=(0.1, 0.2, 0.4), amplitude: float = 150e-9, frequency: float = PROTOCOL.drive_frequency,
    periods: int = 4,
) -> pd.DataFrame:
    """Step sizes for several settle windows (assumption ``settled_position``).

    The settled position averages x_r − x_p over the last ``fraction`` of each stick phase;
    the table shows how much the mean step of the last ``periods − 1`` periods depends on it.
    """
    rows = []
    for label, contacts, model in CONFIGURATIONS:
        drive = Drive(contacts=contacts, actuator_model=model)
        for fraction in fractions:
            wf = waveforms.sawtooth(amplitude, frequency, drive, periods=periods, settle_fraction=fraction)
            res = dynamics.simulate(drive, wf, max_points=2)
            rows.append({"configuration": label, "settle_fraction": float(fraction),
                         "mean_step_m": float(res.step_sizes.mean())})
    return pd.DataFrame(rows)


#: Factors the contact moduli E* and G* are multiplied by in :func:`rigid_coulomb_limit`.
#: The rigid drive's step is 2π/ω_runner/400 with ω_runner² ∝ Σ 2aG* ∝ scale^(2/3), so the
#: cost per period grows only as scale^(1/3): the largest factor costs 16 times the first.
STIFFNESS_SCALES = (1.0, 4.0, 16.0, 64.0, 256.0, 1024.0, 4096.0)

#: Rate at which the simulated step approaches the Coulomb limit: |difference| ∝ scale^(−rate).
#: Scaling both materials' E (ν fixed) scales E* and G* by the factor k. The contact law of
#: every contact is self-similar, F = μF_N Φ(u / u_x,max) (Cattaneo–Mindlin, Masing), with the
#: one length u_x,max = μ (E*/G*) d and the Hertz indentation d ∝ E*^(−2/3) (Eq. 7), so
#: u_x,max ∝ k^(−2/3) (not 1/k: the contact radius shrinks as E* grows, and the tangential
#: stiffness 2aG* grows only as k^(2/3)). The drive's departure from rigid Coulomb friction
#: (presliding at the corners, the elastic offset and micro-vibration after re-sticking) is
#: first order in that length.
EXPECTED_COULOMB_RATE = 2.0 / 3.0


def stiffened_drive(drive: Drive, scale: float) -> Drive:
    """The drive with both materials' Young's moduli (so E* and G*) multiplied by ``scale``.

    Poisson's ratios are kept, so E*/G* is unchanged and E*, G* scale exactly by ``scale``
    (:func:`passmd.model.theory.contact_moduli`). Stiffer than diamond is outside the plausible
    range of Young's moduli, and the peak Hertz pressure grows as scale^(2/3), so the copy has
    ``allow_extrapolation=True`` (the hard limits, e.g. a ≤ R/10, still apply).
    """
    k = check_range("scale", scale, 0.0, lower_open=True)
    h, r = drive.hemisphere_material, drive.runner_material
    return drive.replace(
        hemisphere_material=Material(h.youngs_modulus * k, h.poissons_ratio, h.name),
        runner_material=Material(r.youngs_modulus * k, r.poissons_ratio, r.name),
        actuator=drive.actuator,
        allow_extrapolation=True,
    )


def rigid_coulomb_limit(
    amplitude: float = 150e-9,
    frequency: float = PROTOCOL.drive_frequency,
    scales=STIFFNESS_SCALES,
    contacts=(6, 1),
    slow_flyback_loss: float = 0.5,
    periods: int = 4,
    preload: float = 0.4,
    hemisphere_radius: float = 1e-3,
    resolution: float = 1.0,
) -> pd.DataFrame:
    """Simulated step of the rigid-actuator drive against its infinitely stiff Coulomb limit.

    For each number of contacts and two fly-backs the contact moduli E*, G* are multiplied by
    each of ``scales`` (:func:`stiffened_drive`) and the saw-tooth drive is simulated with rigid
    actuators (:func:`passmd.solver.simulation.simulate`); its step (the last period's, the first
    carries the start from virgin contacts) is compared with the closed form of the rigid
    Coulomb drive, :func:`passmd.model.theory.coulomb_sawtooth_step` with μΣF_N
    (:func:`passmd.model.theory.friction_limit`), which the stiffness does not change.

    The two fly-backs: the paper's amplifier (150 V/µs, so t_f ≈ 1.5 µs at 150 nm), where the
    Coulomb loss a t_f² is a fraction of a nanometre and the limit is ≈ A; and a slow fly-back
    whose slew rate is chosen so that a t_f² = ``slow_flyback_loss`` · A, where the limit is
    far below A and the formula's fly-back term is tested. The runs use the fixed step of the
    runner mode (scheme "fixed"), which shrinks with the stiffened contacts;
    ``resolution`` divides it, to show that the gap is the model's and not the time step's.

    Returns
    -------
    DataFrame
        Columns ``configuration, contacts, flyback, scale, E_star_Pa, presliding_m`` (the
        rigid-actuator critical amplitude, Eq. 7 / Eq. 11, the elastic play that the limit
        removes), ``flyback_time_s, integrator_steps, simulated_step_m, coulomb_step_m,
        difference_m`` (simulated − Coulomb).
    """
    A = check_range("amplitude", amplitude, 0.0, lower_open=True, unit="m")
    loss = check_range("slow_flyback_loss", slow_flyback_loss, 0.0, 1.0, lower_open=True, upper_open=True)
    periods = check_count("periods", periods, minimum=2)
    rows = []
    for n in contacts:
        base = Drive(hemisphere_radius=hemisphere_radius, preload=preload, contacts=n,
                     actuator_model="rigid", allow_extrapolation=True)
        F_c = theory.friction_limit(base)
        accel = F_c / base.runner_mass
        # slow fly-back: a t_f² = loss · A, t_f = (A / A_max) · V_pp / SR solved for SR
        t_slow = np.sqrt(loss * A / accel)
        amp = base.amplifier
        slow_rate = amp.peak_to_peak_voltage * A / base.actuator.full_stroke_amplitude / t_slow
        flybacks = (("paper slew rate", amp), ("slow", Amplifier(amp.peak_to_peak_voltage, slow_rate)))
        for label, amplifier in flybacks:
            for k in scales:
                drive = stiffened_drive(base.replace(amplifier=amplifier, actuator=base.actuator), k)
                wf = waveforms.sawtooth(A, frequency, drive, periods=periods)
                t_f = waveforms.flyback_time(A, drive)
                limit = float(theory.coulomb_sawtooth_step(A, frequency, t_f, F_c, drive.runner_mass))
                # the fixed step of the stiffened runner mode: its error shrinks with the
                # stiffness, as the gap it measures does (the error-controlled step's absolute
                # tolerance would not, and would set a floor under the fitted rate)
                res = dynamics.simulate(drive, wf, max_points=2,
                                        scheme=time_steps.SCHEMES["fixed"].replace(refine=resolution))
                step = float(res.step_sizes[-1])
                rows.append({
                    "configuration": f"{'six contacts' if n == 6 else 'one contact'}, {label} fly-back",
                    "contacts": int(n),
                    "flyback": label,
                    "scale": float(k),
                    "E_star_Pa": theory.contact_moduli(drive)[0],
                    "presliding_m": theory.drive_theory(drive)["critical_amplitude_rigid_m"],
                    "flyback_time_s": float(t_f),
                    "integrator_steps": int(res.steps),
                    "simulated_step_m": step,
                    "coulomb_step_m": limit,
                    "difference_m": step - limit,
                })
    return pd.DataFrame(rows)


def coulomb_limit_rates(table: pd.DataFrame) -> pd.DataFrame:
    """Observed convergence rate of each configuration of :func:`rigid_coulomb_limit`.

    The rate is minus the least-squares slope of log|difference| against log(scale); the
    expected rate is :data:`EXPECTED_COULOMB_RATE`.

    Returns
    -------
    DataFrame
        Columns ``configuration, rate, expected_rate, largest_difference_m,
        smallest_difference_m``.
    """
    rows = []
    for label, g in table.groupby("configuration", sort=False):
        slope = np.polyfit(np.log(g["scale"]), np.log(np.abs(g["difference_m"])), 1)[0]
        rows.append({"configuration": label, "rate": float(-slope), "expected_rate": EXPECTED_COULOMB_RATE,
                     "largest_difference_m": float(np.abs(g["difference_m"]).max()),
                     "smallest_difference_m": float(np.abs(g["difference_m"]).min())})
    return pd.DataFrame(rows)


# --------------------------------------------------------------------------------------
# Figures of the numerics section (rows of passmd.experiments.figure_table)
# --------------------------------------------------------------------------------------

#: Step controls of the convergence figure (:data:`STEP_CONTROLS`; rigid actuators run those of
#: :data:`RIGID_STEP_CONTROLS`).
CONVERGENCE_STEP_CONTROLS = ("controlled", "adaptive", "quasi-static", "fixed")
#: Saw-tooth of the rigid-Coulomb-limit figure: amplitude (m), frequency (Hz), periods (the last step counts).
COULOMB_RUN = {"amplitude": 150e-9, "frequency": PROTOCOL.drive_frequency, "periods": 4}


def model_convergence(config: RunConfig) -> pd.DataFrame:
    """:func:`convergence_study` over the profile's :data:`RESOLUTIONS` and every step control."""
    return convergence_study(resolutions=RESOLUTIONS[config.profile], step_controls=CONVERGENCE_STEP_CONTROLS,
                             config=config)


def model_coulomb_limit(config: RunConfig) -> pd.DataFrame:
    """:func:`rigid_coulomb_limit` of :data:`COULOMB_RUN`, with each configuration's fitted
    ``rate`` and the ``expected_rate`` (:func:`coulomb_limit_rates`) as columns."""
    table = rigid_coulomb_limit(**COULOMB_RUN)
    rates = coulomb_limit_rates(table).set_index("configuration")
    table["rate"] = table["configuration"].map(rates["rate"])
    table["expected_rate"] = EXPECTED_COULOMB_RATE
    return table


# --------------------------------------------------------------------------------------
# Facts the numerics section quotes (glue names -> numbers), each from its table
# --------------------------------------------------------------------------------------


def step_plan_table() -> pd.DataFrame:
    """The integrator's steps (:func:`passmd.solver.steps.step_plan`) for each of :data:`CONFIGURATIONS`.

    Columns: ``configuration``, stiffest mode (kHz), stability limit 2/ω, fine and coarse step and
    the longest error-controlled step (ns; :data:`passmd.solver.steps.LONGEST_OMEGA_DT` over the
    runner mode's ω, whatever the local error allows).
    """
    rows = []
    for label, contacts, model in CONFIGURATIONS:
        drive = Drive(contacts=contacts, actuator_model=model)
        k_max = theory.drive_theory(drive)["tangential_stiffness_N_per_m"]
        _, mult = contact_groups(drive)
        plan = time_steps.step_plan(drive, max(k_max), float(np.dot(mult, k_max)))
        rows.append({
            "configuration": label,
            "stiffest mode (kHz)": from_si(plan.stiffest_frequency, "kHz"),
            "stability limit 2/ω (ns)": from_si(plan.stability_limit, "ns"),
            "fine step (ns)": from_si(plan.fine_step, "ns"),
            "coarse step (ns)": from_si(plan.coarse_step, "ns"),
            "longest controlled step (ns)": from_si(plan.longest_step, "ns"),
        })
    return pd.DataFrame(rows)


def fitted_convergence_order(rows: pd.DataFrame) -> float:
    """Order p of |error| ∝ h^p: least-squares slope over the runs at the default step or finer."""
    fit = rows[(rows["error_m"] != 0) & (rows["resolution"] >= 1.0)]
    return float(-np.polyfit(np.log(fit["resolution"]), np.log(np.abs(fit["error_m"])), 1)[0])


#: A run of the error-controlled scheme enters its fitted order only if its error exceeds this
#: multiple of the scheme's floor (the largest error of its finest runs, where it no longer
#: approaches the reference): within it, the floor and not the step sets the error. At 3 the floor
#: is at most a third of any error that enters the fit.
FLOOR_FACTOR = 3.0
#: Coarsest resolution in the error-controlled scheme's fitted order. Coarser, the tolerance
#: (resolution⁻⁴ times the default) lets many steps reach the longest step
#: (:data:`passmd.solver.steps.LONGEST_OMEGA_DT` over ω), which it then no longer sets: at 0.25 the
#: runs change when that bound is raised, at 0.5 and finer they hardly do.
CONTROLLED_FIT_COARSEST = 0.5


def fitted_order_above_floor(rows: pd.DataFrame, factor: float = FLOOR_FACTOR,
                             coarsest: float = CONTROLLED_FIT_COARSEST) -> tuple[float, float]:
    """Order p of |error| ∝ h^p of one step control, fitted above its error floor.

    The floor is the largest |error| of the control's finest runs (all configurations); the
    least-squares slope is taken over the runs at ``coarsest`` resolution or finer whose |error|
    exceeds ``factor`` times the floor. Returns (p, floor in m).

    Raises
    ------
    ValueError
        Fewer than two resolutions above the floor: coarser runs are needed to fit an order.
    """
    finest = rows[rows["resolution"] == rows["resolution"].max()]
    floor = float(np.abs(finest["error_m"]).max())
    fit = rows[(np.abs(rows["error_m"]) > factor * floor) & (rows["resolution"] >= coarsest)]
    if fit["resolution"].nunique() < 2:
        raise ValueError(f"only {fit['resolution'].nunique()} resolution(s) with an error above {factor:g} "
                         f"times the floor of {floor:.3g} m: run coarser resolutions to fit an order")
    order = -np.polyfit(np.log(fit["resolution"]), np.log(np.abs(fit["error_m"])), 1)[0]
    return float(order), floor


def convergence_facts(conv: pd.DataFrame) -> dict:
    """Numbers the convergence paragraphs quote (:func:`model_convergence`).

    Explicit schemes (adaptive and fixed): ``conv_order`` and ``conv_max_err_nm``, their order
    and largest error at the default step (nm); ``adaptive_vs_fixed_nm``, their largest
    difference (flexible); ``adaptive_saving``, fixed over adaptive steps. Quasi-static step:
    ``quasi_order``, ``quasi_max_err_nm`` and ``quasi_saving`` (adaptive over its steps).
    Error-controlled scheme: ``ctrl_order`` and ``ctrl_floor_nm`` (:func:`fitted_order_above_floor`),
    ``ctrl_floor_rigid_nm`` and ``ctrl_floor_flexible_nm`` (the largest error of its finest runs
    with rigid and with flexible actuators), ``ctrl_max_err_nm`` (its largest error at the
    default tolerance), ``ctrl_rejected_pct`` (the largest share of its steps rejected there,
    %), ``ctrl_saving_adaptive`` and ``ctrl_saving_fixed`` (explicit adaptive and fixed steps
    over its own, six contacts, flexible) and ``ctrl_saving_rigid`` (fixed over its own, six
    contacts, rigid). Savings are at the default step, for six flexible contacts unless said.
    """
    explicit = conv[conv["step_control"].isin(("adaptive", "fixed"))]
    default = explicit[explicit["resolution"] == 1.0]
    quasi = conv[conv["step_control"] == "quasi-static"]
    controlled = conv[conv["step_control"] == "controlled"]
    ctrl_default = controlled[controlled["resolution"] == 1.0]
    ctrl_order, ctrl_floor = fitted_order_above_floor(controlled)
    ctrl_finest = controlled[controlled["resolution"] == controlled["resolution"].max()]
    ctrl_flexible = ctrl_finest["configuration"].str.contains("flexible")
    adaptive = conv[conv["step_control"] == "adaptive"]
    adaptive = adaptive.set_index(["configuration", "resolution"])["final_position_m"]
    fixed = conv[(conv["step_control"] == "fixed") & conv["configuration"].str.contains("flexible")]
    fixed = fixed.set_index(["configuration", "resolution"])["final_position_m"]
    steps = conv[conv["resolution"] == 1.0].set_index(["configuration", "step_control"])["steps"]
    six, six_rigid = "six contacts, flexible", "six contacts, rigid"
    return {
        "conv_order": fitted_convergence_order(explicit),
        "quasi_order": fitted_convergence_order(quasi),
        "quasi_max_err_nm": float(np.abs(quasi[quasi["resolution"] == 1.0]["error_m"]).max() * 1e9),
        "conv_max_err_nm": float(np.abs(default["error_m"]).max() * 1e9),
        "adaptive_vs_fixed_nm": float(np.abs(adaptive.reindex(fixed.index) - fixed).max() * 1e9),
        "adaptive_saving": float(steps[(six, "fixed")] / steps[(six, "adaptive")]),
        "quasi_saving": float(steps[(six, "adaptive")] / steps[(six, "quasi-static")]),
        "ctrl_order": ctrl_order,
        "ctrl_floor_nm": ctrl_floor * 1e9,
        "ctrl_floor_rigid_nm": float(np.abs(ctrl_finest[~ctrl_flexible]["error_m"]).max() * 1e9),
        "ctrl_floor_flexible_nm": float(np.abs(ctrl_finest[ctrl_flexible]["error_m"]).max() * 1e9),
        "ctrl_max_err_nm": float(np.abs(ctrl_default["error_m"]).max() * 1e9),
        "ctrl_rejected_pct": float((ctrl_default["rejected_steps"] / ctrl_default["steps"]).max() * 100),
        "ctrl_saving_adaptive": float(steps[(six, "adaptive")] / steps[(six, "controlled")]),
        "ctrl_saving_fixed": float(steps[(six, "fixed")] / steps[(six, "controlled")]),
        "ctrl_saving_rigid": float(steps[(six_rigid, "fixed")] / steps[(six_rigid, "controlled")]),
    }


def energy_facts(energy: pd.DataFrame, explicit: pd.DataFrame) -> dict:
    """Numbers of the energy-balance paragraph, from two :func:`energy_balance_table` runs.

    ``energy`` is the default (error-controlled) scheme, ``explicit`` the same runs with
    ``error_control=False``. Returns the largest |relative residual| of ``energy``
    (``energy_max_rel``; ``energy_exact_max_rel`` and ``energy_discrete_max_rel`` per contact
    model) and of ``explicit`` (``energy_explicit_max_rel``), their ratio
    (``energy_tighter``: explicit over default), and the smallest and largest factor by which
    a default run's residual exceeds the explicit scheme's on the same run
    (``energy_ratio_min``, ``energy_ratio_max``).
    """
    keys = ["configuration", "contact_model"]
    if not energy[keys].reset_index(drop=True).equals(explicit[keys].reset_index(drop=True)):
        raise ValueError("explicit must list the same runs as energy, in the same order")
    default = energy["relative_residual"].abs().to_numpy()
    other = explicit["relative_residual"].abs().to_numpy()
    ratio = default / other
    exact = (energy["contact_model"] == "exact").to_numpy()
    return {"energy_max_rel": float(default.max()),
            "energy_exact_max_rel": float(default[exact].max()),
            "energy_discrete_max_rel": float(default[~exact].max()),
            "energy_explicit_max_rel": float(other.max()),
            "energy_tighter": float(other.max() / default.max()),
            "energy_ratio_min": float(ratio.min()), "energy_ratio_max": float(ratio.max())}


def settle_facts(sens: pd.DataFrame) -> dict:
    """Largest spread of the mean step over the settle windows: nm and % of the mean
    (:func:`settle_fraction_sensitivity`)."""
    spread = sens.groupby("configuration")["mean_step_m"].agg(lambda v: v.max() - v.min())
    mean = sens.groupby("configuration")["mean_step_m"].mean()
    return {"settle_spread_nm": float(spread.max() * 1e9),
            "settle_spread_rel": float((spread / mean).max() * 100)}


def coulomb_facts(coulomb: pd.DataFrame, refined: pd.DataFrame) -> dict:
    """Numbers the Coulomb-limit paragraph quotes, from :func:`model_coulomb_limit` and the same
    run at half the time step (``refined``): gaps (nm, % of A_c), fly-back times (µs), rates."""
    k = np.array(sorted(coulomb["scale"].unique()))
    by = coulomb.set_index(["configuration", "scale"])
    paper, slow = "six contacts, paper slew rate fly-back", "six contacts, slow fly-back"
    change = np.abs(refined["difference_m"] - coulomb["difference_m"])
    slow_tf = coulomb[coulomb["flyback"] == "slow"]["flyback_time_s"]
    return {
        "cl_scale_max": float(k[-1]),
        "cl_refined_nm": float(change.max() * 1e9),
        "cl_refined_rel": float((change / np.abs(coulomb["difference_m"])).max() * 100),
        "cl_tf_paper_us": float(by.loc[(paper, k[0]), "flyback_time_s"] * 1e6),
        "cl_tf_slow_min_us": float(slow_tf.min() * 1e6),
        "cl_tf_slow_max_us": float(slow_tf.max() * 1e6),
        "cl_six_paper_limit_nm": float(by.loc[(paper, k[0]), "coulomb_step_m"] * 1e9),
        "cl_six_paper_gap0_nm": float(-by.loc[(paper, k[0]), "difference_m"] * 1e9),
        "cl_six_paper_gap0_ratio": float(-by.loc[(paper, k[0]), "difference_m"]
                                         / by.loc[(paper, k[0]), "presliding_m"] * 100),
        "cl_six_paper_gap_last_nm": float(-by.loc[(paper, k[-1]), "difference_m"] * 1e9),
        "cl_six_slow_limit_nm": float(by.loc[(slow, k[0]), "coulomb_step_m"] * 1e9),
        "cl_six_slow_gap_last_nm": float(abs(by.loc[(slow, k[-1]), "difference_m"]) * 1e9),
        "cl_rate_min": float(coulomb["rate"].min()),
        "cl_rate_max": float(coulomb["rate"].max()),
        "cl_expected": float(EXPECTED_COULOMB_RATE),
    }


def coulomb_side(coulomb: pd.DataFrame) -> str:
    """Where the simulated steps lie against the Coulomb limit: "below" or "on both sides of"."""
    return "below" if (coulomb["difference_m"] < 0).all() else "on both sides of"


def coulomb_rising_gaps(coulomb: pd.DataFrame) -> list[str]:
    """Each place where the gap to the Coulomb limit grows from one stiffness factor to the next."""
    rising = []
    for label, g in coulomb.groupby("configuration", sort=False):
        ordered = g.sort_values("scale")
        gap = np.abs(ordered["difference_m"].to_numpy())
        scales = ordered["scale"].to_numpy()
        rising += [f"{label}: {gap[i] * 1e9:.3f} nm at k = {scales[i]:g} → {gap[i + 1] * 1e9:.3f} nm at "
                   f"k = {scales[i + 1]:g}" for i in np.flatnonzero(np.diff(gap) >= 0)]
    return rising


#: Speed targets of the integrator: ms per 100 Hz period of the
#: six-contact flexible drive with the default (error-controlled) step and the exact contact,
#: which a sweep of the assumption space needs, and ns per fixed step (exact contact).
TARGET_MS_PER_PERIOD, TARGET_NS_PER_STEP = 1.0, 25.0


def benchmark_facts(bench: pd.DataFrame) -> dict:
    """The speed numbers the performance paragraph quotes, from :func:`benchmark_table`:
    ms per 100 Hz period (six flexible contacts, exact contact) with the default
    error-controlled step and with the explicit adaptive one, the periods each timed run
    lasted, the same default-step configuration's median over fresh processes and their number
    (``bench_six_flex_processes_ms``, ``bench_processes``; NaN and 0 if not measured), the
    largest ns per fixed step (exact), the machine's load average, and the targets."""
    spread = bench.attrs.get("across_processes", {})
    six_flex = bench[(bench["contacts"] == 6) & (bench["actuator"] == "flexible")
                     & (bench["contact_model"] == "exact")].set_index("step")
    fixed_exact = bench[(bench["step"] == "fixed") & (bench["contact_model"] == "exact")]
    return {
        "bench_six_flex_ms": float(six_flex.loc["controlled", "ms_per_100Hz_period"]),
        "bench_six_flex_adaptive_ms": float(six_flex.loc["adaptive", "ms_per_100Hz_period"]),
        "bench_periods": int(bench.attrs["meta"].get("periods_per_run", 1)),
        "bench_six_flex_processes_ms": float(spread.get("median_ms_per_100Hz_period", float("nan"))),
        "bench_processes": len(spread.get("ms_per_100Hz_period_per_process", [])),
        "bench_fixed_ns": float(fixed_exact["ns_per_step"].max()),
        "bench_load": float(bench.attrs["meta"].get("load_average_before", [float("nan")])[0]),
        "target_ms_per_period": TARGET_MS_PER_PERIOD,
        "target_ns_per_step": TARGET_NS_PER_STEP,
    }
