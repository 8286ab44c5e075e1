"""The optimized driving waveform of Section 5 (passmd.model.optimized_waveform) and its Eq. 15 design.

The paper's case: six contacts, rigid actuators, R = 1 mm, F_p = 0.4 N, μ = 0.2, A = 202 nm.
Rigid runs are cheap (≈ 0.2 µs steps), so the design (two 100 Hz saw-tooth periods) is
computed once per module.
"""

import numpy as np
import pytest

from passmd.model import theory, waveforms
from passmd.model.defaults import PROTOCOL
from passmd.model.optimized_waveform import (
    MIN_RAMP_FRACTION,
    OptimizedDesign,
    check_fits,
    highest_fitting_frequency,
    max_piezo_velocity,
    optimized,
    optimized_timing,
)
from passmd.model.parameters import paper_drive
from passmd.protocols import eq15
from passmd.solver import simulation

A = 202e-9  # m, the paper's full amplitude for R = 1 mm
#: The saw-tooth frequency of the design and of Fig. 9a (Hz).
F_STEP = PROTOCOL.drive_frequency


@pytest.fixture(scope="module")
def drive():
    return paper_drive(1e-3, 0.4, actuator_model="rigid")


@pytest.fixture(scope="module")
def design(drive):
    return eq15.optimized_design(A, drive)


def _slopes(wave):
    return np.diff(wave.positions) / np.diff(wave.times)


def test_micro_vibration_frequency_of_a_sine():
    t = np.linspace(0.0, 1e-3, 20001)
    f = 12345.0
    v = np.cos(2 * np.pi * f * t)
    f_s, crossings = eq15.micro_vibration_frequency(t, v, np.zeros_like(t), after=1e-5)
    # linear interpolation of zero crossings of a 81-samples-per-cycle cosine: error ~(Δt ω)²/24 ≈ 1e-4
    assert f_s == pytest.approx(f, rel=1e-4)
    assert crossings[0] > 1e-5


def test_micro_vibration_needs_three_turning_points():
    t = np.linspace(0.0, 1e-3, 1001)
    with pytest.raises(ValueError, match="no micro-vibration"):
        eq15.micro_vibration_frequency(t, np.ones_like(t), np.zeros_like(t), after=0.0)


def test_design_applies_eq15(design, drive):
    assert design.settling_time == pytest.approx(0.5 / design.micro_vibration_frequency, rel=1e-12)
    # (V_a − V_r) t_a = u_x,max exactly (arithmetic of the design)
    lhs = (design.acceleration_velocity - design.runner_velocity) * design.acceleration_time
    assert lhs == pytest.approx(design.presliding, rel=1e-12)
    assert design.presliding == pytest.approx(min(theory.drive_theory(drive)["presliding_m"]), rel=1e-12)
    # default free parameter: V_a at the amplifier's slew-rate limit
    assert design.acceleration_velocity == pytest.approx(max_piezo_velocity(drive), rel=1e-12)


def test_measured_micro_vibration_frequency_against_linear_estimate(design, drive):
    """f_s against √(Σ 2aG*/m_r)/2π (theory.runner_frequency).

    The linear estimate uses the contacts' initial tangential stiffness 2aG*. After a slip
    the contacts swing along Masing branches whose secant stiffness falls from 2aG* (small
    swing) to 2/3·2aG* (a swing across the whole presliding range, 2μF_N over 2u_x,max with
    slope 3μF_N/(2u_x,max) at the start). The restoring force of the swing lies between those
    two lines, so f_s lies between √(2/3) ≈ 0.816 and 1 times the linear estimate; 1 % above
    covers the zero-crossing interpolation.
    """
    ratio = design.micro_vibration_frequency / theory.runner_frequency(drive)
    assert np.sqrt(2.0 / 3.0) <= ratio <= 1.01


@pytest.mark.parametrize("frequency", [F_STEP, 1e3, 10e3, 50e3, 110e3, 130e3])
def test_optimized_waveform_honours_slew_rate_and_period(design, drive, frequency):
    fits = frequency <= highest_fitting_frequency(design, A, drive)
    wave = optimized(A, frequency, drive, periods=4, design=design, short_period="refuse" if fits else "cut")
    T = 1.0 / frequency
    assert wave.kind == ("optimized" if fits else "optimized, t_s cut")  # a truncated one says so
    assert wave.period == pytest.approx(T, rel=1e-15)
    assert wave.duration == pytest.approx(4 * T, rel=1e-12)
    # relative 1e-9: the fly-back and acceleration sit exactly at the limit, up to rounding
    assert np.max(np.abs(_slopes(wave))) <= max_piezo_velocity(drive) * (1 + 1e-9)
    assert np.all(wave.positions >= 0.0) and np.max(wave.positions) == pytest.approx(A, rel=1e-12)
    # every period starts at x_p = 0 and its fly-back starts at x_p = A, one per period
    np.testing.assert_allclose(wave.position(np.arange(5) * T), 0.0, atol=1e-6 * A)
    np.testing.assert_allclose(wave.position(wave.slip_marks), A, rtol=1e-9)
    assert np.all(np.diff(wave.slip_marks) == pytest.approx(T, rel=1e-9))
    assert np.all(wave.settle_windows[:, 1] == wave.slip_marks)


