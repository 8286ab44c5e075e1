"""Critical actuation amplitude: Figs. 5 and 6 (Section 4.1).

Below a critical amplitude A_c a saw-tooth moves the runner by "no measurable step" — the
runner "only oscillates around its initial position without step generation" (Section 1).
The paper finds A_c with its dynamic simulation and compares it with closed forms: Eq. 7
(one contact, rigid actuator), Eq. 8 (one contact, flexible), Eq. 11 (six contacts, rigid)
and Eq. 12 (six contacts, flexible). It does not say how A_c was read off the runs; the
protocol below is ours, registered as assumptions, and the chapters show how much each of
its choices moves the result.

Two critical amplitudes, both found by bisection on the amplitude
-----------------------------------------------------------------
``"steady"`` — steady-state A_c (the primary one, checked by the ledger)
    Saw-tooth runs from rest (virgin contacts) of :data:`STEADY_PERIODS` periods at the
    drive frequency f; the step that counts is the *last* one (settled position of the last
    period minus that of the one before,
    :attr:`passmd.dynamics.SimulationResult.step_sizes`), by when the transient of the first
    fly-backs has died out. A_c is the smallest amplitude whose last step exceeds the
    "measurable step" :data:`STEP_THRESHOLD`. After a full slide the contact is left
    pre-strained and the runner keeps a residual micro-vibration, so this A_c depends on the
    drive frequency; the figures show its spread over :data:`FREQUENCY_BAND`.
``"first"`` — onset of full sliding in the first fly-back
    From rest and virgin contacts, one saw-tooth ramp and its fly-back: the smallest
    amplitude at which every contact slides fully (the share of slipping MDR springs
    reaches 1 in every contact group) during that fly-back or the actuator ringing after
    it. No step threshold is involved, and every integrator step is inspected.

Search: bisection on the reproducible bracket [0, A_max] (A_max: the actuator's full
stroke, Table 2). A = 0 makes no step and no slip, so only A_max is simulated to open the
bracket; it halves until narrower than the profile's tolerance, and reports the final
bracket, its midpoint as A_c and the number of runs.

Figures (registered in :mod:`passmd.experiments`): ``fig5a`` (step vs amplitude),
``fig5b`` (one contact, A_c vs preload), ``fig6a``–``fig6c`` (six contacts), and two
sensitivity panels beyond the paper, ``fig56_viscosity`` (A_c vs actuator viscosity c_p)
and ``fig56_frequency`` (A_c vs drive frequency).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from passmd import dynamics, readings, reference, sweep, waveforms
from passmd._validation import check_choice, check_positive, check_range
from passmd.checks import ClaimFails, NotEvaluable, curve_deviation, extractor
from passmd.experiments import PROFILES, register_figure
from passmd.parameters import (
    ACTUATOR_DAMPING_RATIO,
    PRELOAD_GRIDS,
    Assumption,
    Drive,
    actuator_for_radius,
    register_assumption,
)
from passmd.plots import critical_amplitude as plots

__all__ = [
    "DRIVE_FREQUENCY",
    "FREQUENCY_BAND",
    "PROFILE_SETTINGS",
    "PROTOCOLS",
    "STEADY_PERIODS",
    "STEP_THRESHOLD",
    "bisect_amplitude",
    "critical_amplitude",
    "critical_amplitude_point",
    "first_flyback_slip",
    "paper_drive_for",
    "steady_step",
    "step_point",
]

#: "Measurable step" of the steady-state search (m).
STEP_THRESHOLD = 0.5e-9
#: Periods of a steady-state run; the last of its steps counts.
STEADY_PERIODS = 10
#: Drive frequency of the primary (ledger) curves: the frequency of Section 5.2's Fig. 9a (Hz).
DRIVE_FREQUENCY = 100.0
#: Frequencies whose spread of the steady-state A_c is drawn as a band (Hz).
FREQUENCY_BAND = (50.0, 100.0, 200.0)
#: Time after the first fly-back during which slip is still looked for (actuator ringing) (s).
FIRST_FLYBACK_HOLD = 20e-6
#: |T|/μF_N counted as full sliding (the exact MDR contact gives exactly μF_N when sliding).
FULL_SLIDING_SHARE = 1.0 - 1e-9
#: Protocols of :func:`critical_amplitude`.
PROTOCOLS = ("steady", "first")
#: Narrowest bisection bracket, in float spacings of the upper amplitude: the midpoint of a
#: narrower bracket rounds onto one of its ends and the halving stops making progress.
BISECTION_FLOOR_SPACINGS = 16

register_assumption(
    Assumption(
        key="critical_amplitude_protocol",
        symbol="A_c",
        value=(
            f"steady state: smallest saw-tooth amplitude whose last step of a {STEADY_PERIODS}-period run "
            f"from rest exceeds the measurable step, at f = {DRIVE_FREQUENCY:g} Hz (band "
            f"{FREQUENCY_BAND[0]:g}–{FREQUENCY_BAND[-1]:g} Hz), slew-rate fly-back; also the onset of full "
            "sliding of every contact in the first fly-back from virgin contacts"
        ),
        unit="nm",
        rationale=(
            "Section 4.1 does not say how A_c was read off the simulations. Section 1 defines A_c as the "
            "amplitude below which 'no measurable step' is obtained and the runner 'only oscillates "
            "around its initial position', i.e. no steps in continued operation: the last step of a run "
            "long enough for the start-up transient to die out (it has by the 8th period in every "
            "configuration tried). 100 Hz is the saw-tooth frequency of Section 5.2 (Fig. 9a)."
        ),
        sensitivity=(
            "Critical-amplitude chapters: both protocols side by side, the steady-state A_c over "
            "50–200 Hz as a band and from 20 Hz to 1 kHz, both fly-back rules."
        ),
    )
)
register_assumption(
    Assumption(
        key="critical_amplitude_step_threshold",
        symbol="δ",
        value=f"{STEP_THRESHOLD * 1e9:g}",
        unit="nm",
        rationale=(
            "'No measurable step' needs a number. Above the onset the steady step grows about 1 nm "
            "per nm of amplitude (Fig. 5a), so δ raises A_c by about δ: 0.5 nm is 0.5 % of the largest "
            "A_c on the preload grids and 10 % of the smallest (six flexible contacts at 0.1 N), yet "
            "well above the simulator's step convergence (0.05 nm) and the creep the start-up "
            "transient still leaves at the last period below A_c (tested at 0.8 A_c)."
        ),
        sensitivity="Shifts the steady-state A_c by about δ; the first-fly-back onset uses none.",
    )
)


# --------------------------------------------------------------------------------------
# Runs and the search
# --------------------------------------------------------------------------------------


def paper_drive_for(
    contacts: int,
    actuator_model: str,
    hemisphere_radius: float,
    preload: float,
    damping_ratio: float = ACTUATOR_DAMPING_RATIO,
) -> Drive:
    """The Fig. 5/6 drive: Tables 1–2, free runner (no load cell), μ = 0.2, actuator damping ζ."""
    return Drive(
        hemisphere_radius=hemisphere_radius,
        preload=preload,
        contacts=contacts,
        actuator_model=actuator_model,
        actuator=actuator_for_radius(hemisphere_radius, damping_ratio=damping_ratio),
    )


def steady_step(
    drive: Drive,
    amplitude: float,
    frequency: float = DRIVE_FREQUENCY,
    *,
    periods: int = STEADY_PERIODS,
    flyback: str = "slew",
) -> dict:
    """Step sizes of a saw-tooth run from rest; the last one is the steady-state step.

    Parameters
    ----------
    drive : Drive
        The drive.
    amplitude : float
        Actuation amplitude A (m), 0 ≤ A ≤ A_max.
    frequency : float
        Drive frequency f (Hz).
    periods : int
        Periods of the run (>= 2); the steps are the changes of the settled position from
        one period to the next.
    flyback : {"slew", "fixed"}
        Fly-back rule (:func:`passmd.waveforms.flyback_time`).

    Returns
    -------
    dict
        ``steps_m`` (the ``periods − 1`` steps), ``first_step_m`` (across the first
        fly-back), ``last_step_m`` (across the last one), ``wall_time_s``.
    """
    if int(periods) != periods or periods < 2:
        raise ValueError(f"periods = {periods!r} is out of range: must be an integer >= 2")
    wave = waveforms.sawtooth(amplitude, frequency, drive, periods=int(periods), flyback=flyback)
    result = dynamics.simulate(drive, wave, max_points=2)
    steps = result.step_sizes
    return {
        "steps_m": steps.tolist(),
        "first_step_m": float(steps[0]),
        "last_step_m": float(steps[-1]),
        "wall_time_s": result.wall_time,
    }


def first_flyback_slip(
    drive: Drive,
    amplitude: float,
    frequency: float = DRIVE_FREQUENCY,
    *,
    flyback: str = "slew",
    hold: float = FIRST_FLYBACK_HOLD,
) -> dict:
    """Whether every contact group slides fully in the first fly-back from virgin contacts.

    The first period of the saw-tooth at ``frequency`` (ramp 0 → A, fly-back A → 0),
    followed by ``hold`` at x_p = 0 for the actuators' ringing, from rest. The simulator
    inspects every integrator step from the fly-back on for |T|/μF_N
    (``SimulationResult.peak_force_ratio``), which is 1 exactly in full sliding. The ramp
    starts with a jump of x_p's velocity, which leaves the runner vibrating with an
    amplitude of about A·f/ω_r (ω_r the runner-on-contacts frequency, 4–11 kHz): ≤ 0.2 nm at
    100 Hz, but nm at 1 kHz, so the onset is only frequency-independent at low f.

    Returns
    -------
    dict
        ``peak_force_ratio`` (largest |T|/μF_N, one per contact group: side 1 and side 2
        for six contacts), ``full_sliding`` (every group reached full sliding), ``wall_time_s``.
    """
    A = check_range(
        "amplitude", amplitude, 0.0, drive.actuator.full_stroke_amplitude, lower_open=True, unit="m"
    )
    check_positive("hold", hold, "s")
    t_fb = waveforms.flyback_time(A, drive, flyback)
    t_ramp = 1.0 / check_positive("frequency", frequency, "Hz") - t_fb
    if t_ramp <= t_fb:
        raise ValueError(
            f"frequency = {frequency!r} is out of range: the fly-back of {t_fb:.3g} s must "
            "take less than half a period"
        )
    period = t_ramp + t_fb + hold
    wave = waveforms.piecewise_linear(
        [0.0, 0.8 * t_ramp, t_ramp, t_ramp + t_fb, period],
        [0.0, 0.8 * A, A, 0.0, 0.0],
        1.0 / period,
        1,
        settle_window=(0.8 * t_ramp, t_ramp),
        slip_mark=t_ramp,
        kind="first fly-back",
    )
    result = dynamics.simulate(drive, wave, max_points=2)
    peak = result.peak_force_ratio[0]  # every integrator step from the fly-back on
    return {
        "peak_force_ratio": peak.tolist(),
        "full_sliding": bool(np.all(peak >= FULL_SLIDING_SHARE)),
        "wall_time_s": result.wall_time,
    }


def bisect_amplitude(moves, upper: float, tolerance: float) -> dict:
    """Smallest amplitude in (0, upper] at which ``moves(A)`` turns true, by bisection.

    ``moves(0)`` is false by definition (no drive, no motion) and is not evaluated; the
    bracket [0, upper] is opened by evaluating ``moves(upper)`` and then halved until it
    is at most ``tolerance`` wide. If ``moves`` switches more than once in the bracket,
    the bisection finds one of the switches; the runs of Fig. 5a show where that matters.
    ``tolerance`` must be at least ``BISECTION_FLOOR_SPACINGS`` float spacings of
    ``upper`` (the resolution of the amplitude), so the halving always ends.

    Returns
    -------
    dict
        ``critical_amplitude_m`` (midpoint of the final bracket; NaN when
        ``moves(upper)`` is false), ``bracket_low_m``, ``bracket_high_m`` (NaN when
        ``moves(upper)`` is false), ``runs`` (evaluations of ``moves``).
    """
    lo, hi = 0.0, check_positive("upper", upper, "m")
    check_positive("tolerance", tolerance, "m")
    floor = BISECTION_FLOOR_SPACINGS * float(np.spacing(hi))
    if tolerance < floor:
        raise ValueError(
            f"tolerance (--tolerance) = {tolerance!r} m is out of range: must be >= {floor:.3g} m, "
            f"{BISECTION_FLOOR_SPACINGS} float spacings of the amplitude {hi!r} m (a narrower bracket "
            "cannot be represented)"
        )
    runs = 1
    if not moves(hi):
        return {
            "critical_amplitude_m": math.nan,
            "bracket_low_m": hi,
            "bracket_high_m": math.nan,
            "runs": runs,
        }
    while hi - lo > tolerance:
        mid = 0.5 * (lo + hi)
        runs += 1
        if moves(mid):
            hi = mid
        else:
            lo = mid
    return {"critical_amplitude_m": 0.5 * (lo + hi), "bracket_low_m": lo, "bracket_high_m": hi, "runs": runs}


def critical_amplitude(
    drive: Drive,
    *,
    protocol: str = "steady",
    frequency: float = DRIVE_FREQUENCY,
    flyback: str = "slew",
    periods: int = STEADY_PERIODS,
    threshold: float = STEP_THRESHOLD,
    tolerance: float = 0.1e-9,
) -> dict:
    """Simulated critical amplitude A_c of a drive (protocols: see the module docstring).

    Parameters
    ----------
    drive : Drive
        The drive (one or six contacts, rigid or flexible actuators).
    protocol : {"steady", "first"}
        Steady-state A_c (the last step of a ``periods``-period run at ``frequency``
        exceeds ``threshold``) or the onset of full sliding in the first fly-back.
    frequency : float
        Drive frequency f of the saw-tooth (Hz).
    flyback : {"slew", "fixed"}
        Fly-back rule (:func:`passmd.waveforms.flyback_time`).
    periods : int
        Periods of a steady-state run (>= 2).
    threshold : float
        Measurable step δ (m) of the steady-state protocol.
    tolerance : float
        Largest width of the final bracket (m).

    Returns
    -------
    dict
        ``critical_amplitude_m``, ``bracket_low_m``, ``bracket_high_m``, ``runs``,
        ``wall_time_s`` (integration time of all runs).
    """
    if not isinstance(drive, Drive):
        raise ValueError(f"drive = {drive!r} is not a Drive")
    check_choice("protocol", protocol, PROTOCOLS)
    check_choice("flyback", flyback, ("slew", "fixed"))
    check_positive("frequency", frequency, "Hz")
    check_positive("tolerance", tolerance, "m")
    check_range("threshold", threshold, 0.0, lower_open=True, unit="m")
    if int(periods) != periods or periods < 2:
        raise ValueError(f"periods = {periods!r} is out of range: must be an integer >= 2")
    wall = [0.0]

    def moves(amplitude):
        if protocol == "steady":
            out = steady_step(drive, amplitude, frequency, periods=int(periods), flyback=flyback)
            wall[0] += out["wall_time_s"]
            return out["last_step_m"] > threshold
        out = first_flyback_slip(drive, amplitude, frequency, flyback=flyback)
        wall[0] += out["wall_time_s"]
        return out["full_sliding"]

    found = bisect_amplitude(moves, drive.actuator.full_stroke_amplitude, tolerance)
    found["wall_time_s"] = wall[0]
    return found


# --------------------------------------------------------------------------------------
# Sweep point functions (top level, scalar keyword arguments: picklable and cacheable)
# --------------------------------------------------------------------------------------


def critical_amplitude_point(
    contacts: int,
    actuator_model: str,
    hemisphere_radius: float,
    preload: float,
    protocol: str,
    frequency: float,
    flyback: str,
    tolerance: float,
    damping_ratio: float = ACTUATOR_DAMPING_RATIO,
    periods: int = STEADY_PERIODS,
    threshold: float = STEP_THRESHOLD,
) -> dict:
    """:func:`critical_amplitude` of :func:`paper_drive_for` (one sweep point, SI results)."""
    drive = paper_drive_for(contacts, actuator_model, hemisphere_radius, preload, damping_ratio)
    return critical_amplitude(
        drive,
        protocol=protocol,
        frequency=frequency,
        flyback=flyback,
        periods=periods,
        threshold=threshold,
        tolerance=tolerance,
    )


def step_point(
    contacts: int,
    actuator_model: str,
    hemisphere_radius: float,
    preload: float,
    amplitude: float,
    frequency: float,
    flyback: str,
    damping_ratio: float = ACTUATOR_DAMPING_RATIO,
    periods: int = STEADY_PERIODS,
) -> dict:
    """First and last step (m) and integration time (s) of a saw-tooth run of :func:`paper_drive_for`."""
    if amplitude == 0.0:  # x_p stays 0: nothing moves
        return {"first_step_m": 0.0, "last_step_m": 0.0, "wall_time_s": 0.0}
    drive = paper_drive_for(contacts, actuator_model, hemisphere_radius, preload, damping_ratio)
    out = steady_step(drive, amplitude, frequency, periods=periods, flyback=flyback)
    return {key: out[key] for key in ("first_step_m", "last_step_m", "wall_time_s")}


# --------------------------------------------------------------------------------------
# Profiles and figure data
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ProfileSettings:
    """What a resolution profile means for the critical-amplitude figures."""

    preloads: dict  # hemisphere radius (m) -> preloads (N) of Figs. 5b and 6
    frequencies: tuple  # drive frequencies of the steady-state band (Hz)
    tolerance: float  # width of the final bisection bracket (m)
    amplitude_step: float  # amplitude grid step of Fig. 5a (m)
    damping_ratios: tuple  # actuator damping ratios ζ of the viscosity panel
    sensitivity_frequencies: tuple  # drive frequencies of the frequency panel (Hz)


PROFILE_SETTINGS = {
    "quick": ProfileSettings(
        preloads={1.0e-3: (0.2, 0.6, 1.0), 0.25e-3: (0.2, 0.4)},
        frequencies=(DRIVE_FREQUENCY,),
        tolerance=0.5e-9,
        amplitude_step=20e-9,
        damping_ratios=(0.005, 0.05, 0.5),
        sensitivity_frequencies=(100.0, 1000.0),
    ),
    "paper": ProfileSettings(
        preloads={r: tuple(float(p) for p in grid) for r, grid in PRELOAD_GRIDS.items()},
        frequencies=FREQUENCY_BAND,
        tolerance=0.1e-9,
        amplitude_step=1e-9,
        damping_ratios=tuple(float(z) for z in ACTUATOR_DAMPING_RATIO * np.logspace(-1, 1, 5)),
        sensitivity_frequencies=(20.0, 50.0, 100.0, 200.0, 500.0, 1000.0),
    ),
}


def _settings(profile: str) -> ProfileSettings:
    return PROFILE_SETTINGS[check_choice("profile", profile, PROFILES)]


def _protocols(actuator_model: str, frequencies) -> list[dict]:
    """The (protocol, fly-back, frequency[, ζ]) combinations drawn for an actuator model.

    Flexible actuators are also searched at the evaluated alternatives of the ledger's axis
    ``damping_ratio`` (:mod:`passmd.readings`; Table 2's c_p is lost), steady state with the
    slew-rate fly-back at :data:`DRIVE_FREQUENCY`; every other row uses
    :data:`~passmd.parameters.ACTUATOR_DAMPING_RATIO`.
    """
    combos = [{"protocol": "steady", "flyback": "slew", "frequency": float(f)} for f in frequencies]
    combos.append({"protocol": "first", "flyback": "slew", "frequency": DRIVE_FREQUENCY})
    if actuator_model == "flexible":  # the fly-back rule and ζ only matter for flexible actuators
        combos.append({"protocol": "steady", "flyback": "fixed", "frequency": DRIVE_FREQUENCY})
        combos.append({"protocol": "first", "flyback": "fixed", "frequency": DRIVE_FREQUENCY})
        combos.extend({"protocol": "steady", "flyback": "slew", "frequency": DRIVE_FREQUENCY,
                       "damping_ratio": float(z)} for z in readings.axis("damping_ratio").alternatives)
    return combos


def _run_searches(points: list[dict], description: str) -> pd.DataFrame:
    """Run critical-amplitude searches through the sweep engine; tidy frame in nm."""
    frame = sweep.run(critical_amplitude_point, points, description=description)
    out = pd.DataFrame(
        {
            "contacts": frame["contacts"].astype(int),
            "actuator_model": frame["actuator_model"],
            "radius_mm": frame["hemisphere_radius"] * 1e3,
            "preload_N": frame["preload"],
            "protocol": frame["protocol"],
            "flyback": frame["flyback"],
            "frequency_Hz": frame["frequency"],
            "damping_ratio": frame["damping_ratio"],
            "critical_amplitude_nm": frame["critical_amplitude_m"] * 1e9,
            "bracket_low_nm": frame["bracket_low_m"] * 1e9,
            "bracket_high_nm": frame["bracket_high_m"] * 1e9,
            "runs": frame["runs"].astype(int),
            "wall_time_s": frame["wall_time_s"],
        }
    )
    out.attrs["sweep"] = frame.attrs.get("sweep", {})  # points computed / taken from the cache
    return out


def _preload_figure(profile: str, contacts: int, radius: float, models, curve: str) -> pd.DataFrame:
    s = _settings(profile)
    points = [
        {
            "contacts": contacts,
            "actuator_model": model,
            "hemisphere_radius": radius,
            "preload": float(p),
            "tolerance": s.tolerance,
            "damping_ratio": ACTUATOR_DAMPING_RATIO,
            **combo,
        }
        for p in s.preloads[radius]
        for model in models
        for combo in _protocols(model, s.frequencies)
    ]
    table = _run_searches(points, curve.split("_")[0])
    closed = reference.closed_form_curves(curve)
    merged = table.merge(closed, on="preload_N", how="left", validate="many_to_one")
    merged.attrs = table.attrs
    return merged


@register_figure(
    "fig5a",
    title="Step size against actuation amplitude, one contact, 0.4 N, R = 1 mm",
    chapter="critical_amplitude_one",
    plot=plots.plot_fig5a,
)
def fig5a(profile: str = "paper") -> pd.DataFrame:
    """Fig. 5a: first and steady-state step against the amplitude (one contact, F_p = 0.4 N, R = 1 mm).

    Rigid and flexible actuators with the slew-rate fly-back, and flexible with the fixed
    2 µs fly-back, at :data:`DRIVE_FREQUENCY`; the amplitude grid runs from 0 to the full
    stroke in the profile's step. Lengths in nm.
    """
    s = _settings(profile)
    radius, preload = 1.0e-3, 0.4
    a_max = actuator_for_radius(radius).full_stroke_amplitude
    amplitudes = np.round(np.arange(0.0, a_max * (1 + 1e-9), s.amplitude_step), 15)
    series = [("rigid", "slew"), ("flexible", "slew"), ("flexible", "fixed")]
    points = [
        {
            "contacts": 1,
            "actuator_model": model,
            "hemisphere_radius": radius,
            "preload": preload,
            "amplitude": float(a),
            "frequency": DRIVE_FREQUENCY,
            "flyback": flyback,
        }
        for model, flyback in series
        for a in amplitudes
    ]
    frame = sweep.run(step_point, points, description="fig5a")
    closed = reference.closed_form_curves("fig5b_closed_form").set_index("preload_N").loc[preload]
    table = pd.DataFrame(
        {
            "actuator_model": frame["actuator_model"],
            "flyback": frame["flyback"],
            "frequency_Hz": frame["frequency"],
            "preload_N": frame["preload"],
            "amplitude_nm": frame["amplitude"] * 1e9,
            "first_step_nm": frame["first_step_m"] * 1e9,
            "steady_step_nm": frame["last_step_m"] * 1e9,
            "threshold_nm": STEP_THRESHOLD * 1e9,
            "u_x_max_nm": closed["u_x_max_nm"],
            "u_x_max_plus_u_x_a_nm": closed["u_x_max_plus_u_x_a_nm"],
            "wall_time_s": frame["wall_time_s"],
        }
    )
    table.attrs["sweep"] = frame.attrs.get("sweep", {})
    return table


@register_figure(
    "fig5b",
    title="Critical amplitude against preload, one contact, R = 1 mm",
    chapter="critical_amplitude_one",
    plot=plots.plot_fig5b,
)
def fig5b(profile: str = "paper") -> pd.DataFrame:
    """Fig. 5b: A_c against preload, one contact, rigid and flexible, with Eqs. 7 and 8 (nm)."""
    return _preload_figure(profile, 1, 1.0e-3, ("rigid", "flexible"), "fig5b_closed_form")


@register_figure(
    "fig6a",
    title="Critical amplitude against preload, six contacts, rigid, R = 1 mm",
    chapter="critical_amplitude_six",
    plot=plots.plot_fig6,
)
def fig6a(profile: str = "paper") -> pd.DataFrame:
    """Fig. 6a: A_c against preload, six contacts, rigid actuators, with Eqs. 10 and 11 (nm)."""
    return _preload_figure(profile, 6, 1.0e-3, ("rigid",), "fig6a_closed_form")


@register_figure(
    "fig6b",
    title="Critical amplitude against preload, six contacts, flexible, R = 1 mm",
    chapter="critical_amplitude_six",
    plot=plots.plot_fig6,
)
def fig6b(profile: str = "paper") -> pd.DataFrame:
    """Fig. 6b: A_c against preload, six contacts, flexible actuators, R = 1 mm, with Eqs. 12–14 (nm)."""
    return _preload_figure(profile, 6, 1.0e-3, ("flexible",), "fig6b_closed_form")


@register_figure(
    "fig6c",
    title="Critical amplitude against preload, six contacts, flexible, R = 0.25 mm",
    chapter="critical_amplitude_six",
    plot=plots.plot_fig6,
)
def fig6c(profile: str = "paper") -> pd.DataFrame:
    """Fig. 6c: A_c against preload, six contacts, flexible actuators, R = 0.25 mm, with Eqs. 12–14 (nm)."""
    return _preload_figure(profile, 6, 0.25e-3, ("flexible",), "fig6c_closed_form")


def _closed_form_at(contacts: int, actuator_model: str, radius: float, preload: float) -> float:
    """Eq. 7/8 (one contact) or Eq. 11/12 (six contacts) in nm, from passmd.theory."""
    from passmd.theory import drive_theory

    drive = paper_drive_for(contacts, actuator_model, radius, preload)
    return drive_theory(drive)["analytic_critical_amplitude_m"] * 1e9


@register_figure(
    "fig56_viscosity",
    title="Critical amplitude against actuator viscosity c_p, 0.4 N, R = 1 mm",
    chapter="critical_amplitude_six",
    plot=plots.plot_viscosity,
)
def fig56_viscosity(profile: str = "paper") -> pd.DataFrame:
    """Beyond the paper: A_c of flexible actuators against c_p (a decade either side of the default).

    One and six contacts, F_p = 0.4 N, R = 1 mm; both protocols and both fly-back rules.
    ``actuator_viscosity_kg_per_s`` is c_p = 2ζ√(k_p m_a); ``closed_form_nm`` is Eq. 8
    (one contact) or Eq. 12 (six), which do not depend on c_p.
    """
    s = _settings(profile)
    radius, preload = 1.0e-3, 0.4
    points = [
        {
            "contacts": n,
            "actuator_model": "flexible",
            "hemisphere_radius": radius,
            "preload": preload,
            "protocol": protocol,
            "frequency": DRIVE_FREQUENCY,
            "flyback": flyback,
            "tolerance": s.tolerance,
            "damping_ratio": float(z),
        }
        for n in (1, 6)
        for z in s.damping_ratios
        for protocol in PROTOCOLS
        for flyback in ("slew", "fixed")
    ]
    table = _run_searches(points, "fig56_viscosity")
    table["actuator_viscosity_kg_per_s"] = [
        actuator_for_radius(radius, damping_ratio=z).viscosity for z in table["damping_ratio"]
    ]
    table["closed_form_nm"] = [_closed_form_at(n, "flexible", radius, preload) for n in table["contacts"]]
    return table


@register_figure(
    "fig56_frequency",
    title="Critical amplitude against drive frequency, 0.4 N, R = 1 mm",
    chapter="critical_amplitude_six",
    plot=plots.plot_frequency,
)
def fig56_frequency(profile: str = "paper") -> pd.DataFrame:
    """Beyond the paper: A_c (both protocols) against the drive frequency of the runs.

    One and six contacts, rigid and flexible (slew-rate fly-back), F_p = 0.4 N, R = 1 mm;
    ``closed_form_nm`` is Eq. 7/8 (one contact) or Eq. 11/12 (six).
    """
    s = _settings(profile)
    radius, preload = 1.0e-3, 0.4
    points = [
        {
            "contacts": n,
            "actuator_model": model,
            "hemisphere_radius": radius,
            "preload": preload,
            "protocol": protocol,
            "frequency": float(f),
            "flyback": "slew",
            "tolerance": s.tolerance,
            "damping_ratio": ACTUATOR_DAMPING_RATIO,
        }
        for n in (1, 6)
        for model in ("rigid", "flexible")
        for protocol in PROTOCOLS
        for f in s.sensitivity_frequencies
    ]
    table = _run_searches(points, "fig56_frequency")
    table["closed_form_nm"] = [
        _closed_form_at(n, m, radius, preload)
        for n, m in zip(table["contacts"], table["actuator_model"], strict=True)
    ]
    return table


# --------------------------------------------------------------------------------------
# Ledger extractors (claims of Section 4.1, passmd/data/reference/claims.csv)
# --------------------------------------------------------------------------------------


def primary(table: pd.DataFrame, actuator_model: str | None = None, reading=None) -> pd.DataFrame:
    """The rows of one reading of the A_c protocol (default: steady state, :data:`DRIVE_FREQUENCY`,
    slew-rate fly-back, ζ = :data:`~passmd.parameters.ACTUATOR_DAMPING_RATIO`).

    ``reading`` is a ledger reading (:mod:`passmd.readings`): its ``ac_protocol``,
    ``flyback``, ``drive_frequency_s4`` and ``damping_ratio`` select the rows. The fly-back
    rule and ζ apply to flexible actuators only (the rigid runs use the slew-rate fly-back). Raises
    :class:`passmd.ledger.NotEvaluable` when the table holds no run at that reading and
    :class:`passmd.ledger.ClaimFails` when a preload makes no step up to the full stroke.
    """
    protocol, flyback, frequency = "steady", "slew", DRIVE_FREQUENCY
    zeta = ACTUATOR_DAMPING_RATIO
    if reading is not None:
        protocol, flyback = reading["ac_protocol"], reading["flyback"]
        frequency = float(reading["drive_frequency_s4"])
        zeta = float(reading.get("damping_ratio", zeta))
    if actuator_model == "rigid":  # no actuator dynamics: neither the fly-back rule nor ζ applies
        flyback, zeta = "slew", ACTUATOR_DAMPING_RATIO
    rows = table[
        (table["protocol"] == protocol)
        & (table["flyback"] == flyback)
        & np.isclose(table["frequency_Hz"], frequency)
        & np.isclose(table["damping_ratio"], zeta, rtol=1e-9, atol=0)
    ]
    if actuator_model is not None:
        rows = rows[rows["actuator_model"] == actuator_model]
    rows = rows.sort_values("preload_N")
    if rows.empty:
        raise NotEvaluable(f"no {protocol} A_c runs with the {flyback} fly-back at {frequency:g} Hz "
                           f"and ζ = {zeta:g} on this grid")
    if rows["critical_amplitude_nm"].isna().any():
        where = rows.loc[rows["critical_amplitude_nm"].isna(), "preload_N"].tolist()
        raise ClaimFails(f"no step up to the full stroke at {', '.join(f'{p:g}' for p in where)} N "
                         "(A_c above A_max)")
    return rows


def _curve(results, key: str, actuator_model: str, reading=None) -> dict:
    rows = primary(results[key], actuator_model, reading)
    return {"x": rows["preload_N"].to_numpy(), "y": rows["critical_amplitude_nm"].to_numpy()}


#: Axes of passmd.readings the A_c curves depend on (rigid actuators: neither the fly-back rule nor ζ).
_RIGID_AXES = ("ac_protocol", "drive_frequency_s4")
_FLEXIBLE_AXES = ("flyback", "ac_protocol", "drive_frequency_s4", "damping_ratio")


@extractor("fig5a-no-step-below-50nm", depends_on=("flyback",))
def _fig5a_no_step(results, reading) -> dict:
    table = results["fig5a"]
    rows = table[(table["actuator_model"] == "flexible") & (table["flyback"] == reading["flyback"])]
    rows = rows.sort_values("amplitude_nm")
    if rows.empty:
        raise NotEvaluable(f"no flexible runs with the {reading['flyback']} fly-back")
    step = rows["steady_step_nm"].to_numpy(dtype=float)
    holds = np.where(np.isfinite(step), step <= rows["threshold_nm"].to_numpy(dtype=float), np.nan)
    return {"x": rows["amplitude_nm"].to_numpy(), "holds": holds}


@extractor("fig5b-rigid-ac-matches-eq7", depends_on=_RIGID_AXES)
def _fig5b_rigid(results, reading) -> dict:
    return _curve(results, "fig5b", "rigid", reading)


@extractor("fig5b-flexible-ac-matches-eq8", depends_on=_FLEXIBLE_AXES)
def _fig5b_flexible(results, reading) -> dict:
    return _curve(results, "fig5b", "flexible", reading)


@extractor("fig5b-flexible-above-rigid", depends_on=_FLEXIBLE_AXES)
def _fig5b_order(results, reading) -> dict:
    rigid = _curve(results, "fig5b", "rigid", reading)
    flexible = _curve(results, "fig5b", "flexible", reading)
    if not np.array_equal(rigid["x"], flexible["x"]):
        raise NotEvaluable("rigid and flexible A_c are not on the same preloads")
    return {"lhs": flexible["y"], "rhs": rigid["y"]}


@extractor("fig6a-rigid-ac-matches-eq11", depends_on=_RIGID_AXES)
def _fig6a_eq11(results, reading) -> dict:
    return _curve(results, "fig6a", "rigid", reading)


@extractor("fig6a-rigid-ac-not-eq10", depends_on=_RIGID_AXES)
def _fig6a_not_eq10(results, reading) -> dict:
    c = _curve(results, "fig6a", "rigid", reading)
    own = curve_deviation(c["x"], c["y"], "fig6a_closed_form", "u_x_max_e_nm")
    sides = min(
        curve_deviation(c["x"], c["y"], "fig6a_closed_form", column)
        for column in ("u_x_max_1_nm", "u_x_max_2_nm")
    )
    return {"lhs": own, "rhs": sides}


@extractor("fig6b-flexible-r1-ac-matches-eq12", depends_on=_FLEXIBLE_AXES)
def _fig6b_eq12(results, reading) -> dict:
    return _curve(results, "fig6b", "flexible", reading)


@extractor("fig6c-flexible-r025-ac-matches-eq12", depends_on=_FLEXIBLE_AXES)
def _fig6c_eq12(results, reading) -> dict:
    return _curve(results, "fig6c", "flexible", reading)
