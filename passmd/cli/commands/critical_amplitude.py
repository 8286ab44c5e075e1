"""``passmd critical-amplitude``: the simulated and the analytic critical amplitude A_c."""

from __future__ import annotations

import math
import textwrap

from passmd.cli import kernels
from passmd.cli.drive import build_drive, drive_rows
from passmd.cli.errors import UsageError
from passmd.cli.notes import diagnosis_rows, hz, ringing_text
from passmd.cli.options import FREQUENCY, THRESHOLD, TOLERANCE, add_drive_options, add_sweep_options
from passmd.cli.output import (
    JSON_HELP,
    check_results,
    describe,
    drive_record,
    emit_json,
    emit_rows,
    flyback_label,
    fmt,
)
from passmd.model.defaults import PROTOCOL
from passmd.runtime.units import from_si

__all__ = ["READINGS", "add_parser", "run_critical_amplitude"]

#: The three readings of A_c, and what each means for a designer.
READINGS = {
    "analytic": "analytic (Eq. 7/8, 11/12): the contacts' presliding plus the actuators' deformation, "
                "no runner dynamics; a first sizing, to be checked by simulation",
    "steady": "simulated steady: where the last step of a run first exceeds the measurable step, what "
              "continuous operation needs at this preload and frequency; read it at the drive's own (the "
              "runner's ringing makes it turn with both)",
    "first": "simulated first fly-back: above it every contact slides fully in the first fly-back from "
             "rest; what a start from rest needs",
}

#: passmd.protocols.diagnosis.AGREEMENT in percent (said here so --help does not import it;
#: tests/test_diagnosis.py checks they agree, and the description below).
AGREEMENT_PERCENT = 10

_EPILOG = textwrap.dedent("""\
    Three readings of A_c, each for a different question: analytic (closed form, no
    dynamics: a first sizing), simulated steady (what continuous operation needs, read at the
    drive's own preload and frequency), simulated first fly-back (a start from rest slips at once).

    The simulated A_c comes from the critical-amplitude chapters' search
    (passmd.protocols.critical_amplitude): bisection on [0, A_max] with one of two
    protocols, reporting its final bracket. steady: the last step of a run of
    --periods saw-tooth periods from rest exceeds --threshold; first: every contact
    slides fully in the first fly-back from virgin contacts.

    The steady A_c is read at one driving frequency (--frequency, default 100 Hz, Section 4.1's
    saw-tooth) and can move several-fold with it. --frequency LO..HI[:lin][:N] reads it at N
    frequencies over a band (log-spaced unless :lin, N default 10; e.g. 100Hz..20kHz) and reports
    the worst case, the largest A_c, with the frequency where it occurs: the amplitude that moves
    the runner at every frequency computed in the band (between two of them it may be larger).
    Band points run in parallel and are cached (--cache-dir), as sweep points.

    Where the simulated A_c departs from its closed form by more than 10 % (the band within which
    the critical-amplitude chapters call the two in agreement), the command computes why: it
    searches A_c again with one candidate cause removed at a time (a fly-back of 10 actuator
    periods, rigid actuators, the runner at rest at each fly-back, the first-fly-back reading) and
    names each cause by the share of the departure its removal takes away (passmd.protocols.diagnosis;
    cached; --no-diagnosis skips it).

    --json keys (SI units): reading, critical_amplitude_m (null if none up to A_max),
    bracket_m, analytic_critical_amplitude_m, critical_amplitude_rigid_m,
    critical_amplitude_flexible_m, protocol, threshold_m, tolerance_m, frequency_Hz,
    periods, flyback, simulations, wall_time_s, ringing{...} (the runner's swing after a
    fly-back at A_c and what is left of it at the next: as passmd run), band{frequencies_Hz,
    critical_amplitudes_m, worst_m, worst_frequency_Hz} (a band only), diagnosis{departure_m,
    causes[{cause, counterfactual_value_m, share, changed, why}], named} (null when A_c agrees
    with its closed form), drive{...}

    The steady A_c can jump up and down with preload, frequency or radius: the runner still
    rings from the previous fly-back when the next one starts, and whether that one slips
    depends on where in its swing the runner is (the "runner ringing" row says when, the
    diagnosis whether it is what moves A_c).""")


