"""Physics and numerics of the hybrid simulator (passmd.solver.simulation).

Runs are kept short (1 kHz drive, few periods) so the whole file takes seconds; the
physics checked does not depend on the drive frequency being the paper's.
"""

import numpy as np
import pytest

from passmd.model import theory, waveforms
from passmd.model.contact import contact_arrays, contact_stiffness, stack_contacts
from passmd.model.parameters import Drive
from passmd.solver import simulation, steps
from passmd.solver.results import SimulationError
from passmd.solver.setup import contact_groups
from passmd.solver.steps import SCHEMES

F_TEST = 1000.0  # Hz: 1 ms periods keep tests fast; the runner mode (~5-11 kHz) settles within


def one_contact(model="rigid", **kw):
    return Drive(contacts=1, actuator_model=model, **kw)


def presliding(drive):
    return theory.drive_theory(drive)["presliding_m"][0]


def run(drive, amplitude, periods=4, frequency=F_TEST, **kw):
    wf = waveforms.sawtooth(amplitude, frequency, drive, periods=periods)
    return simulation.simulate(drive, wf, **kw)


def test_rigid_one_contact_no_step_below_presliding():
    d = one_contact()
    res = run(d, 0.5 * presliding(d))
    # micro-slip only, no net step: what remains is the settled position's averaging error
    # over the runner's undamped micro-vibration (≈ 0.1 nm here); 2 % of u_x,max (0.8 nm) is
    # far below a step that full sliding makes (≥ 0.5 u_x,max, next test)
    assert np.max(np.abs(res.step_sizes)) < 0.02 * presliding(d)


def test_rigid_one_contact_step_grows_one_for_one_above_presliding():
    d = one_contact()
    u = presliding(d)
    s3 = run(d, 3 * u).step_sizes[-1]
    s4 = run(d, 4 * u).step_sizes[-1]
    assert s3 > 0.5 * u
    # steady step = A − (a constant set by the contact): slope 1 within 2 % (micro-vibration phase)
    assert (s4 - s3) / u == pytest.approx(1.0, rel=0.02)


@pytest.mark.parametrize("model", ["rigid", "flexible"])
def test_mirrored_waveform_mirrors_motion(model):
    d = one_contact(model)
    wf = waveforms.sawtooth(3 * presliding(d), F_TEST, d, periods=3)
    fwd = simulation.simulate(d, wf)
    back = simulation.simulate(d, wf.mirrored())
    # the exact contact is odd in u, so the mirrored run is the negated run up to rounding
    np.testing.assert_allclose(back.settled_positions, -fwd.settled_positions, rtol=1e-9, atol=1e-18)


def test_six_contacts_do_not_rely_on_shared_side_state():
    d = Drive(actuator_model="flexible")
    wf = waveforms.sawtooth(120e-9, F_TEST, d, periods=3)
    shared = simulation.simulate(d, wf)
    separate = simulation.simulate(d, wf, share_side_state=False)
    # same physics, six states instead of two: only summation order differs
    np.testing.assert_allclose(separate.settled_positions, shared.settled_positions, rtol=1e-9, atol=1e-15)


def _dominant_frequency(t, x):
    x = x - x.mean()
    crossings = np.flatnonzero(np.diff(np.signbit(x)))
    # linear interpolation of the crossing times
    tc = t[crossings] - x[crossings] * (t[crossings + 1] - t[crossings]) / (x[crossings + 1] - x[crossings])
    return 0.5 / np.mean(np.diff(tc))


def test_linear_limit_rigid_runner_frequency():
    """μ → large: no slip; after the fly-back the runner rings at √(2aG*/m_r)/2π."""
    d = one_contact(friction_coefficient=1e4, allow_extrapolation=True)  # beyond μ = 1: a numerical device
    res = run(d, 20e-9, periods=1, frequency=200.0, max_points=200001)
    t, x = res.time, res.runner_position - res.piezo_position
    sel = (t > 0.5 * res.waveform.period) & (t < 0.95 * res.waveform.period)  # ramp, before the fly-back
    f = _dominant_frequency(t[sel], x[sel])
    assert f == pytest.approx(theory.runner_frequency(d), rel=0.01)  # Cattaneo-Mindlin slope at |u| << u_max


