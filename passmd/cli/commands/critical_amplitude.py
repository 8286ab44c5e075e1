"""``passmd critical-amplitude``: the simulated and the analytic critical amplitude A_c."""

from __future__ import annotations

import math
import textwrap

from passmd.cli import kernels
from passmd.cli.drive import build_drive, drive_rows
from passmd.cli.errors import UsageError
from passmd.cli.notes import ringing_text
from passmd.cli.options import FREQUENCY, THRESHOLD, TOLERANCE, add_drive_options
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

_EPILOG = textwrap.dedent("""\
    Three readings of A_c, each for a different question: analytic (closed form, no
    dynamics: a first sizing), simulated steady (what continuous operation needs, read at the
    drive's own preload and frequency), simulated first fly-back (a start from rest slips at once).

    The simulated A_c comes from the critical-amplitude chapters' search
    (passmd.protocols.critical_amplitude): bisection on [0, A_max] with one of two
    protocols, reporting its final bracket. steady: the last step of a run of
    --periods saw-tooth periods from rest exceeds --threshold; first: every contact
    slides fully in the first fly-back from virgin contacts.

    --json keys (SI units): reading, critical_amplitude_m (null if none up to A_max),
    bracket_m, analytic_critical_amplitude_m, critical_amplitude_rigid_m,
    critical_amplitude_flexible_m, protocol, threshold_m, tolerance_m, frequency_Hz,
    periods, flyback, simulations, wall_time_s, ringing{...} (the runner's swing after a
    fly-back at A_c and what is left of it at the next: as passmd run), drive{...}

    The steady A_c can jump up and down with preload, frequency or radius: the runner still
    rings from the previous fly-back when the next one starts, and whether that one slips
    depends on where in its swing the runner is (the "runner ringing" row says when).""")


def add_parser(command) -> None:
    p = command("critical-amplitude", "simulated and analytic critical amplitude A_c", _EPILOG)
    add_drive_options(p)
    group = p.add_argument_group("search")
    group.add_argument("--protocol", choices=("steady", "first"), default="steady",
                       help="steady-state A_c or first-fly-back onset (default: steady)")
    FREQUENCY.add(group)
    group.add_argument("--periods", type=int, default=PROTOCOL.steady_periods, metavar="N",
                       help=f"periods of a steady-state run (default: {PROTOCOL.steady_periods})")
    THRESHOLD.add(group)
    TOLERANCE.add(group)
    group.add_argument("--analytic-only", action="store_true", help="skip the simulation (default: off)")
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
    frequency = FREQUENCY.parse_or(args, PROTOCOL.drive_frequency)
    if args.analytic_only:
        return {}
    kernels.notice_on_compile()
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
    }


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
    check_results(record)
    if args.json:
        emit_json(record, out)
        return 0
    rows = [] if args.analytic_only else _search_rows(record, drive)
    eq = "Eq. 7/11" if drive.actuator_model == "rigid" else "Eq. 8/12"
    rows.append((f"analytic A_c ({eq})", fmt(record["analytic_critical_amplitude_m"], "nm")))
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
    return [
        (f"simulated A_c, {record['protocol']} reading",
         f"{fmt(found, 'nm')}  (bracket {from_si(lo, 'nm'):.4g}–{from_si(hi, 'nm'):.4g} nm)"
         if found is not None else
         f"none up to the full stroke {fmt(a_max, 'nm')} ({criterion})"),
        ("search", f"{record['protocol']}: {criterion}, "
                   f"f = {fmt(record['frequency_Hz'], 'kHz')}, {flyback_label(record['flyback'])} fly-back, "
                   f"{record['simulations']} simulations"),
        ("runner ringing", f"at A = {fmt(record['ringing']['amplitude_m'], 'nm')}: "
                           + ringing_text(record["ringing"], f"the {record['protocol']} A_c"
                                          if record["protocol"] == "steady" else "the first reading")),
    ]
