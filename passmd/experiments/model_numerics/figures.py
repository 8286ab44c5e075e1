"""Trust in the integrator: time-step convergence, energy balance, settle windows, the rigid Coulomb limit.

These are not paper figures; they back every figure's numbers. Each function returns a
tidy DataFrame in SI units. The accuracies the integrator states for the figures, the numbers the
chapter quotes from these tables and the stored speed benchmarks are in
:mod:`passmd.experiments.model_numerics.facts`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd.experiments import FigureSpec
from passmd.ledger.claims import load_claims
from passmd.model import theory, waveforms
from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import Amplifier, Drive, Material
from passmd.model.tables import Actuator, actuator_for_radius, actuator_viscosity
from passmd.protocols import critical_amplitude, ringing
from passmd.protocols.velocity import steady_run
from passmd.runtime import sweep
from passmd.runtime.config import RunConfig
from passmd.runtime.validation import check_choice, check_count, check_range
from passmd.solver import simulation, steps

#: Configurations the numerics are shown for: (label, contacts, actuator model).
CONFIGURATIONS = (
    ("one contact, rigid", 1, "rigid"),
    ("one contact, flexible", 1, "flexible"),
    ("six contacts, rigid", 6, "rigid"),
    ("six contacts, flexible", 6, "flexible"),
)

#: Refinement factors of the default step (1 = the default).
RESOLUTIONS = {"quick": (0.5, 1.0, 2.0, 4.0), "paper": (0.25, 0.5, 1.0, 2.0, 4.0, 8.0)}


#: Step controls of :func:`convergence_study` by name: the integration schemes
#: (:data:`passmd.solver.steps.SCHEMES`) it compares.
STEP_CONTROLS = {
    "controlled": steps.SCHEMES["controlled"],  # the default: error-controlled steps
    "adaptive": steps.SCHEMES["adaptive"],  # explicit adaptive step (fine while ringing, coarse after)
    "quasi-static": steps.SCHEMES["quasi-static"],  # m_a neglected, fixed runner step
    "fixed": steps.SCHEMES["fixed"],  # the fine step throughout: the reference scheme
}
#: Step controls that differ for rigid actuators (they have no actuator mode to adapt to: their
#: explicit adaptive and quasi-static steps are the fixed one).
RIGID_STEP_CONTROLS = ("controlled", "fixed")
#: The step control whose finest run is a configuration's reference, by actuator model: the fixed
#: fine step (rigid) and the explicit adaptive step (flexible: there the fixed fine step runs only
#: up to resolution 2; how closely the two agree is ``adaptive_vs_fixed_nm`` of
#: :func:`~passmd.experiments.model_numerics.facts.convergence_facts`).
REFERENCE_CONTROL = {"rigid": "fixed", "flexible": "adaptive"}


def convergence_point(contacts: int, actuator_model: str, step_control: str, resolution: float,
                      amplitude: float, frequency: float, periods: int, preload: float,
                      hemisphere_radius: float) -> dict:
    """One run of :func:`convergence_study`: the saw-tooth run's steps and final position (SI)."""
    drive = Drive(hemisphere_radius=hemisphere_radius, preload=preload, contacts=contacts,
                  actuator_model=actuator_model)
    wf = waveforms.sawtooth(amplitude, frequency, drive, periods=periods)
    scheme = STEP_CONTROLS[step_control].replace(refine=resolution)
    res = simulation.simulate(drive, wf, scheme=scheme, max_points=2)
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
    scheme: str = "controlled",
) -> pd.DataFrame:
    """Energy balance W_in = E_kin + E_el + W_contact + W_damp of each configuration.

    Runs :func:`passmd.solver.simulation.simulate` at ``resolution`` with the exact contact and with
    the discrete contact (:data:`passmd.model.defaults.PROTOCOL` ``.springs`` springs), with
    ``scheme`` (:data:`passmd.solver.steps.SCHEMES`; the chapter compares the default,
    error-controlled one with the explicit "adaptive" one: the fixed fine step for rigid
    actuators, adaptive for flexible ones).
    """
    scheme = steps.resolve_scheme(scheme).replace(refine=resolution)
    rows = []
    for label, contacts, model in CONFIGURATIONS:
        drive = Drive(contacts=contacts, actuator_model=model)
        wf = waveforms.sawtooth(amplitude, frequency, drive, periods=periods)
        for contact in ("exact", "discrete"):
            res = simulation.simulate(drive, wf, contact_model=contact, springs=PROTOCOL.springs,
                                      max_points=2, scheme=scheme, energy=True)
            bal = res.energy_balance()
            rows.append({"configuration": label, "contact_model": contact, **bal})
    return pd.DataFrame(rows)


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
            res = simulation.simulate(drive, wf, max_points=2)
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
    return drive.replace(hemisphere_material=Material(h.youngs_modulus * k, h.poissons_ratio, h.name),
                         runner_material=Material(r.youngs_modulus * k, r.poissons_ratio, r.name),
                         actuator=drive.actuator, allow_extrapolation=True)


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
                res = simulation.simulate(drive, wf, max_points=2,
                                        scheme=steps.SCHEMES["fixed"].replace(refine=resolution))
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
# The actuator mass: what Table 2's printed m_a does, against heavier actuators
# --------------------------------------------------------------------------------------