def test_linear_limit_flexible_two_mass_oscillator():
    """μ → large, flexible actuator: the slow mode of the 2-DOF system (m_r on k_c, k_c in series
    with the actuator k_p and m_a) from the eigenvalues of the linear system."""
    d = one_contact("flexible", friction_coefficient=1e4, allow_extrapolation=True)
    res = run(d, 20e-9, periods=1, frequency=200.0, max_points=200001)
    k_c = theory.drive_theory(d)["tangential_stiffness_N_per_m"][0]
    a = d.actuator
    M = np.diag([d.runner_mass, a.mass])
    K = np.array([[k_c, -k_c], [-k_c, k_c + a.stiffness]])
    w2 = np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real)
    f_slow = np.sqrt(w2[0]) / (2 * np.pi)
    t, x = res.time, res.runner_position - res.piezo_position
    sel = (t > 0.5 * res.waveform.period) & (t < 0.95 * res.waveform.period)
    assert _dominant_frequency(t[sel], x[sel]) == pytest.approx(f_slow, rel=0.01)


@pytest.mark.parametrize("model", ["rigid", "flexible"])
def test_time_step_convergence(model):
    """Halving the step changes the 3-period step size by < 0.5 % (model chapter: convergence shown)."""
    d = Drive(contacts=1, actuator_model=model)
    wf = waveforms.sawtooth(120e-9, F_TEST, d, periods=3)
    coarse = simulation.simulate(d, wf).final_position
    fine = simulation.simulate(d, wf, scheme=SCHEMES["controlled"].replace(refine=2.0)).final_position
    assert abs(fine - coarse) < 0.005 * abs(fine)


@pytest.mark.parametrize(
    "model,contact", [("rigid", "exact"), ("flexible", "exact"), ("flexible", "discrete")]
)
def test_energy_balance(model, contact):
    """W_in = E_kin + E_el + Σ∫T du + W_damp; the residual is the integrator's O(dt²) error."""
    d = Drive(actuator_model=model)
    wf = waveforms.sawtooth(120e-9, F_TEST, d, periods=2)
    res = simulation.simulate(d, wf, contact_model=contact, springs=200, energy=True)
    bal = res.energy_balance()
    assert bal["input_work"] > 0 and bal["contact_work"] > 0
    assert abs(bal["relative_residual"]) < 1e-3


@pytest.mark.parametrize("contacts,model", [(1, "rigid"), (1, "flexible"), (6, "rigid"), (6, "flexible")])
def test_error_controlled_energy_balance_at_100_hz(contacts, model):
    """Three 100 Hz periods, where the runner rings for milliseconds in long error-controlled
    steps, at the smallest and the largest amplitude of the figures: the default step closes
    the balance (exact contact) to 1e-5 and to no worse than the explicit schemes' residual on
    the same run, or 1e-6, whichever is larger. Both bounds failed by one to two orders of
    magnitude while the velocity update took the rest force linear over the step and the work
    terms were summed with the trapezoidal rule (up to 3.6e-4 at 20 nm)."""
    d = Drive(contacts=contacts, actuator_model=model)
    for amplitude in (20e-9, 202e-9):
        default = run(d, amplitude, periods=3, frequency=100.0, max_points=2, energy=True)
        explicit = run(d, amplitude, periods=3, frequency=100.0, max_points=2, scheme="adaptive", energy=True)
        residual = abs(default.energy_balance()["relative_residual"])
        reference = abs(explicit.energy_balance()["relative_residual"])
        assert residual < 1e-5, (amplitude, residual)
        assert residual <= max(reference, 1e-6), (amplitude, residual, reference)