def test_first_period_is_a_sawtooth(design, drive):
    opt = optimized(A, F_STEP, drive, periods=3, design=design)
    saw = waveforms.sawtooth(A, F_STEP, drive, periods=3)
    t = np.linspace(0.0, 0.01, 1001)
    np.testing.assert_allclose(opt.position(t), saw.position(t), rtol=0, atol=1e-6 * A)
    np.testing.assert_allclose(opt.settle_windows[0], saw.settle_windows[0], rtol=1e-12)
    # from the second period on: hold for t_s, then rise by Δ_a in t_a
    T = 0.01
    assert opt.position(T + 0.999 * design.settling_time) == 0.0
    t_end = T + design.settling_time + design.acceleration_time
    assert opt.position(t_end) == pytest.approx(design.acceleration_amplitude, rel=1e-9)


def test_settling_fits_at_low_frequency_only(design, drive):
    low = optimized_timing(design, A, F_STEP, drive)
    assert low["settling_fits"] and low["settling_time_s"] == design.settling_time
    high = optimized_timing(design, A, 110e3, drive)
    # documented behaviour: the settling time is cut to what is left, nothing fails
    assert not high["settling_fits"]
    assert 0.0 <= high["settling_time_s"] < design.settling_time
    assert high["acceleration_time_s"] == design.acceleration_time
    T = high["period_s"]
    parts = ("flyback_time_s", "settling_time_s", "acceleration_time_s", "ramp_time_s")
    assert sum(high[k] for k in parts) == pytest.approx(T, rel=1e-12)
    assert high["ramp_time_s"] >= MIN_RAMP_FRACTION * (T - high["flyback_time_s"]) * (1 - 1e-12)


def test_long_acceleration_is_cut_not_failed(drive):
    slow = OptimizedDesign(
        settling_time=50e-6, acceleration_time=40e-6, acceleration_amplitude=80e-9
    )
    timing = optimized_timing(slow, A, 50e3, drive)
    assert not timing["acceleration_fits"] and timing["settling_time_s"] == 0.0
    # V_a is kept, so the amplitude shrinks with the time
    v_a = timing["acceleration_amplitude_m"] / timing["acceleration_time_s"]
    assert v_a == pytest.approx(2e-3, rel=1e-12)
    wave = optimized(A, 50e3, drive, periods=2, design=slow, short_period="cut")
    assert np.max(np.abs(_slopes(wave))) <= max_piezo_velocity(drive) * (1 + 1e-9)


def test_highest_fitting_frequency_is_where_settling_stops_fitting(design, drive):
    """At or below it one Eq. 15 period fits whole (optimized_timing's settling_fits), above it not;
    it follows the closed form T = t_fb + (t_s + t_a) / (1 − MIN_RAMP_FRACTION) here (the ramp's
    share, not A/V_max, binds for the paper's drive)."""
    f_max = highest_fitting_frequency(design, A, drive)
    t_fb = waveforms.flyback_time(A, drive)
    expected = 1.0 / (t_fb + (design.settling_time + design.acceleration_time) / (1 - MIN_RAMP_FRACTION))
    assert f_max == pytest.approx(expected, rel=1e-12)
    assert optimized_timing(design, A, f_max * (1 - 1e-9), drive)["settling_fits"]
    assert not optimized_timing(design, A, f_max * (1 + 1e-9), drive)["settling_fits"]
    # a short settling time: the slow ramp's A/V_max binds instead, and the rule still marks the edge
    quick = OptimizedDesign(settling_time=1e-7, acceleration_time=1e-7, acceleration_amplitude=5e-9)
    f_quick = highest_fitting_frequency(quick, A, drive)
    assert f_quick == pytest.approx(1.0 / max(t_fb + 2e-7 + A / max_piezo_velocity(drive), 2 * t_fb,
                                              t_fb + 4e-7), rel=1e-12)


