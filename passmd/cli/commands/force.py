"""``passmd force``: the generated force against the load cell at stall (Section 4.2)."""

from __future__ import annotations

import re
import textwrap

from passmd.cli import kernels
from passmd.cli.commands.run import check_memory, check_output_paths, waveform_args, write_outputs
from passmd.cli.drive import build_drive, drive_rows
from passmd.cli.errors import UsageError
from passmd.cli.options import add_drive_options, add_output_options, add_simulation_options
from passmd.cli.output import check_results, describe, drive_record, emit_json, emit_rows, fmt
from passmd.cli.result_bounds import ResultError
from passmd.model.defaults import PROTOCOL

__all__ = ["add_parser", "run_force"]

_EPILOG = textwrap.dedent("""\
    Runs the saw-tooth from rest with the load cell at its free length and lengthens
    the run (from --periods, by 1.5 to 4 times, up to --max-periods) until the force-generation
    chapter's stall criterion holds; reports whether it did. A stall force never exceeds
    the Coulomb bound mu*sum(F_N); the force still to come is given only where its
    extrapolation is credible (else null, and remaining_force_note says why).

    --json keys (SI units): generated_force_N (k times the mean runner position over the
    last period), converged, coulomb_bound_N, periods, periods_simulated,
    remaining_force_N, remaining_force_note, force_spread_N, mean_friction_N,
    no_slip_reference_force_N, last_step_m, net_displacement_m, wall_time_s, cpu_time_s,
    amplitude_m, frequency_Hz, drive{...}""")


_SWING_NOTE = ("the load cell's period mean is still above μΣF_N: the runner swings on the load cell, "
               "a transient, not a stall force; raise --max-periods")


def add_parser(command) -> None:
    p = command("force", "generated force against the load cell at stall (Section 4.2)", _EPILOG)
    add_drive_options(p)
    add_simulation_options(p, default_periods=PROTOCOL.stall_periods)
    p.add_argument("--max-periods", type=int, default=PROTOCOL.stall_max_periods, metavar="N",
                   help="longest run before a point is reported as not stalled "
                        f"(default: {PROTOCOL.stall_max_periods})")
    add_output_options(p)
    p.set_defaults(handler=run_force)


def _check_options(args, drive):
    """(amplitude, frequency) in SI; the options the stall protocol does not take are refused."""
    if args.waveform != "sawtooth":
        raise UsageError(
            "--waveform optimized is not supported by force: the stall protocol of the force-generation "
            "chapter (Section 4.2) drives with the saw-tooth; use `passmd run --waveform optimized "
            "--load-cell` for one run against the load cell"
        )
    if args.springs is not None:
        raise UsageError("--springs is not supported by force: the stall runs use the exact contact")
    amplitude, frequency = waveform_args(args, drive)
    from passmd.protocols.stall import STALL_WINDOW

    shortest = STALL_WINDOW + 1  # the stall criterion compares the means of a window of periods
    if args.periods < shortest:
        raise UsageError(f"--periods = {args.periods} is out of range: must be >= {shortest} (the stall "
                         "criterion's window of periods, plus one)")
    if args.max_periods < args.periods:
        raise UsageError(f"--max-periods = {args.max_periods} is out of range: must be >= --periods "
                         f"({args.periods})")
    check_memory(args, "--max-periods")
    check_output_paths(args)
    return amplitude, frequency


def run_force(args, out) -> int:
    from passmd.protocols import stall

    drive = build_drive(args, load_cell=True)
    amplitude, frequency = _check_options(args, drive)
    kernels.notice_on_compile()
    # the force-generation chapter's stall protocol: runs from rest, lengthened until stalled
    try:
        found = stall.generated_force(drive, amplitude, frequency,
                                      initial_periods=args.periods, max_periods=args.max_periods,
                                      progress="long")  # on stderr, also off a terminal
    except ValueError as exc:  # name the command's options, not the library's parameters
        text = re.sub(r"\binitial_periods\b", "--periods", str(exc))
        raise UsageError(re.sub(r"\bmax_periods\b", "--max-periods", text)) from exc
    except stall.ForceBoundError as exc:
        raise ResultError(str(exc)) from exc
    check_results(found)
    force, bound = found["generated_force_N"], found["coulomb_bound_N"]
    # Only the runner's inertia carries a period mean past μΣF_N, in a run cut short while the
    # runner swings on the load cell: that reading is no generated force, and no force above
    # the Coulomb bound is reported.
    swinging = not found["converged"] and abs(force) > bound
    if args.csv or args.plot:  # the reported run again, for its time series
        from passmd.model import waveforms
        from passmd.plots.force_generation import stall_trace_figure
        from passmd.solver import simulation

        wave = waveforms.sawtooth(amplitude, frequency, drive, periods=found["periods"])
        shown = None if swinging else force
        write_outputs(args, simulation.simulate(drive, wave, max_points=args.max_points),
                      figure=lambda result, title: stall_trace_figure(result, title, shown, bound))
    record = {"command": "force", "waveform": "sawtooth", "flyback": drive.amplifier.flyback,
              "amplitude_m": amplitude, "frequency_Hz": frequency, "drive": drive_record(drive), **found}
    if swinging:
        record["generated_force_N"] = None
        record["generated_force_note"] = _SWING_NOTE
    if args.json:
        emit_json(record, out)
        return 0
    label, state = "generated force k·x̄_r", "stalled"
    shown = fmt(force, "N")
    if not found["converged"]:
        state = f"NOT stalled after {found['periods_simulated']} periods"
        if swinging:
            shown, state = "not determined", f"{state}: {_SWING_NOTE}"
    if found["remaining_force_N"] is None:
        to_come = f"still to come not estimated: {found['remaining_force_note']}"
    else:
        to_come = f"still to come ≈ {fmt(found['remaining_force_N'], 'N')}"
    rows = [
        ("waveform", f"sawtooth, A = {fmt(amplitude, 'nm')}, f = {fmt(frequency, 'kHz')}"),
        (label, f"{shown}  ({state})"),
        ("Coulomb bound μΣF_N", fmt(bound, "N")),
        ("run reported", f"{found['periods']} periods from rest; {to_come}"),
        ("last step", fmt(found["last_step_m"], "nm")),
        ("integration", f"{found['periods_simulated']} periods, {found['wall_time_s']:.3g} s"),
    ]
    emit_rows(f"passmd force — {describe(drive)}, load cell k = "
              f"{fmt(drive.load_cell_stiffness, 'N/m')}", [*rows, *drive_rows(drive)], out)
    return 0