def test_divergence_is_reported(monkeypatch):
    d = one_contact("flexible")
    wf = waveforms.sawtooth(100e-9, F_TEST, d, periods=1)
    plan_dt = steps.step_plan(d, 3e6, 3e6).stability_limit
    monkeypatch.setattr("passmd.solver.setup.STABILITY_MARGIN", 100.0)  # let an unstable step through
    with pytest.raises(SimulationError, match=r"diverged at integrator step \d+.*time step"):
        simulation.simulate(d, wf, scheme=SCHEMES["fixed"].replace(dt=5 * plan_dt))


def test_kernel_wrapper_refuses_a_wrong_array_naming_it(monkeypatch):
    """The compiled loop does no bounds checks: its Python wrapper checks every array first."""
    from passmd.solver import kernels

    seen = []
    integrate = kernels.integrate

    def capture(*args, **kwargs):
        seen.append(args)
        return integrate(*args, **kwargs)

    monkeypatch.setattr(kernels, "integrate", capture)
    run(one_contact(), 50e-9, periods=1)
    segments, mechanics, control, contacts, buffers, limit = seen[0][:6]  # (then: checked by the caller)
    narrow = buffers._replace(per=np.zeros((1, kernels.PER_COLUMNS - 1)))
    with pytest.raises(ValueError, match=r"buffers\.per has shape \(1, 7\), must be \(1, 8\)"):
        integrate(segments, mechanics, control, contacts, narrow, limit)
    ints = segments._replace(t0=segments.t0.astype(np.int64))
    with pytest.raises(ValueError, match=r"segments\.t0 must be a C-contiguous float64 array"):
        integrate(ints, mechanics, control, contacts, buffers, limit)
    with pytest.raises(ValueError, match=r"mechanics = \(1\.0,\) is not a Mechanics"):
        integrate(segments, (1.0,), control, contacts, buffers, limit)


def test_bad_inputs():
    d = one_contact()
    with pytest.raises(ValueError, match=r"^amplitude = -1e-08 is out of range"):
        waveforms.sawtooth(-10e-9, F_TEST, d)
    with pytest.raises(ValueError, match=r"^frequency = -5.0 is out of range"):
        waveforms.sawtooth(10e-9, -5.0, d)
    with pytest.raises(ValueError, match=r"monotone in time"):
        waveforms.piecewise_linear([0, 6e-4, 4e-4, 1e-3], [0, 1e-8, 2e-8, 0], F_TEST, 1, (1e-4, 2e-4), 6e-4)
    wf = waveforms.sawtooth(10e-9, F_TEST, d)
    with pytest.raises(ValueError, match=r"^dt = 1e-05 is out of range: .*stable"):
        simulation.simulate(one_contact("flexible"), wf, scheme=SCHEMES["fixed"].replace(dt=1e-5))
    with pytest.raises(ValueError, match=r"^contact_model = 'soft'"):
        simulation.simulate(d, wf, contact_model="soft")
    with pytest.raises(ValueError, match=r"^frequency = 400000.0 is out of range"):
        waveforms.sawtooth(202e-9, 4e5, Drive())


@pytest.mark.parametrize("model", ["rigid", "flexible"])
@pytest.mark.parametrize("name", list(SCHEMES))
def test_every_scheme_runs_and_agrees(model, name):
    """Each named scheme integrates a 2-period run to within the converged accuracy
    (steps.CONVERGED_ACCURACY) of the fixed fine step; error control rejects steps only
    where it is on."""
    d = one_contact(model)
    wf = waveforms.sawtooth(150e-9, F_TEST, d, periods=2)
    ref = simulation.simulate(d, wf, scheme="fixed", max_points=2)
    res = simulation.simulate(d, wf, scheme=name, max_points=2)
    np.testing.assert_allclose(res.settled_positions, ref.settled_positions, rtol=0,
                               atol=steps.CONVERGED_ACCURACY)
    if not SCHEMES[name].error_control:
        assert res.rejected_steps == 0
    assert res.fine_step == ref.fine_step
    if name != "fixed" and model == "flexible":
        assert res.steps < ref.steps / 2  # the quiet phases take longer steps