def test_eq15_refuses_a_period_it_does_not_fit(design, drive):
    """By default the waveform is Eq. 15's or refused in one line naming the highest fitting frequency;
    the truncated study waveforms are asked for by name."""
    f_max = highest_fitting_frequency(design, A, drive)
    assert check_fits(design, A, f_max * 0.99, drive) == f_max * 0.99
    with pytest.raises(ValueError) as caught:
        optimized(A, 2 * f_max, drive, periods=3, design=design)
    message = str(caught.value)
    assert "\n" not in message and f"must be <= {f_max:.4g} Hz" in message and "t_s = " in message
    assert caught.value.name == "frequency" and caught.value.limits == (("<=", f_max),)
    with pytest.raises(ValueError, match="out of range for the Eq. 15 waveform"):
        optimized_timing(design, A, 2 * f_max, drive, short_period="refuse")
    assert optimized(A, 2 * f_max, drive, periods=3, design=design, short_period="skip").kind == \
        "optimized, t_s skipped"


def test_bad_inputs(design, drive):
    with pytest.raises(ValueError, match="acceleration_velocity"):
        eq15.optimized_design(A, drive, acceleration_velocity=0.2)
    with pytest.raises(ValueError, match="first_period"):
        optimized(A, F_STEP, drive, design=design, first_period="ramp")
    with pytest.raises(ValueError, match="frequency"):
        optimized(A, 300e3, drive, design=design)
    with pytest.raises(ValueError, match="acceleration_amplitude"):
        optimized(10e-9, F_STEP, drive, design=design)


def test_waveform_needs_a_design(drive):
    """Building the waveform never simulates: without a design it is refused, naming it."""
    with pytest.raises(ValueError, match="design = None"):
        optimized(A, F_STEP, drive, periods=2)


def test_optimized_run_from_rest(design, drive):
    res = simulation.simulate(drive, optimized(A, F_STEP, drive, periods=3, design=design))
    assert res.settled_positions.shape == (3,)
    assert np.all(np.isfinite(res.settled_positions)) and np.all(res.step_sizes > 0)


def test_skip_rule_drops_the_settling_only_when_it_does_not_fit(design, drive):
    low = optimized_timing(design, A, F_STEP, drive, short_period="skip")
    assert low["settling_time_s"] == design.settling_time
    high = optimized_timing(design, A, 110e3, drive, short_period="skip")
    assert not high["settling_fits"] and high["settling_time_s"] == 0.0
    wave = optimized(A, 110e3, drive, periods=3, design=design, short_period="skip")
    T = 1.0 / 110e3
    # no hold: the fast segment starts right at the period start
    x_end = wave.position(T + design.acceleration_time)
    assert x_end == pytest.approx(design.acceleration_amplitude, rel=1e-9)
    with pytest.raises(ValueError, match="short_period"):
        optimized_timing(design, A, 110e3, drive, short_period="wait")


def test_first_period_can_be_optimized_too(design, drive):
    wave = optimized(A, 1e3, drive, periods=2, design=design, first_period="optimized")
    # from rest: hold for t_s, then the fast rise, in every period including the first
    assert wave.position(0.999 * design.settling_time) == 0.0
    t_end = design.settling_time + design.acceleration_time
    assert wave.position(t_end) == pytest.approx(design.acceleration_amplitude, rel=1e-9)
    np.testing.assert_allclose(np.diff(wave.settle_windows[:, 1]), 1e-3, rtol=1e-9)


# --------------------------------------------------------------------------------------
# The velocity protocol (passmd.protocols.velocity)
# --------------------------------------------------------------------------------------


def test_steady_periods_cover_the_steady_time():
    from passmd.protocols import velocity

    assert velocity.steady_periods(F_STEP) == velocity.MIN_PERIODS
    assert velocity.steady_periods(110e3) == 550  # 5 ms at 110 kHz, exactly (no rounding up by 1e-9 noise)


def test_steady_velocity_reads_the_second_half():
    from types import SimpleNamespace

    from passmd.protocols import velocity

    period = 1e-5
    n = np.arange(40)
    means = np.where(n < 20, 0.0, (n - 20) * 2e-9)  # still at first, then 2 nm per period
    result = SimpleNamespace(period_mean_position=means, waveform=SimpleNamespace(period=period))
    out = velocity.steady_velocity(result)
    assert out["velocity_m_per_s"] == pytest.approx(2e-9 / period, rel=1e-12)
    assert out["velocity_drift"] == pytest.approx(0.0, abs=1e-12)


def test_waveform_velocity_below_the_step_protocol_is_mean_step_times_f(drive, design):
    from passmd.protocols import velocity

    steps = velocity.step_run(drive, A, F_STEP, "optimized", design)
    v = velocity.waveform_velocity(drive, A, F_STEP, "optimized", design)
    assert v == pytest.approx(steps["mean_step_m"] * F_STEP, rel=1e-12)
    assert steps["settled_positions_m"].shape == (velocity.STEP_PERIODS,)
    with pytest.raises(ValueError, match="waveform"):
        velocity.steady_run(drive, A, 1e3, "triangle", "cut")
