"""``passmd theory``: the closed forms of a drive configuration (Eqs. 1, 4, 7–14)."""

from __future__ import annotations

import textwrap

from passmd.cli.drive import build_drive, drive_rows
from passmd.cli.options import add_drive_options
from passmd.cli.output import (
    JSON_HELP,
    check_results,
    describe,
    drive_record,
    emit_json,
    emit_rows,
    fmt,
    sides,
)

_EPILOG = textwrap.dedent("""\
    --json keys (SI units): E_star_Pa, G_star_Pa, normal_force_N, contact_radius_m,
    indentation_m, tangential_stiffness_N_per_m, presliding_m, actuator_deformation_m
    (per side: [side 1, side 2] for six contacts), critical_amplitude_rigid_m,
    critical_amplitude_flexible_m, analytic_critical_amplitude_m (for --actuator),
    runner_frequency_Hz (the runner on its contacts, each in series with its actuator: the linear
    estimate of its ringing), runner_frequency_rigid_actuators_Hz (contacts alone),
    runner_frequency_full_slip_Hz (contacts at their full-slip secant stiffness, 2/3 of 2aG*: the
    lowest a sticking swing rings at), actuator_natural_frequency_Hz, drive{...}

    The runner rings after each fly-back a few % below runner_frequency_Hz: its first swings
    micro-slip, which softens the contacts (passmd run and critical-amplitude print the simulated
    ringing beside this estimate).""")


def add_parser(command) -> None:
    p = command("theory", "closed forms of a drive configuration (Eqs. 1, 4, 7–14)", _EPILOG)
    add_drive_options(p)
    p.add_argument("--json", action="store_true", help=JSON_HELP)
    p.set_defaults(handler=run_theory)


def run_theory(args, out) -> int:
    from passmd.model.theory import drive_theory, runner_frequency

    drive = build_drive(args)
    result = drive_theory(drive)
    result["runner_frequency_Hz"] = runner_frequency(drive, in_series=True)
    result["runner_frequency_rigid_actuators_Hz"] = runner_frequency(drive)
    result["runner_frequency_full_slip_Hz"] = runner_frequency(drive, in_series=True, full_slip=True)
    result["actuator_natural_frequency_Hz"] = drive.actuator.natural_frequency
    check_results(result)
    if args.json:
        emit_json({"command": "theory", "drive": drive_record(drive), **result}, out)
        return 0
    counts = [g.count for g in drive.contact_groups] or None  # another arrangement: one value per group

    def per_group(values, unit):
        return sides(values, unit, counts=counts)

    rows = [
        ("E* (Eq. 4)", fmt(result["E_star_Pa"], "GPa")),
        ("G* (Eq. 4)", fmt(result["G_star_Pa"], "GPa")),
        ("normal force per contact F_N (Eq. 1)", per_group(result["normal_force_N"], "N")),
        ("Hertz contact radius a", per_group(result["contact_radius_m"], "mm")),
        ("indentation d", per_group(result["indentation_m"], "nm")),
        ("tangential stiffness 2aG*", per_group(result["tangential_stiffness_N_per_m"], "N/m")),
        ("presliding u_x,max (Eq. 7/10)", per_group(result["presliding_m"], "nm")),
        ("actuator deformation u_x,a (Eq. 9/14)", per_group(result["actuator_deformation_m"], "nm")),
        ("A_c, rigid actuators (Eq. 7/11)", fmt(result["critical_amplitude_rigid_m"], "nm")),
        ("A_c, flexible actuators (Eq. 8/12)", fmt(result["critical_amplitude_flexible_m"], "nm")),
        ("runner-on-contacts frequency", _runner_text(drive, result)),
        ("bare actuator frequency", fmt(result["actuator_natural_frequency_Hz"], "kHz")),
    ]
    emit_rows(f"passmd theory — {describe(drive)}", [*rows, *drive_rows(drive)], out)
    return 0


def _runner_text(drive, result) -> str:
    """The runner's linear frequency with the actuators in series, and what it leaves out."""
    linear = fmt(result["runner_frequency_Hz"], "kHz")
    if drive.actuator_model == "rigid":
        return (f"{linear} (√(Σ 2aG* / m_r) / 2π; the first swings after a fly-back micro-slip and ring down "
                f"to {fmt(result['runner_frequency_full_slip_Hz'], 'kHz')})")
    return (f"{linear} (each contact's 2aG* in series with its actuator's k_p; "
            f"{fmt(result['runner_frequency_rigid_actuators_Hz'], 'kHz')} with rigid actuators); the first "
            "swings after a fly-back micro-slip and ring down to "
            f"{fmt(result['runner_frequency_full_slip_Hz'], 'kHz')} (contacts at their full-slip secant "
            "stiffness)")