def test_bad_scheme_is_one_line_naming_it():
    d = one_contact()
    wf = waveforms.sawtooth(50e-9, F_TEST, d, periods=1)
    with pytest.raises(ValueError) as err:
        simulation.simulate(d, wf, scheme="verlet")
    message = str(err.value)
    assert message == ("scheme = 'verlet' is not allowed: must be one of 'controlled', 'reference', "
                       "'adaptive', 'quasi-static', 'fixed' or a passmd.solver.steps.Scheme")
    with pytest.raises(ValueError, match=r"^dt = 1e-09 is not allowed with scheme 'adaptive'"):
        SCHEMES["adaptive"].replace(dt=1e-9)
    with pytest.raises(ValueError, match=r"^refine = -2.0 is out of range"):
        SCHEMES["controlled"].replace(refine=-2.0)


def test_summary_keys_and_units():
    d = Drive(load_cell=True)
    res = run(d, 150e-9, periods=3)
    s = res.summary()
    assert {"final_position_m", "step_sizes_m", "mean_velocity_m_per_s", "generated_force_N"} <= set(s)
    assert len(s["step_sizes_m"]) == 2
    assert s["generated_force_N"] == pytest.approx(2.5e4 * res.period_mean_position[-1], rel=1e-12)


def test_default_step_converged_to_005_nm():
    """The benchmark's 'converged accuracy' (CONVERGED_ACCURACY, 0.05 nm): the 3-period position
    at 100 Hz of the default scheme (error-controlled, default tolerance) and of the explicit
    steps at their default step (adaptive for flexible actuators, fixed for rigid ones) is
    within it of the reference, the fixed (rigid) or explicit adaptive (flexible) step 4×
    finer: that run's O(dt²) error is 16× smaller than at the default step, so it stands in
    for dt → 0."""
    from passmd.experiments.model_numerics.figures import convergence_study

    df = convergence_study(resolutions=(1.0, 4.0), step_controls=("controlled", "adaptive"))
    default = df[df["resolution"] == 1.0]
    assert set(default["step_control"]) == {"controlled", "adaptive", "fixed"}
    assert len(default[default["step_control"] == "controlled"]) == 4  # every configuration
    assert (default["error_m"].abs() < steps.CONVERGED_ACCURACY).all(), default


def test_contact_memory_never_overflows_in_a_100_hz_period():
    """A 10 ms stick phase of runner micro-vibration records hundreds of nested reversals;
    the exact contact's stack must hold them (an overflow would forget a minor loop)."""
    d = Drive(actuator_model="flexible")
    res = run(d, 150e-9, periods=2, frequency=100.0)
    assert res.summary()["contact_memory_overflows"] == 0
    assert max(m["max_depth"] for m in res.contact_memory) > 2


# --------------------------------------------------------------------------------------
# bounded work: chunked kernel calls, refusal before the start
# --------------------------------------------------------------------------------------

FIELDS = ("time", "runner_position", "runner_velocity", "actuator_position", "friction_force",
          "slip_share", "settled_positions", "back_steps", "peak_force_ratio", "period_mean_position",
          "period_mean_friction", "final_state")


@pytest.mark.parametrize("model", ["rigid", "flexible"])
@pytest.mark.parametrize("contacts", [1, 6])
@pytest.mark.parametrize("scheme", ["controlled", "reference", "adaptive"])
def test_chunked_run_is_bit_identical(monkeypatch, model, contacts, scheme):
    """The kernel pauses every CHUNK_STEPS steps (also inside a waveform piece) and resumes
    from its carried state: the run must be the uninterrupted run to the last bit."""
    d = Drive(actuator_model=model, contacts=contacts)
    wf = waveforms.sawtooth(150e-9, F_TEST, d, periods=3)
    whole = simulation.simulate(d, wf, max_points=3000, scheme=scheme, energy=True)
    monkeypatch.setattr(simulation, "CHUNK_STEPS", 997)  # prime: pauses land everywhere
    chunked = simulation.simulate(d, wf, max_points=3000, scheme=scheme, energy=True)
    assert chunked.steps == whole.steps and chunked.fine_steps == whole.fine_steps
    assert chunked.rejected_steps == whole.rejected_steps
    for name in FIELDS:
        np.testing.assert_array_equal(getattr(chunked, name), getattr(whole, name), err_msg=name)
    assert chunked.energy == whole.energy
    assert chunked.contact_memory == whole.contact_memory