def add_parser(command) -> None:
    p = command("critical-amplitude", "simulated and analytic critical amplitude A_c", _EPILOG)
    add_drive_options(p)
    group = p.add_argument_group("search")
    group.add_argument("--protocol", choices=("steady", "first"), default="steady",
                       help="steady-state A_c or first-fly-back onset (default: steady)")
    group.add_argument(FREQUENCY.flag, metavar="f", default=None,
                       help=f"driving frequency, or a band LO..HI[:lin][:N] (e.g. 100Hz..20kHz) whose worst "
                            f"case is reported [kHz; unit required] (default: {FREQUENCY.default})")
    group.add_argument("--periods", type=int, default=PROTOCOL.steady_periods, metavar="N",
                       help=f"periods of a steady-state run (default: {PROTOCOL.steady_periods})")
    THRESHOLD.add(group)
    TOLERANCE.add(group)
    group.add_argument("--analytic-only", action="store_true", help="skip the simulation (default: off)")
    group.add_argument("--no-diagnosis", action="store_true",
                       help="do not compute why A_c departs from its closed form (default: computed where it "
                            f"departs by more than {AGREEMENT_PERCENT} %%)")
    add_sweep_options(p)
    p.add_argument("--json", action="store_true", help=JSON_HELP)
    p.set_defaults(handler=run_critical_amplitude)


def _search(args, drive) -> dict:
    """The simulated A_c of the book's search (every option checked, searched unless --analytic-only)."""
    from passmd.protocols import critical_amplitude

    if args.periods < 2:
        raise UsageError(f"--periods = {args.periods} is out of range: a step needs >= 2 periods")
    if args.threshold is not None and args.protocol == "first":
        raise UsageError("--threshold contradicts --protocol first: the first-fly-back protocol has no "
                         "step threshold (use --protocol steady, or drop --threshold)")
    threshold = THRESHOLD.parse_or(args, PROTOCOL.step_threshold)
    tolerance = TOLERANCE.parse_or(args, PROTOCOL.search_tolerance)
    band = _band(args)
    frequency = FREQUENCY.parse_or(args, PROTOCOL.drive_frequency) if band is None else None
    if args.analytic_only:
        return {}
    kernels.notice_on_compile()
    if band is not None:
        return _band_search(args, drive, band, threshold, tolerance)
    # the book's search (critical-amplitude chapters): one protocol for users and book
    found = critical_amplitude.critical_amplitude(
        drive, protocol=args.protocol, frequency=frequency,
        periods=args.periods, threshold=threshold, tolerance=tolerance,
        progress="long",  # a long search's progress on stderr, also when it is not a terminal
    )
    value = found["critical_amplitude_m"]
    return {
        "reading": f"simulated {args.protocol}",
        "critical_amplitude_m": None if math.isnan(value) else value,
        "bracket_m": [found["bracket_low_m"],
                      None if math.isnan(found["bracket_high_m"]) else found["bracket_high_m"]],
        "protocol": args.protocol,
        "threshold_m": threshold if args.protocol == "steady" else None,
        "tolerance_m": tolerance,
        "frequency_Hz": frequency,
        "periods": args.periods if args.protocol == "steady" else 1,
        "flyback": drive.amplifier.flyback,
        "simulations": found["runs"],
        "wall_time_s": found["wall_time_s"],
        "ringing": _ringing(drive, value, frequency, args),
        "band": None,
    }


def _band(args) -> tuple[float, ...] | None:
    """The frequencies of ``--frequency LO..HI[:lin][:N]`` (log-spaced by default), None for one frequency."""
    raw = getattr(args, "frequency", None)
    if raw is None or ".." not in raw:
        return None
    from passmd.cli.commands.sweep import parse_vary

    spec = raw.strip()
    if not any(part.strip() in ("lin", "linear", "log") for part in spec.split(":")[1:]):
        spec += ":log"
    try:
        axis = parse_vary(f"frequency={spec}")
    except UsageError as exc:
        typed = f"--vary = 'frequency={spec}'"
        raise UsageError(str(exc).replace(typed, f"--frequency = {raw!r}", 1)) from None
    for value in axis.values:
        try:
            FREQUENCY.parse(type(args)(**{**vars(args), "frequency": f"{value!r} Hz"}))
        except (UsageError, ValueError) as exc:
            reason = str(exc).split(" is ", 1)[-1]
            raise UsageError(f"--frequency = {raw!r}: {hz(value)} is {reason}") from None
    return axis.values