#: Density of corundum (Al₂O₃), of which ruby is a variety (kg/m³; handbook value, not the paper's):
#: a hemisphere's own mass, (2/3)πR³ρ, is a lower bound on a real actuator's moving mass.
RUBY_DENSITY = 3980.0
#: The drive of the actuator-mass study: Fig. 6b's six contacts, flexible actuators, R = 1 mm, 0.4 N.
MASS_STUDY_DRIVE = {"hemisphere_radius": 1.0e-3, "preload": 0.4}
#: Factors on Table 2's printed m_a (R = 1 mm) per profile: from the printed 2.2e-5 g to a thousand times
#: it (22 mg); a ruby hemisphere's own mass is added to each grid.
MASS_FACTORS = {"quick": (1.0, 10.0, 100.0, 1000.0), "paper": tuple(10.0 ** (k / 2) for k in range(7))}
#: Saw-tooth frequencies of the study's steady velocities (Hz): the critical amplitude's 100 Hz and the
#: paper's 110 kHz limit of control (Section 5.2), with the frequencies between them on the paper profile.
MASS_FREQUENCIES = {"quick": (PROTOCOL.drive_frequency, 110e3),
                    "paper": (PROTOCOL.drive_frequency, 10e3, 50e3, 80e3, 100e3, 110e3, 130e3)}
#: Fly-back rules the study's critical amplitude is searched with (at the full stroke both take the same
#: time, so the velocities and the ringing are the same under either).
MASS_FLYBACKS = ("slew", "fixed")


#: The ledger's claim whose tolerance the actuator-mass study applies: Fig. 6b's A_c against Eq. 12.
MASS_STUDY_CLAIM = "fig6b-flexible-r1-ac-matches-eq12"


def mass_study_tolerance() -> float:
    """Relative tolerance of the ledger's claim :data:`MASS_STUDY_CLAIM` (claims.csv), which the
    actuator-mass study holds each A_c to."""
    claim = load_claims().set_index("id").loc[MASS_STUDY_CLAIM]
    if claim["tolerance_kind"] != "rel":
        raise ValueError(f"claim {MASS_STUDY_CLAIM!r} has tolerance_kind = {claim['tolerance_kind']!r}: the "
                         "study compares relative deviations ('rel')")
    return float(claim["tolerance_num"])


def hemisphere_mass(hemisphere_radius: float = MASS_STUDY_DRIVE["hemisphere_radius"]) -> float:
    """Mass (kg) of one ruby hemisphere of radius R: (2/3)πR³ρ with :data:`RUBY_DENSITY`."""
    radius = check_range("hemisphere_radius", hemisphere_radius, 0.0, lower_open=True, unit="m")
    return 2.0 / 3.0 * np.pi * radius**3 * RUBY_DENSITY


def actuator_masses(profile: str) -> np.ndarray:
    """The study's actuator masses (kg): :data:`MASS_FACTORS` times Table 2's m_a and a ruby
    hemisphere's mass, sorted."""
    check_choice("profile", profile, tuple(MASS_FACTORS))
    printed = actuator_for_radius(MASS_STUDY_DRIVE["hemisphere_radius"]).mass
    return np.array(sorted([printed * k for k in MASS_FACTORS[profile]] + [hemisphere_mass()]))


def mass_study_drive(actuator_mass: float, hemisphere_radius: float, preload: float) -> Drive:
    """Fig. 6b's drive (six flexible contacts, Table 2) with the actuator mass ``actuator_mass`` (kg) and
    its viscosity for the same damping ratio ζ (c_p = 2ζ√(k_p m_a)). Masses beyond the plausible range
    are allowed: this study explores them."""
    table2 = actuator_for_radius(hemisphere_radius)
    actuator = Actuator(stiffness=table2.stiffness, mass=actuator_mass,
                        viscosity=actuator_viscosity(table2.stiffness, actuator_mass),
                        full_stroke_amplitude=table2.full_stroke_amplitude)
    return Drive(hemisphere_radius=hemisphere_radius, preload=preload, actuator=actuator,
                 allow_extrapolation=True)