#: Per-period measures and end state of a run (the recorded samples are spaced over the whole
#: waveform, so they differ between a run stopped early and a shorter waveform).
PERIOD_FIELDS = ("settled_positions", "back_steps", "peak_force_ratio", "period_mean_position",
                 "period_mean_friction", "final_state")


@pytest.mark.parametrize("model, contacts, scheme", [
    ("rigid", 1, "controlled"), ("rigid", 6, "controlled"), ("flexible", 1, "controlled"),
    ("flexible", 6, "controlled"), ("flexible", 6, "reference"), ("flexible", 6, "quasi-static")])
def test_continued_simulation_is_the_shorter_run(monkeypatch, model, contacts, scheme):
    """A saw-tooth run stopped after n periods is the n-period run to the last bit, and running
    on (in several calls, with pauses anywhere) gives the run of the whole waveform."""
    monkeypatch.setattr(simulation, "CHUNK_STEPS", 997)  # pauses also inside pieces
    d = Drive(actuator_model=model, contacts=contacts)
    wave = waveforms.sawtooth(150e-9, F_TEST, d, periods=5)
    sim = simulation.Simulation(d, wave, max_points=3000, scheme=scheme, energy=True)
    sim.run_to(2)
    early = sim.result()
    kept = {name: getattr(early, name).copy() for name in PERIOD_FIELDS}
    short = simulation.simulate(d, waveforms.sawtooth(150e-9, F_TEST, d, periods=2), max_points=3000,
                                scheme=scheme, energy=True)
    np.testing.assert_array_equal(early.waveform.times, short.waveform.times)
    np.testing.assert_array_equal(early.waveform.positions, short.waveform.positions)
    np.testing.assert_array_equal(early.waveform.settle_windows, short.waveform.settle_windows)
    assert early.waveform.periods == 2 and early.waveform.amplitude == short.waveform.amplitude
    assert (early.steps, early.fine_steps) == (short.steps, short.fine_steps)
    for name in PERIOD_FIELDS:
        np.testing.assert_array_equal(getattr(early, name), getattr(short, name), err_msg=name)
    assert early.energy == short.energy and early.contact_memory == short.contact_memory
    sim.run_to(3)
    sim.run_to(3)  # already there: nothing to do
    sim.run_to(5)
    whole = simulation.simulate(d, wave, max_points=3000, scheme=scheme, energy=True)
    continued = sim.result()
    assert continued.waveform is wave and continued.steps == whole.steps
    for name in FIELDS:
        np.testing.assert_array_equal(getattr(continued, name), getattr(whole, name), err_msg=name)
    assert continued.energy == whole.energy
    for name, value in kept.items():  # a result returned earlier does not change
        np.testing.assert_array_equal(getattr(early, name), value, err_msg=name)


def test_continued_simulation_bad_use():
    d = one_contact()
    sim = simulation.Simulation(d, waveforms.sawtooth(50e-9, F_TEST, d, periods=3))
    with pytest.raises(ValueError, match=r"call run_to first"):
        sim.result()
    with pytest.raises(ValueError, match=r"^periods = 4 is out of range: the waveform has 3 periods"):
        sim.run_to(4)
    with pytest.raises(ValueError, match=r"^periods = 0 is out of range"):
        sim.run_to(0)


def test_continued_simulation_is_refused_as_the_shorter_run(monkeypatch):
    """The step budget applies to the periods asked for, as to a waveform of that length."""
    d = one_contact()
    monkeypatch.setattr(steps, "MAX_STEPS", 5000.0)  # ≈ 2070 steps per period: 2 periods fit
    sim = simulation.Simulation(d, waveforms.sawtooth(20e-9, F_TEST, d, periods=3))
    sim.run_to(2)
    with pytest.raises(steps.WorkLimitError, match=r"\(--periods\) = 3 must be <= 2"):
        sim.run_to(3)
    assert sim.periods_done == 2