def _band_search(args, drive, band, threshold, tolerance) -> dict:
    """A_c at every frequency of the band (cached sweep points), the worst case and where it occurs."""
    from passmd.cli.configuration import run_config
    from passmd.protocols.maps import compute_map

    if args.periods != PROTOCOL.steady_periods or threshold != PROTOCOL.step_threshold or \
            tolerance != PROTOCOL.search_tolerance:
        raise UsageError("--frequency with a band reads A_c with the sweep's protocol: leave --periods, "
                         "--threshold and --tolerance at their defaults (or give one frequency)")
    table = compute_map("critical-amplitude", [{"drive": drive, "frequency": f} for f in band],
                        reading=args.protocol, config=run_config(args), description="critical amplitude band")
    values = [None if v is None or math.isnan(v) else float(v) for v in table["critical_amplitude_m"]]
    found = [(v, f) for v, f in zip(values, band, strict=True) if v is not None]
    worst, at = max(found) if found else (None, None)
    i = list(band).index(at) if at is not None else 0
    row = table.iloc[i]
    ring = {k: row[k] for k in ("ringing_frequency_Hz", "ringing_linear_frequency_Hz", "ringing_amplitude_m",
                                "ringing_decay_time_s",
                                "next_flyback_after_s", "ringing_at_next_flyback_m", "ringing_affects_steps")}
    ring = {k: None if isinstance(v, float) and math.isnan(v) else v for k, v in ring.items()}
    ring["ringing_affects_steps"] = bool(ring["ringing_affects_steps"])
    ring["amplitude_m"] = worst if worst is not None else drive.actuator.full_stroke_amplitude
    high = row["bracket_high_m"]
    return {
        "reading": f"simulated {args.protocol}",
        "critical_amplitude_m": worst,
        "bracket_m": [float(row["bracket_low_m"]), None if high is None or math.isnan(high) else float(high)],
        "protocol": args.protocol,
        "threshold_m": threshold if args.protocol == "steady" else None,
        "tolerance_m": tolerance,
        "frequency_Hz": at if at is not None else band[0],
        "periods": args.periods if args.protocol == "steady" else 1,
        "flyback": drive.amplifier.flyback,
        "simulations": int(sum(table["runs"])),
        "wall_time_s": float(sum(table["wall_time_s"])),
        "ringing": ring,
        "band": {"frequencies_Hz": list(band), "critical_amplitudes_m": values, "worst_m": worst,
                 "worst_frequency_Hz": at},
    }


def _diagnosis(args, drive, record) -> dict | None:
    """Why the simulated A_c departs from its closed form (None where it agrees within the band,
    there is none, or --no-diagnosis)."""
    from passmd.protocols import diagnosis

    found, closed = record.get("critical_amplitude_m"), record["analytic_critical_amplitude_m"]
    if args.no_diagnosis or found is None or not diagnosis.departs(found, closed):
        return None
    from passmd.cli.configuration import run_config

    point = {"drive": drive, "frequency": record["frequency_Hz"], "amplitude": found}
    out = diagnosis.diagnose("critical-amplitude", [point], [found], reading=args.protocol,
                             config=run_config(args))
    causes = [{"cause": c["cause"], "counterfactual_value_m": c["counterfactual_value"], "share": c["share"],
               "changed": c["changed"], "why": c["why"], "key": c["key"], "tried": c["tried"],
               "counterfactual_closed_form_m": c["counterfactual_expected"]} for c in out["causes"]]
    return {"departure_m": out["departure"], "closed_form_m": closed, "causes": causes, "named": out["named"]}


def _ringing(drive, found: float, frequency: float, args) -> dict:
    """The runner's ringing after a fly-back at A_c (at the full stroke if none): whether the steady
    reading depends on it (the first reading has no earlier fly-back)."""
    from passmd.protocols import ringing

    at = drive.actuator.full_stroke_amplitude if math.isnan(found) else found
    ring = ringing.at_frequency(ringing.stick_ringing(drive, at, frequency), frequency)
    ring["ringing_affects_steps"] = ring["ringing_affects_steps"] and args.protocol == "steady"
    return {**{k: None if isinstance(v, float) and math.isnan(v) else v for k, v in ring.items()},
            "amplitude_m": at}