def actuator_mass_point(actuator_mass: float, hemisphere_radius: float, preload: float,
                        frequencies: tuple) -> dict:
    """One mass of :func:`actuator_mass_study`: the steady-state A_c under each fly-back rule
    (:data:`MASS_FLYBACKS`) and Eq. 12's, the actuator's natural frequencies (bare, and on each side's
    contact stiffness 2aG*), the runner's ringing after a full-stroke fly-back
    (:func:`passmd.protocols.ringing.stick_ringing`) and the saw-tooth's steady velocity at the full
    stroke at each of ``frequencies`` (SI)."""
    drive = mass_study_drive(actuator_mass, hemisphere_radius, preload)
    closed = theory.drive_theory(drive)
    stroke = drive.actuator.full_stroke_amplitude
    out = {"eq12_m": closed["critical_amplitude_flexible_m"],
           "actuator_frequency_Hz": drive.actuator.natural_frequency,
           "ringing_frequency_Hz": ringing.stick_ringing(drive, stroke)["ringing_frequency_Hz"]}
    for side, k_contact in enumerate(closed["tangential_stiffness_N_per_m"], start=1):
        out[f"actuator_on_contact_{side}_Hz"] = float(
            np.sqrt((drive.actuator.stiffness + k_contact) / actuator_mass) / (2 * np.pi))
    for rule in MASS_FLYBACKS:
        found = critical_amplitude.critical_amplitude(drive, flyback=rule)
        out[f"critical_amplitude_{rule}_m"] = found["critical_amplitude_m"]
    out["velocity_m_per_s"] = np.array([steady_run(drive, stroke, f, "sawtooth", "")["velocity_m_per_s"]
                                        for f in frequencies])
    return out


def actuator_mass_study(config: RunConfig) -> pd.DataFrame:
    """A_c, ringing frequencies and velocity of Fig. 6b's drive against the actuator mass
    (:func:`actuator_masses`): one row per mass and frequency of :data:`MASS_FREQUENCIES` (the mass's
    scalars repeated), with ``printed`` (Table 2's m_a) and ``hemisphere`` (a ruby hemisphere's mass)
    marking those rows; display columns in nm, kHz, µg and mm/s."""
    frequencies = tuple(float(f) for f in MASS_FREQUENCIES[config.profile])
    points = [{"actuator_mass": float(m), **MASS_STUDY_DRIVE, "frequencies": frequencies}
              for m in actuator_masses(config.profile)]
    runs = sweep.run(actuator_mass_point, points, description="actuator mass", config=config)
    printed = actuator_for_radius(MASS_STUDY_DRIVE["hemisphere_radius"]).mass
    rows = []
    for _, run in runs.iterrows():
        scalars = {k: run[k] for k in runs.columns if k not in ("velocity_m_per_s", "frequencies")}
        for f, v in zip(frequencies, np.asarray(run["velocity_m_per_s"]), strict=True):
            rows.append({**scalars, "frequency_Hz": f, "velocity_m_per_s": float(v)})
    table = pd.DataFrame(rows)
    table["printed"] = np.isclose(table["actuator_mass"], printed, rtol=1e-9, atol=0)
    table["hemisphere"] = np.isclose(table["actuator_mass"], hemisphere_mass(), rtol=1e-9, atol=0)
    table["actuator_mass_ug"] = table["actuator_mass"] * 1e9
    for column in ("eq12_m", *(f"critical_amplitude_{rule}_m" for rule in MASS_FLYBACKS)):
        table[column[:-2] + "_nm"] = table[column] * 1e9
    table["frequency_kHz"] = table["frequency_Hz"] / 1e3
    table["velocity_mm_per_s"] = table["velocity_m_per_s"] * 1e3
    table["eq12_tolerance_rel"] = mass_study_tolerance()
    return table


#: The chapter's rows of the figure table.
FIGURES = (
    FigureSpec("model_convergence", "Time-step convergence of the runner position after three periods",
               "model_numerics", model_convergence, "numerics:plot_convergence"),
    FigureSpec("model_coulomb_limit", "Simulated step against the rigid Coulomb limit, stiffened contacts",
               "model_numerics", model_coulomb_limit, "numerics:plot_coulomb_limit"),
    FigureSpec("model_actuator_mass", "Critical amplitude, ringing frequencies and velocity against the "
               "actuator mass, 22 µg to 22 mg", "model_numerics", actuator_mass_study,
               "numerics:plot_actuator_mass"),
)