@pytest.mark.parametrize("scheme", ["adaptive", "controlled"])
def test_expected_steps_match_the_run(scheme):
    """The pre-run estimate is exact for fixed steps and a close lower bound when adaptive;
    error-controlled runs take fewer steps than it (it counts their uncontrolled steps)."""
    for model in ("rigid", "flexible"):
        d = Drive(actuator_model=model)
        wf = waveforms.sawtooth(202e-9, 100.0, d, periods=1)
        res = simulation.simulate(d, wf, scheme=scheme)
        E, G = theory.contact_moduli(d)
        forces, mult = contact_groups(d)
        rows = [contact_arrays("exact", F, d.hemisphere_radius, E, G, d.friction_coefficient) for F in forces]
        params, _ = stack_contacts(rows)
        ks = np.array([contact_stiffness(params[g]) for g in range(len(rows))])
        plan = steps.step_plan(d, ks.max(), float(np.sum(mult * ks)))
        est = steps.expected_steps(wf, plan, res.fine_step, res.coarse_step).sum()
        if scheme == "controlled":
            assert res.steps < est
            continue
        # rigid: every step is planned; flexible: ringing after the slip adds fine steps (< 2 %)
        assert est <= res.steps
        assert est == pytest.approx(res.steps, rel=0.02 if model == "flexible" else 1e-6)


def test_run_beyond_the_step_budget_is_refused_before_it_starts(monkeypatch):
    d = one_contact()
    wf = waveforms.sawtooth(20e-9, F_TEST, d, periods=3)
    monkeypatch.setattr(steps, "MAX_STEPS", 5000.0)  # ≈ 2070 steps per period: 2 periods fit
    refused = r"budget of 5e\+03 steps .*\(--periods\) = 3 must be <= 2"
    with pytest.raises(steps.WorkLimitError, match=refused):
        simulation.simulate(d, wf)
    monkeypatch.setattr(steps, "MAX_STEPS", 10.0)  # not even one period fits: name the step
    with pytest.raises(steps.WorkLimitError, match=r"runner_mass \(--runner-mass\)"):
        simulation.simulate(d, wf)


def test_step_below_the_time_resolution_is_refused():
    d = one_contact()
    # a 1e-18 m saw-tooth flies back in 1e-17 s: 40 steps of 2.5e-19 s cannot advance t ≈ 1 ms
    wf = waveforms.sawtooth(1e-18, F_TEST, d, periods=2)
    with pytest.raises(steps.WorkLimitError, match=r"float spacings of t .*--amplitude.*--slew-rate"):
        simulation.simulate(d, wf)
    light = one_contact(runner_mass=1e-33, allow_extrapolation=True)  # past the plausible range on purpose
    with pytest.raises(steps.WorkLimitError, match=r"runner_mass \(--runner-mass\) = 1e-33"):
        simulation.simulate(light, waveforms.sawtooth(20e-9, F_TEST, light, periods=2))
    flexible = one_contact("flexible")
    with pytest.raises(steps.WorkLimitError, match=r"dt = 1e-22 s"):
        simulation.simulate(flexible, waveforms.sawtooth(20e-9, F_TEST, flexible, periods=2),
                          scheme=SCHEMES["fixed"].replace(dt=1e-22))


def test_progress_bar_on_request(monkeypatch, capsys):
    d = one_contact()
    wf = waveforms.sawtooth(20e-9, F_TEST, d, periods=3)
    monkeypatch.setattr(simulation, "CHUNK_STEPS", 500)
    simulation.simulate(d, wf, progress=True)
    assert "period" in capsys.readouterr().err
    simulation.simulate(d, wf)  # default: a short run, and stderr is not a terminal here
    assert capsys.readouterr().err == ""