def run_critical_amplitude(args, out) -> int:
    from passmd.model.theory import drive_theory

    drive = build_drive(args)
    theory = drive_theory(drive)
    record = {
        "command": "critical-amplitude",
        "drive": drive_record(drive),
        "analytic_critical_amplitude_m": theory["analytic_critical_amplitude_m"],
        "critical_amplitude_rigid_m": theory["critical_amplitude_rigid_m"],
        "critical_amplitude_flexible_m": theory["critical_amplitude_flexible_m"],
        **_search(args, drive),
    }
    if not args.analytic_only:
        record["diagnosis"] = _diagnosis(args, drive, record)
    check_results(record)
    if args.json:
        emit_json(record, out)
        return 0
    rows = [] if args.analytic_only else _search_rows(record, drive)
    eq = "Eq. 7/11" if drive.actuator_model == "rigid" else "Eq. 8/12"
    analytic = (f"analytic A_c ({eq})", fmt(record["analytic_critical_amplitude_m"], "nm"))
    rows.insert(1 if rows else 0, analytic)
    if record.get("diagnosis"):
        rows += _diagnosis_rows(record, eq)
    rows += [(f"what the {name} reading means", text.split(": ", 1)[1])
             for name, text in READINGS.items()]
    emit_rows(f"passmd critical-amplitude — {describe(drive)}", [*rows, *drive_rows(drive)], out)
    return 0


def _search_rows(record: dict, drive) -> list[tuple[str, str]]:
    found = record["critical_amplitude_m"]
    lo, hi = record["bracket_m"]
    a_max = drive.actuator.full_stroke_amplitude
    if record["protocol"] == "steady":
        criterion = f"last of {record['periods']} steps > {fmt(record['threshold_m'], 'nm')}"
    else:
        criterion = "full sliding of every contact in the first fly-back"
    band = record.get("band")
    where = (f"worst over {hz(band['frequencies_Hz'][0])}–{hz(band['frequencies_Hz'][-1])}, at "
             f"{hz(record['frequency_Hz'])}" if band else f"at {hz(record['frequency_Hz'])}")
    rows = [
        (f"simulated A_c {where}, {record['protocol']} reading",
         f"{fmt(found, 'nm')}  (bracket {from_si(lo, 'nm'):.4g}–{from_si(hi, 'nm'):.4g} nm)"
         if found is not None else
         f"none up to the full stroke {fmt(a_max, 'nm')} ({criterion})"),
    ]
    if band:
        shown = ["–" if v is None else f"{from_si(v, 'nm'):.4g} nm" for v in band["critical_amplitudes_m"]]
        rows.append(("over the band", ", ".join(
            f"{v} at {hz(f)}" for f, v in zip(band["frequencies_Hz"], shown, strict=True))
            + "; the worst case moves the runner at every frequency computed"))
    return rows + [
        ("search", f"{record['protocol']}: {criterion}, "
                   f"{'f over the band' if band else 'f = ' + fmt(record['frequency_Hz'], 'kHz')}, "
                   f"{flyback_label(record['flyback'])} fly-back, {record['simulations']} simulations"),
        ("runner ringing", f"at A = {fmt(record['ringing']['amplitude_m'], 'nm')}: "
                           + ringing_text(record["ringing"], f"the {record['protocol']} A_c"
                                          if record["protocol"] == "steady" else "the first reading",
                                          diagnosed=bool(record.get("diagnosis")))),
    ]


def _diagnosis_rows(record: dict, eq: str) -> list[tuple[str, str]]:
    """The diagnosis in rows: the departure, each cause with its counterfactual A_c and share."""
    found, closed = record["critical_amplitude_m"], record["analytic_critical_amplitude_m"]
    gap = found / closed - 1.0
    side = "below" if gap < 0 else "above"
    symptom = (f"A_c = {fmt(found, 'nm')} lies {100 * abs(gap):.0f} % {side} the closed form's "
               f"{fmt(closed, 'nm')} ({eq}), beyond the {AGREEMENT_PERCENT} % band of agreement")
    diagnosis = record["diagnosis"]
    causes = [{**c, "counterfactual_values": [c["counterfactual_value_m"]],
               "counterfactual_value": c["counterfactual_value_m"],
               "counterfactual_expected": c["counterfactual_closed_form_m"]} for c in diagnosis["causes"]]
    return diagnosis_rows({"causes": causes, "named": diagnosis["named"]}, symptom, "nm", "A_c")
