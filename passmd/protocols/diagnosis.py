"""Why a result departs from its closed form or its expected trend: computed, one cause at a time.

A simulated critical amplitude far from Eq. 8/11/12, a step or velocity that turns over a sweep, a
velocity that rolls off at high frequency, an Eq. 15 waveform slower than the saw-tooth: each has
several candidate causes, and a rule of thumb cannot tell which one acts on a given drive. Here the
point is simulated again with one candidate cause removed at a time, and each cause is named by how
much of the departure its removal takes away:

``flyback`` — the fly-back overshoot
    A fly-back shorter than the actuator's period makes the actuator overshoot (a ramp of duration
    t leaves a mass–spring of period T_a ringing with up to A·T_a/(π t)). Removed: a fly-back of
    :data:`FLYBACK_PERIODS` bare-actuator periods, which leaves at most A/(10π) ≈ 3 % of the
    amplitude (the stated time at every amplitude; only where it fits in half the period).
``actuator`` — the actuators' dynamics
    Removed: rigid actuators (the hemispheres follow x_p exactly); the closed form the departure
    is measured from becomes Eq. 7/11.
``ringing`` — the runner's ringing at the next fly-back
    After a fly-back the runner swings on its contacts and is still swinging when the next
    fly-back comes (:mod:`passmd.protocols.ringing`). Removed: x_p rests at 0 after each fly-back
    until the swing has decayed below :data:`REST_SWING` (at most :data:`MAX_REST`), so every
    fly-back meets a runner at rest; the step is that of the last of the run's periods. A velocity
    or step read at a period shorter than one swing is that of a runner in continuous motion, which
    rests would stop: there the cause is not tried.
``reading`` — the steady reading
    The closed forms describe the onset of full sliding; the steady reading asks for a step in
    continued operation. Removed: the first-fly-back reading (critical amplitude only).
``share`` — the fly-back's share of the period
    As the period shortens, the ramp's speed approaches the fly-back's and the saw-tooth loses the
    asymmetry a step needs. Removed: a fly-back :data:`SHARE_FACTOR` times shorter (velocity, step
    and gain only).

The departure D is the result minus what its closed form or trend expects; the counterfactual's
D' is measured the same way on the counterfactual (its own closed form for rigid actuators), and
the cause's share is 1 − D'/D: 100 % when removing it removes the departure, 0 when it changes
nothing, negative when the departure grows, above 100 % when its removal overshoots to a departure
the other way (then another cause acts the other way). Causes interact, so shares need not add up
to 100 %. The causes are listed by how near their removal brings the result to what is expected
(|1 − share|), and a cause is named when its share is at least :data:`EXPLAINS`. Every
counterfactual is a point of :func:`passmd.runtime.sweep.run`, cached like any sweep point.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from passmd.model import theory, waveforms
from passmd.model.defaults import PROTOCOL
from passmd.model.parameters import Drive
from passmd.model.tables import Assumption
from passmd.protocols import critical_amplitude, ringing, velocity
from passmd.runtime import sweep
from passmd.runtime.validation import check_choice
from passmd.solver.results import SimulationError

__all__ = ["AGREEMENT", "ASSUMPTIONS", "CAUSES", "EXPLAINS", "FLYBACK_PERIODS", "MAX_DIAGNOSED",
           "MAX_REST", "QUANTITIES", "REST_SWING", "SHARE_FACTOR", "Cause", "counterfactual_point",
           "departs", "diagnose", "rest_time", "running_max", "sweep_departures"]

#: Relative departure of a simulated A_c from its closed form beyond which it is diagnosed, and of a
#: value from its trend between two neighbouring sweep points: the 10 % band within which the critical
#: amplitude chapters call an A_c and a closed form in agreement (Fig. 6); the steady reading itself
#: sits about δ = 0.5 nm (the measurable step) above the onset, 1–3 % of the A_c of either drive.
AGREEMENT = 0.10
#: Bare-actuator periods of the counterfactual fly-back: a ramp of n periods leaves at most
#: A/(nπ) of actuator ringing, 3 % of the amplitude for n = 10, below :data:`AGREEMENT`.
FLYBACK_PERIODS = 10
#: How much shorter the counterfactual fly-back of the ``share`` cause is.
SHARE_FACTOR = 10.0
#: Swing left at the next fly-back below which the runner counts as at rest: a tenth of the
#: measurable step, so no step read to that resolution depends on it.
REST_SWING = PROTOCOL.step_threshold / 10
#: Longest rest after a fly-back (s); the swing left then is reported.
MAX_REST = 1.0
#: Share of the departure a cause's removal must take away to be named.
EXPLAINS = 0.5
#: Quantities a diagnosis covers.
QUANTITIES = ("critical-amplitude", "velocity", "step", "gain")

ASSUMPTIONS: tuple[Assumption, ...] = (
    Assumption(
        key="diagnosis_thresholds",
        symbol="–",
        value=(f"a departure beyond {100 * AGREEMENT:.0f} % is diagnosed; a cause is named when its removal "
               f"takes away at least {100 * EXPLAINS:.0f} % of it"),
        unit="",
        rationale=(
            "The paper attributes the critical amplitude to the contacts' presliding, the actuators' "
            "dynamics and their interaction (Section 4.1) without weighing them for a given drive; passmd "
            "weighs them, one cause removed at a time. The agreement band is the one the "
            "critical-amplitude chapters judge Fig. 6 by; half of the departure is the least share that "
            "makes a cause the larger part of it."
        ),
        sensitivity=("Design chapter: the range of the naming share over which the causes named at the "
                     "example drive's A_c stay the same, and the departure against the band."),
    ),
)
#: Periods of a run with rests (its last step counts, as the steady critical-amplitude reading).
_RESTED_PERIODS = PROTOCOL.steady_periods


@dataclass(frozen=True)
class Cause:
    """A candidate cause: its key, its name, what the counterfactual removes, where it applies."""

    key: str
    label: str
    removed: str
    quantities: tuple[str, ...]


#: The candidate causes, in the order they are tried (module docstring).
CAUSES = {c.key: c for c in (
    Cause("flyback", "fly-back overshoot", f"a fly-back of {FLYBACK_PERIODS} actuator periods",
          QUANTITIES),
    Cause("actuator", "actuator dynamics", "rigid actuators", QUANTITIES),
    Cause("ringing", "runner ringing", "the runner at rest at each fly-back",
          ("critical-amplitude", "velocity", "step")),
    Cause("reading", "steady reading", "the first-fly-back reading", ("critical-amplitude",)),
    Cause("share", "fly-back's share of the period", f"a fly-back {SHARE_FACTOR:g} times shorter",
          ("velocity", "step", "gain")),
)}


def departs(value: float, expected: float, tolerance: float = AGREEMENT) -> bool:
    """Whether ``value`` departs from ``expected`` by more than ``tolerance`` of it."""
    return bool(abs(value - expected) > tolerance * abs(expected))


def _actuator_period(drive: Drive) -> float:
    return 1.0 / drive.actuator.natural_frequency


def rest_time(drive: Drive, amplitude: float, frequency: float) -> dict:
    """How long x_p must rest after a fly-back at ``amplitude`` for the runner's swing to fall below
    :data:`REST_SWING`: ``rest_s`` (at most :data:`MAX_REST`) and ``swing_left_m`` then."""
    probe = ringing.stick_ringing(drive, amplitude, frequency, hold=MAX_REST)
    times, swings = np.asarray(probe["swing_times_s"]), np.asarray(probe["swing_amplitudes_m"])
    below = np.flatnonzero(swings <= REST_SWING)
    rest = float(times[below[0]]) if below.size else MAX_REST
    return {"rest_s": max(rest, 1.0 / frequency), "swing_left_m": float(ringing.left_after(probe, rest))}


def _changed(drive: Drive, cause: str, amplitude: float, frequency: float,
             quantity: str) -> tuple[Drive | None, str]:
    """The drive with ``cause`` removed (None where it does not apply) and what was changed."""
    t_fb = waveforms.flyback_time(amplitude, drive)
    flexible = drive.actuator_model == "flexible"
    if cause == "flyback":
        if not flexible:
            return None, "rigid actuators do not overshoot"
        longer = FLYBACK_PERIODS * _actuator_period(drive)
        if longer <= t_fb:
            return None, (f"the fly-back ({t_fb * 1e6:.3g} µs) already lasts {FLYBACK_PERIODS} actuator "
                          "periods")
        if longer >= 0.5 / frequency:
            return None, (f"a fly-back of {FLYBACK_PERIODS} actuator periods ({longer * 1e6:.3g} µs) does "
                          "not fit in half the period")
        longer_drive = drive.replace(amplifier=replace(drive.amplifier, flyback=longer))
        return longer_drive, f"a {longer * 1e6:.3g} µs fly-back"
    if cause == "actuator":
        if not flexible:
            return None, "the actuators are rigid already"
        return drive.replace(actuator_model="rigid"), "rigid actuators"
    if cause == "ringing":  # a moving runner (velocity, step) is stopped by rests shorter than a swing
        swing = 1.0 / theory.runner_frequency(drive, in_series=True)
        if quantity != "critical-amplitude" and 1.0 / frequency < swing:
            return None, (f"the period ({1e6 / frequency:.3g} µs) is shorter than one swing of the runner "
                          f"({swing * 1e6:.3g} µs): no ringing between fly-backs to remove")
        return drive, CAUSES[cause].removed
    if cause == "share":
        shorter = t_fb / SHARE_FACTOR
        return (drive.replace(amplifier=replace(drive.amplifier, flyback=shorter)),
                f"a {shorter * 1e6:.3g} µs fly-back")
    return drive, CAUSES[cause].removed


def counterfactual_point(quantity: str, cause: str, drive: Drive, frequency: float, amplitude: float,
                         reading: str = "steady") -> dict:
    """The result at one point with ``cause`` removed (a point of :func:`passmd.runtime.sweep.run`).

    ``amplitude`` is the point's amplitude, or for the critical amplitude the A_c found (the
    fly-back and the ringing the counterfactual removes are those at it).

    Returns
    -------
    dict
        ``value`` (SI; None where the cause does not apply or the counterfactual finds none),
        ``expected`` (the closed form of the counterfactual's drive, critical amplitude only),
        ``changed`` (what the counterfactual changed, or why it does not apply), ``tried`` (whether
        it was run; with no value, ``changed`` says why), ``rest_s`` and
        ``swing_left_m`` (the ``ringing`` cause: the rest after each fly-back and the swing left).
    """
    check_choice("quantity", quantity, QUANTITIES)
    check_choice("cause", cause, tuple(CAUSES))
    out = {"value": None, "expected": None, "changed": "", "tried": False, "rest_s": None,
           "swing_left_m": None}
    if quantity not in CAUSES[cause].quantities or (cause == "reading" and reading != "steady") or (
            cause == "ringing" and quantity == "critical-amplitude" and reading != "steady"):
        out["changed"] = "does not apply"
        return out
    changed, text = _changed(drive, cause, amplitude, frequency, quantity)
    out["changed"] = text
    if changed is None:
        return out
    out["tried"] = True
    try:
        _counterfactual(out, quantity, cause, drive, changed, frequency, amplitude, reading)
    except (SimulationError, ValueError) as exc:  # the counterfactual cannot be run: said, not hidden
        out.update(value=None, changed=f"{out['changed']}: not computed ({str(exc).splitlines()[0]})")
    return out


def _counterfactual(out: dict, quantity, cause, drive, changed, frequency, amplitude, reading) -> None:
    """Fill ``out`` with the counterfactual's value (:func:`counterfactual_point`)."""
    rest = 0.0
    if cause == "ringing":
        found = rest_time(drive, amplitude, frequency)
        rest = found["rest_s"]
        out.update(rest_s=rest, swing_left_m=found["swing_left_m"])
        out["changed"] = (f"the runner at rest at each fly-back ({rest * 1e3:.3g} ms rests, "
                          f"±{found['swing_left_m'] * 1e9:.2g} nm left)")
    if quantity == "critical-amplitude":
        protocol = "first" if cause == "reading" else reading
        found = critical_amplitude.critical_amplitude(changed, protocol=protocol, frequency=frequency,
                                                      rest=rest)
        out["value"] = None if math.isnan(found["critical_amplitude_m"]) else found["critical_amplitude_m"]
        if out["value"] is None:
            out["changed"] += ": no onset up to the full stroke"
        out["expected"] = theory.drive_theory(changed)["analytic_critical_amplitude_m"]
    elif cause == "ringing":  # velocity or step: the last step of a run with rests
        steps = critical_amplitude.steady_step(changed, amplitude, frequency, periods=_RESTED_PERIODS,
                                               rest=rest)
        out["value"] = steps["last_step_m"] * (frequency if quantity == "velocity" else 1.0)
    elif quantity == "gain":
        from passmd.protocols.maps import gain_point

        gain = gain_point(changed, amplitude, frequency)
        out["value"] = gain["gain_m_per_s"]
        if gain["note"]:
            out["changed"] += f": {gain['note']}"
    else:
        run = velocity.steady_run(changed, amplitude, frequency, "sawtooth", "cut")
        out["value"] = run["velocity_m_per_s"] if quantity == "velocity" else run["step_m"]


def _why(cause: str, point: dict) -> str:
    """What the cause is at this point, from the drive's numbers (a fact, not a verdict: the share says
    whether it matters)."""
    drive, frequency, amplitude = point["drive"], point["frequency"], point["amplitude"]
    t_fb = waveforms.flyback_time(amplitude, drive)
    rule = drive.amplifier.flyback
    kind = f"{rule} " if isinstance(rule, str) else ""
    if cause == "flyback" and drive.actuator_model == "flexible":
        period = _actuator_period(drive)
        relation = "shorter than" if t_fb < period else f"{t_fb / period:.2g} times"
        return (f"the {t_fb * 1e6:.3g} µs {kind}fly-back at A = {amplitude * 1e9:.4g} nm is {relation} the "
                f"actuator's {period * 1e6:.3g} µs period, so the actuator overshoots")
    if cause == "share":
        return (f"the {t_fb * 1e6:.3g} µs fly-back takes {100 * t_fb * frequency:.0f} % of the "
                f"{1e6 / frequency:.3g} µs period")
    if cause == "actuator" and drive.actuator_model == "flexible":
        act = drive.actuator
        return (f"the actuators' compliance and mass (k_p = {act.stiffness:.3g} N/m, "
                f"m_a = {act.mass:.3g} kg, ζ = {act.damping_ratio:.3g})")
    if cause == "ringing":
        return "the runner's swing from the previous fly-back meets the next one"
    if cause == "reading":
        return ("the closed forms describe the onset of full sliding, which the first-fly-back reading "
                "measures")
    return ""


def _number(value) -> float | None:
    """A sweep cell as a float, None for no value (the table holds NaN for it)."""
    return None if value is None or not math.isfinite(float(value)) else float(value)


def _departure(quantity: str, values: list, expected: list, frequencies: list) -> float | None:
    """The departure of one point from its closed form (critical amplitude) or from zero (gain), or of
    the second of two points from the trend the first sets: the closed form's scaling for the critical
    amplitude, a constant step (a velocity ∝ f) otherwise."""
    if any(v is None for v in values):
        return None
    if len(values) == 1:
        return values[0] - (expected[0] if quantity == "critical-amplitude" else 0.0)
    (p, q), (fp, fq) = values, frequencies
    if quantity == "critical-amplitude":
        return q - p * expected[1] / expected[0]
    return q - p * (fq / fp if quantity == "velocity" else 1.0)


def diagnose(quantity: str, points: list[dict], values: list, *, reading: str = "steady", config=None,
             causes: tuple[str, ...] | None = None) -> dict:
    """Each candidate cause of one departure, by how much its removal takes the departure away.

    Parameters
    ----------
    quantity : {"critical-amplitude", "velocity", "step", "gain"}
        What departs.
    points : list of dict
        One point (its departure from the closed form, or a gain below 0) or two neighbouring points of
        a sweep (the second's departure from the trend the first sets), each ``{"drive", "frequency",
        "amplitude"}``, the amplitude of the critical amplitude being the A_c found.
    values : list
        The result at each point (SI).
    reading : {"steady", "first"}
        The critical amplitude's reading.
    config : passmd.runtime.config.RunConfig, optional
        How the counterfactual points run (cached, in parallel: :func:`passmd.runtime.sweep.run`).
    causes : tuple of str, optional
        The candidate causes to try (default: every one that applies to ``quantity``).

    Returns
    -------
    dict
        ``departure`` (SI), ``expected`` (the closed forms at the points, critical amplitude),
        ``causes``: one dict per cause tried, best explanation first — ``cause`` (name), ``key``,
        ``changed``, ``counterfactual_values`` (SI, one per point), ``counterfactual_value`` (at the
        last point), ``share`` (1 − D'/D; None where it does not apply) — and ``named``: the causes
        whose share is at least :data:`EXPLAINS`.
    """
    check_choice("quantity", quantity, QUANTITIES)
    if len(points) not in (1, 2) or len(values) != len(points):
        raise ValueError("diagnose takes one point, or two neighbouring points, with a value each")
    keys = [k for k in (causes or CAUSES) if quantity in CAUSES[k].quantities]
    expected = [theory.drive_theory(p["drive"])["analytic_critical_amplitude_m"] for p in points]
    frequencies = [p["frequency"] for p in points]
    departure = _departure(quantity, list(values), expected, frequencies)
    calls = [{"quantity": quantity, "cause": k, "drive": p["drive"], "frequency": p["frequency"],
              "amplitude": p["amplitude"], "reading": reading} for k in keys for p in points]
    frame = sweep.run(counterfactual_point, calls, config=config, description="diagnosis")
    rows = frame.to_dict(orient="records")
    found = []
    for i, key in enumerate(keys):
        mine = rows[i * len(points):(i + 1) * len(points)]
        cf = [_number(r["value"]) for r in mine]
        cf_expected = [_number(r["expected"]) for r in mine] if quantity == "critical-amplitude" else expected
        moved = _departure(quantity, cf, cf_expected, frequencies)
        share = None if moved is None or not departure else 1.0 - moved / departure
        found.append({"cause": CAUSES[key].label, "key": key, "changed": mine[-1]["changed"],
                      "counterfactual_values": cf, "counterfactual_value": cf[-1],
                      "counterfactual_expected": (cf_expected[-1] if quantity == "critical-amplitude"
                                                  else None),
                      "share": share, "tried": bool(mine[-1]["tried"]), "why": _why(key, points[-1]),
                      "rest_s": _number(mine[-1]["rest_s"]),
                      "swing_left_m": _number(mine[-1]["swing_left_m"])})
    found.sort(key=lambda c: math.inf if c["share"] is None else abs(1.0 - c["share"]))
    named = [c["cause"] for c in found if c["share"] is not None and c["share"] >= EXPLAINS]
    return {"quantity": quantity, "values": list(values), "expected": expected, "departure": departure,
            "causes": found, "named": named}


#: Most departures of one sweep diagnosed (the largest first); each costs a few runs per cause.
MAX_DIAGNOSED = 3


def sweep_departures(quantity: str, values, expected, frequencies, resolution,
                     limit: int = MAX_DIAGNOSED) -> list[tuple[int, ...]]:
    """The points of a one-axis sweep (in axis order) whose departure :func:`diagnose` should explain.

    * critical amplitude: neighbours (i, i + 1) whose second departs from the trend the first sets
      (the closed form's scaling, :func:`diagnose`) by more than :data:`AGREEMENT` of it: a jump;
    * velocity, step: each turn of the curve (:func:`passmd.protocols.ringing.turns`, changes beyond
      ``resolution``) and the point after it: a roll-off or a non-monotone stretch;
    * gain: the most negative gain below −``resolution``: Eq. 15 slower than the saw-tooth.

    The largest ``limit`` departures, as index tuples; values None or NaN are skipped.
    """
    check_choice("quantity", quantity, QUANTITIES)
    v = [_number(x) for x in values]
    if quantity == "gain":
        below = [(x, i) for i, x in enumerate(v) if x is not None and x < -float(resolution[i])]
        return [(min(below)[1],)] if below else []
    if quantity == "critical-amplitude":
        found = []
        for i in range(len(v) - 1):
            if v[i] is None or v[i + 1] is None:
                continue
            trend = v[i] * float(expected[i + 1]) / float(expected[i])
            if departs(v[i + 1], trend):
                found.append((abs(v[i + 1] - trend), (i, i + 1)))
        return [pair for _, pair in sorted(found, reverse=True)[:limit]]
    found = []
    for i in ringing.turns(values, resolution):
        if i + 1 < len(v) and v[i] is not None and v[i + 1] is not None:
            ratio = float(frequencies[i + 1]) / float(frequencies[i]) if quantity == "velocity" else 1.0
            trend = v[i] * ratio
            found.append((abs(v[i + 1] - trend), (i, i + 1)))
    return [pair for _, pair in sorted(found, reverse=True)[:limit]]


def running_max(values) -> list[float | None]:
    """The largest value up to each point (None where none yet): along an axis, the amplitude that
    moves the runner at every point up to there."""
    out, top = [], None
    for x in values:
        x = _number(x)
        if x is not None and (top is None or x > top):
            top = x
        out.append(top)
    return out