# --------------------------------------------------------------------------------------
# quasi-static actuator step (opt-in)
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("contacts", [1, 6])
@pytest.mark.parametrize("contact", ["exact", pytest.param("discrete", marks=pytest.mark.slow)])
def test_quasi_static_step_matches_the_fixed_fine_step(contacts, contact):
    """Settled position after 3 periods at 100 Hz within 0.05 nm of the fixed fine step
    (the reference scheme), at the full stroke where the slips are largest."""
    d = Drive(contacts=contacts, actuator_model="flexible")
    wf = waveforms.sawtooth(202e-9, 100.0, d, periods=3)
    ref = simulation.simulate(d, wf, scheme="fixed", contact_model=contact, max_points=2)
    quasi = simulation.simulate(d, wf, contact_model=contact, max_points=2, scheme="quasi-static",
                                energy=True)
    assert quasi.steps < ref.steps / 50
    np.testing.assert_allclose(quasi.settled_positions, ref.settled_positions, rtol=0, atol=0.05e-9)
    assert abs(quasi.energy_balance()["relative_residual"]) < 1e-4


def test_quasi_static_step_chunked_is_bit_identical(monkeypatch):
    d = Drive(actuator_model="flexible")
    wf = waveforms.sawtooth(150e-9, F_TEST, d, periods=3)
    whole = simulation.simulate(d, wf, max_points=3000, scheme="quasi-static", energy=True)
    monkeypatch.setattr(simulation, "CHUNK_STEPS", 997)
    chunked = simulation.simulate(d, wf, max_points=3000, scheme="quasi-static", energy=True)
    for name in FIELDS:
        np.testing.assert_array_equal(getattr(chunked, name), getattr(whole, name), err_msg=name)
    assert chunked.energy == whole.energy


def test_quasi_static_step_converges():
    """Halving the quasi-static step (resolution 2 → 4) shrinks the 3-period error roughly 4×
    (second order), measured against resolution 8."""
    d = Drive(contacts=1, actuator_model="flexible")
    wf = waveforms.sawtooth(150e-9, 100.0, d, periods=3)
    pos = {r: simulation.simulate(d, wf, scheme=SCHEMES["quasi-static"].replace(refine=r),
                                max_points=2).final_position
           for r in (1.0, 2.0, 8.0)}
    e1, e2 = abs(pos[1.0] - pos[8.0]), abs(pos[2.0] - pos[8.0])
    assert e1 < 0.05e-9
    assert e2 < e1 / 2.5  # order > 1.3; Verlet's 2 expected


# --------------------------------------------------------------------------------------
# error-controlled step (the default scheme)
# --------------------------------------------------------------------------------------

VARIANTS = [(contacts, model, contact) for contacts in (1, 6) for model in ("rigid", "flexible")
            for contact in ("exact", "discrete")]


@pytest.mark.parametrize("contacts, model, contact", [
    v if v[2] == "exact" or v[1] == "rigid" else pytest.param(*v, marks=pytest.mark.slow) for v in VARIANTS])
def test_error_controlled_step_matches_the_fixed_fine_step(contacts, model, contact):
    """Every model variant: settled positions over 3 periods at 100 Hz, full stroke (202 nm,
    where the slips are largest) within CONVERGED_ACCURACY (0.05 nm) of the fixed fine step,
    the reference scheme, with far fewer steps, and an energy balance closed to 1e-4."""
    d = Drive(contacts=contacts, actuator_model=model)
    wf = waveforms.sawtooth(202e-9, 100.0, d, periods=3)
    ref = simulation.simulate(d, wf, scheme="fixed", contact_model=contact, max_points=2)
    ctrl = simulation.simulate(d, wf, contact_model=contact, max_points=2, energy=True)
    assert ctrl.steps < ref.steps / 5
    np.testing.assert_allclose(ctrl.settled_positions, ref.settled_positions, rtol=0,
                               atol=steps.CONVERGED_ACCURACY)
    np.testing.assert_allclose(ctrl.back_steps, ref.back_steps, rtol=0, atol=steps.CONVERGED_ACCURACY)
    assert abs(ctrl.energy_balance()["relative_residual"]) < 1e-4


def test_error_controlled_step_converges():
    """Tightening the tolerance (resolution r divides it by r⁴, so the step by ≈ r) shrinks the
    3-period error against the fixed fine step at 4× resolution; at the default it is within
    CONVERGED_ACCURACY."""
    d = Drive(contacts=6, actuator_model="rigid")
    wf = waveforms.sawtooth(150e-9, 100.0, d, periods=3)
    ref = simulation.simulate(d, wf, scheme=SCHEMES["fixed"].replace(refine=4.0), max_points=2).final_position
    runs = {r: simulation.simulate(d, wf, scheme=SCHEMES["controlled"].replace(refine=r), max_points=2)
            for r in (0.5, 1.0, 2.0)}
    err = {r: abs(run.final_position - ref) for r, run in runs.items()}
    assert err[1.0] < steps.CONVERGED_ACCURACY
    assert err[2.0] < err[1.0] < err[0.5]
    assert runs[0.5].steps < runs[1.0].steps < runs[2.0].steps


def test_error_controlled_step_rejects_and_counts():
    """Steps whose error estimate exceeds the tolerance are retried shorter (the slip at each
    fly-back forces some); they are counted in ``steps`` and in ``rejected_steps``."""
    d = Drive(contacts=6, actuator_model="rigid")
    res = simulation.simulate(d, waveforms.sawtooth(150e-9, 100.0, d, periods=2), max_points=2)
    assert 0 < res.rejected_steps < res.steps / 2
    fixed = simulation.simulate(d, waveforms.sawtooth(150e-9, 100.0, d, periods=2), max_points=2,
                              scheme="adaptive")
    assert fixed.rejected_steps == 0


@pytest.mark.parametrize("model", ["rigid", "flexible"])
def test_error_controlled_samples_at_their_own_times(model):
    """Steps longer than the sampling interval are sampled inside (cubic Hermite in x_r): the
    samples lie on the uniform grid (rigid), and x_r, v_r there agree with the fixed fine step's
    samples to 0.05 nm and 1 % of the velocity range (linear interpolation of the fine
    samples, 1 µs apart, is itself accurate to a few pm at the ≈ 11 kHz ringing)."""
    d = Drive(contacts=6, actuator_model=model)
    wf = waveforms.sawtooth(150e-9, 100.0, d, periods=2)
    ref = simulation.simulate(d, wf, scheme="fixed", max_points=20001)
    ctrl = simulation.simulate(d, wf, max_points=20001)
    if model == "rigid":  # (flexible: samples in the fine steps after a corner are at step ends)
        np.testing.assert_allclose(np.diff(ctrl.time), wf.duration / 20000, rtol=1e-6)
    x = np.interp(ctrl.time, ref.time, ref.runner_position)
    v = np.interp(ctrl.time, ref.time, ref.runner_velocity)
    assert np.abs(ctrl.runner_position - x).max() < steps.CONVERGED_ACCURACY
    assert np.abs(ctrl.runner_velocity - v).max() < 0.01 * np.ptp(ref.runner_velocity)


def test_error_controlled_reversals_keep_the_contact_dissipation():
    """Reversals of u inside a step are committed at the interpolated extremum, so the work the
    contacts absorb over the ringing stick phases matches the fixed fine step's to 0.1 %
    (the Masing loops' dissipation grows with the cube of their amplitude)."""
    d = Drive(contacts=6, actuator_model="rigid")
    wf = waveforms.sawtooth(150e-9, 100.0, d, periods=3)
    ref = simulation.simulate(d, wf, scheme="fixed", max_points=2, energy=True)
    ctrl = simulation.simulate(d, wf, max_points=2, energy=True)
    assert ctrl.energy["contact"] == pytest.approx(ref.energy["contact"], rel=1e-3)
    assert sum(m["reversals"] for m in ctrl.contact_memory) > 0
