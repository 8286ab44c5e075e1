"""``passmd run``: one simulation of a driving waveform from rest; the checks ``force`` shares."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import NamedTuple

from passmd.cli import kernels, startup
from passmd.cli.commands.contact import check_springs
from passmd.cli.drive import _typed, build_drive, drive_rows
from passmd.cli.errors import UsageError
from passmd.cli.notes import hz, ringing_text
from passmd.cli.options import (
    AMPLITUDE,
    FREQUENCY,
    Quantity,
    add_drive_options,
    add_output_options,
    add_simulation_options,
)
from passmd.cli.output import (
    check_output_file,
    check_results,
    describe,
    drive_record,
    emit_json,
    emit_rows,
    fmt,
    nm,
)
from passmd.cli.result_bounds import check_run_bounds
from passmd.cli.streams import available_memory, check_new_outputs, check_outputs, create_outputs
from passmd.model.defaults import PROTOCOL
from passmd.runtime.units import from_si

__all__ = ["RunOptions", "add_parser", "check_memory", "check_output_paths", "check_run_options", "run_run",
           "simulate", "waveform_args", "write_outputs"]

_RUN_KEYS = """\
By default one run of --periods periods from rest; its mean velocity averages from rest.
--steady measures instead as the book does (passmd.protocols.velocity): max(20, f·5 ms)
periods from rest, the velocity the slope of the period-mean position over the run's
second half ('steady' in --json: velocity_m_per_s, velocity_drift, step_m). It is not
the default: a few periods from rest are what the paper's Fig. 9a and the step measure.
--waveform optimized designs t_s, t_a, Δ_a by Eq. 15 from the drive's own saw-tooth
response (--design-response: the 100 Hz response of Section 5.2, or the one at --frequency);
--settling-time, --acceleration-time, --acceleration-amplitude replace them. Eq. 15's period
needs t_s + t_a, the fly-back and a slow ramp: above the highest frequency at which it fits
(said in the output, eq15_highest_frequency_Hz in --json) the run is refused.

--json keys (SI units): final_position_m, settled_positions_m, step_sizes_m,
back_steps_m, mean_velocity_m_per_s (>= 2 periods), periods, frequency_Hz, amplitude_m,
integrator_steps and the integrator's step sizes (keys ending in _time_step_s), wall_time_s, waveform,
flyback, protocol, drive{...}, design{...}, eq15_highest_frequency_Hz and
design_given_by_options (optimized),
steady{...} (--steady), ringing{ringing_frequency_Hz, ringing_amplitude_m, ringing_decay_time_s,
next_flyback_after_s, ringing_at_next_flyback_m, ringing_affects_steps}: the runner's swing
after a saw-tooth fly-back of this amplitude (passmd.protocols.ringing) and what is left of it
when the next fly-back starts; velocity_drift (--steady) is the velocity of the run's fourth
quarter minus that of its third, over the velocity: near 0 when the run is steady"""

#: Bytes per recorded sample (time, piezo/runner positions and velocities, per-group
#: contact columns, with the DataFrame/plot copies) and per period (waveform breakpoints,
#: per-period measures) used to estimate a run's memory before allocating it.
_BYTES_PER_SAMPLE = 4 * 8 * (4 + 3 * 6)
_BYTES_PER_PERIOD = 8 * 64

#: Options that replace a part of the Eq. 15 design of --waveform optimized (OptimizedDesign fields).
EQ15_OVERRIDES = (
    Quantity("--settling-time", "us", "t_s", "Eq. 15 settling time (optimized waveform)",
             "1/(2 f_s) of the saw-tooth response", 0.0, False, field="settling_time"),
    Quantity("--acceleration-time", "us", "t_a", "Eq. 15 acceleration time (optimized waveform)",
             "u_x,max/(V_a − V_r)", field="acceleration_time"),
    Quantity("--acceleration-amplitude", "nm", "Δ_a", "Eq. 15 acceleration amplitude (optimized waveform)",
             "V_a t_a, V_a the slew-rate limit", field="acceleration_amplitude"),
)

#: Image formats --plot can write (matplotlib's Agg/PDF/SVG/PS backends).
_PLOT_FORMATS = ("png", "pdf", "svg", "ps", "eps", "jpg", "jpeg", "tif", "tiff", "webp")


#: The names ``--scheme`` takes (:data:`passmd.solver.steps.SCHEMES`; listed here so that the parser
#: loads no solver module).
SCHEME_NAMES = ("controlled", "reference", "adaptive", "quasi-static", "fixed")

_DEFAULT_PERIODS = 3
#: Fewest periods of a --steady run: its second half must hold two quarters of >= 1 period.
_STEADY_MIN_PERIODS = 4


def add_parser(command) -> None:
    p = command("run", "one simulation of a driving waveform from rest", _RUN_KEYS +
                ", generated_force_N (with --load-cell)")
    add_drive_options(p)
    add_simulation_options(p, default_periods=_DEFAULT_PERIODS)
    p.set_defaults(periods=None)  # --steady's own length unless given
    p.add_argument("--load-cell", action="store_true",
                   help="the runner pushes against the load cell (default: off, free runner)")
    p.add_argument("--scheme", choices=SCHEME_NAMES, default="controlled",
                   help="integration scheme (passmd.solver.steps.SCHEMES): controlled, the default; "
                        "reference, the error-controlled step the default is tested against; adaptive, "
                        "quasi-static and fixed, the explicit schemes of the convergence study (default: "
                        "controlled)")
    group = p.add_argument_group("steady velocity and the Eq. 15 design")
    group.add_argument("--steady", action="store_true",
                       help="the book's steady-velocity protocol: max(20, f·5 ms) periods from rest (unless "
                            "--periods), velocity from the second half's period means (default: off, the "
                            "mean velocity of --periods periods from rest)")
    group.add_argument("--design-response", choices=("paper", "driving"), default="paper",
                       help="saw-tooth response the Eq. 15 design is made from: paper, the 100 Hz response "
                            "of Section 5.2 (one design per drive and amplitude, whose micro-vibration no "
                            "later fly-back cuts short); driving, the response at --frequency "
                            "(default: paper)")
    for q in EQ15_OVERRIDES:
        q.add(group)
    add_output_options(p)
    # collection stays paused through the imports and the kernels' loading (passmd.cli.startup)
    p.set_defaults(handler=run_run, resumes_collector=True)


def waveform_args(args, drive):
    """(amplitude, frequency) in SI after the display-unit checks."""
    a_max = drive.actuator.full_stroke_amplitude
    amplitude = AMPLITUDE.parse_or(args, a_max)
    if amplitude > a_max * (1 + 1e-12):
        raise UsageError(
            f"--amplitude = {from_si(amplitude, 'nm'):.10g} nm is out of range: must be <= "
            f"{from_si(a_max, 'nm'):.10g} nm, the actuator's full stroke (--full-stroke-amplitude)"
        )
    frequency = FREQUENCY.parse_or(args, PROTOCOL.drive_frequency)
    if getattr(args, "steady", False) and args.periods is None:
        from passmd.protocols.velocity import steady_periods

        args.periods = steady_periods(frequency)
    elif args.periods is None:
        args.periods = _DEFAULT_PERIODS
    if getattr(args, "steady", False) and args.periods < _STEADY_MIN_PERIODS:
        raise UsageError(f"--periods = {args.periods} is out of range with --steady: must be an integer >= "
                         f"{_STEADY_MIN_PERIODS} (the velocity of the second half, and the drift between its "
                         "quarters, need two periods each)")
    if args.periods < 1:
        raise UsageError(f"--periods = {args.periods} is out of range: must be an integer >= 1")
    return min(amplitude, a_max), frequency


def check_memory(args, periods_flag: str = "--periods") -> None:
    """Refuse a run whose records would not fit in memory (estimated before allocating)."""
    if args.max_points < 2:
        raise UsageError(f"--max-points = {args.max_points} is out of range: must be an integer >= 2")
    periods = max(args.periods, getattr(args, "max_periods", 0) or 0)
    need = args.max_points * _BYTES_PER_SAMPLE + periods * _BYTES_PER_PERIOD
    available = available_memory()
    if available is not None and need > available // 2:
        raise UsageError(
            f"--max-points = {args.max_points} with {periods_flag} = {periods} needs about "
            f"{need / 2**30:.3g} GiB, more than half the {available / 2**30:.3g} GiB available: "
            "lower --max-points or the number of periods"
        )


def check_output_paths(args) -> None:
    """--csv/--plot: a file name in an existing directory, a known image format, two different
    files neither of which is where standard output goes (before running; blank names are
    refused by the parser)."""
    for flag, name in (("--csv", args.csv), ("--plot", args.plot)):
        if name is not None:
            check_output_file(flag, name)
    if args.plot is not None:
        suffix = Path(args.plot).suffix.lower().lstrip(".")
        if suffix not in _PLOT_FORMATS:
            raise UsageError(f"--plot = {args.plot!r} has {'no' if not suffix else 'an unknown'} image "
                             f"extension: must end in one of {', '.join('.' + f for f in _PLOT_FORMATS)}")
    check_outputs({f"--csv {args.csv}": args.csv, f"--plot {args.plot}": args.plot})
    check_new_outputs(_named(args), overwrite=args.overwrite)


def _named(args) -> dict[str, str]:
    """--csv and --plot given: path -> the option as typed."""
    return {name: f"{flag} {name}" for flag, name in (("--csv", args.csv), ("--plot", args.plot)) if name}


class RunOptions(NamedTuple):
    """The options of a run, checked once (:func:`check_run_options`), in SI."""

    amplitude: float
    frequency: float
    #: None: the exact contact; else the discrete contact's springs (>= 2)
    springs: int | None
    #: the Eq. 15 design's fields the options replace (--settling-time, ...), by field
    design_overrides: dict


def check_run_options(args, drive) -> RunOptions:
    """Every option of ``run`` that is not the drive's, checked before anything runs."""
    amplitude, frequency = waveform_args(args, drive)
    overrides = [q.flag for q in EQ15_OVERRIDES if getattr(args, q.dest) is not None]
    if args.design_response != "paper" and args.waveform != "optimized":
        overrides.insert(0, f"--design-response {args.design_response}")
    if overrides and args.waveform != "optimized":
        raise UsageError(f"{overrides[0]} needs --waveform optimized: it replaces a part of the Eq. 15 "
                         "design")
    # Δ_a first: of several refused values the one the amplitude bounds is reported
    given = {q.field: q.parse(args) for q in (EQ15_OVERRIDES[2], *EQ15_OVERRIDES[:2])}
    given = {name: value for name, value in given.items() if value is not None}
    delta = given.get("acceleration_amplitude")
    if delta is not None and not delta < amplitude:
        raise UsageError(f"--acceleration-amplitude = {args.acceleration_amplitude} is out of range: must "
                         f"be < {fmt(amplitude, 'nm')}, the actuation amplitude A (Eq. 15: the fast segment "
                         "ends below A)")
    return RunOptions(amplitude, frequency, check_springs(args.springs), given)


def simulate(args, drive, options: RunOptions):
    """(result, Eq. 15 design or None) of the run the options describe (saw-tooth or Eq. 15);
    ``options`` from :func:`check_run_options`."""
    startup.load_numba_without_blas_probe()
    from passmd.model import optimized_waveform, waveforms
    from passmd.protocols import eq15
    from passmd.solver import simulation

    amplitude, frequency, springs, given = options
    if args.waveform == "optimized":
        # Eq. 15, designed from this drive's own simulated saw-tooth response (first period a
        # saw-tooth, as in the paper); a ValueError (e.g. Δ_a ≥ A) is a usage error
        kernels.notice_on_compile()  # the design simulates: every option is checked by now
        design = eq15.optimized_design(amplitude, drive, response_frequency=eq15.
                                       response_frequency(frequency, args.design_response))
        if given:  # the user's values replace the design's (its f_s, V_r, u_x,max stay as measured)
            design = replace(design, **given)
        _check_eq15_fits(args, design, amplitude, frequency, drive)
        wave = optimized_waveform.optimized(amplitude, frequency, drive, periods=args.periods,
                                            design=design)
    else:
        design = None
        wave = waveforms.sawtooth(amplitude, frequency, drive, periods=args.periods)
        kernels.notice_on_compile()  # after the last check of the options: a refusal stays one line
    result = simulation.simulate(
        drive, wave, contact_model="exact" if springs is None else "discrete",
        springs=PROTOCOL.springs if springs is None else springs, max_points=args.max_points,
        scheme=args.scheme, progress="long",  # a long run's progress on stderr, also off a terminal
    )
    return result, design


def _check_eq15_fits(args, design, amplitude, frequency, drive) -> None:
    """Refuse a --frequency at which Eq. 15's period does not fit, naming the highest that does."""
    from passmd.model import optimized_waveform

    f_max = optimized_waveform.highest_fitting_frequency(design, amplitude, drive)
    if optimized_waveform.optimized_timing(design, amplitude, frequency, drive)["settling_fits"]:
        return
    given = [f"{flag} {getattr(args, dest)}" for flag, dest in (("--settling-time", "settling_time"),
                                                              ("--acceleration-time", "acceleration_time"))
             if getattr(args, dest)]
    source = " and ".join(given) if given else f"the {hz(design.response_frequency)} saw-tooth response"
    remedy = f"; lower {' or '.join(g.split()[0] for g in given)}, or give a lower --frequency" \
        if given and args.frequency is None else ""
    raise UsageError(
        f"--frequency = {_typed('--frequency', args, frequency)} is out of range for --waveform optimized: "
        f"must be <= {hz(f_max, down=True)}, the highest frequency at which Eq. 15 fits this drive at A = "
        f"{fmt(amplitude, 'nm')}: t_s + t_a = "
        f"{(design.settling_time + design.acceleration_time) * 1e6:.4g} µs "
        f"(from {source}), the fly-back and the slow ramp (at least half of the rest) need a period of "
        f"{1e6 / f_max:.4g} µs{remedy}")


def runner_ringing(drive, amplitude: float, frequency: float) -> dict:
    """The runner's ringing after a saw-tooth fly-back of this run's amplitude and frequency and what
    of it is left at the next fly-back (:func:`passmd.protocols.ringing.at_frequency`)."""
    from passmd.protocols import ringing

    probe = ringing.stick_ringing(drive, amplitude, frequency)
    return {k: None if isinstance(v, float) and math.isnan(v) else v  # no swing: no frequency, no decay
            for k, v in ringing.at_frequency(probe, frequency).items()}


def design_row(design, given=()) -> str:
    """The Eq. 15 design in display units: t_s, t_a, Δ_a (V_a), f_s, V_r, u_x,max; ``given``:
    the fields an option set (marked "(given)")."""
    def mark(name):
        return " (given)" if name in given else ""

    return (f"t_s = {design.settling_time * 1e6:.4g} µs{mark('settling_time')}, "
            f"t_a = {design.acceleration_time * 1e6:.4g} µs{mark('acceleration_time')}, "
            f"Δ_a = {fmt(design.acceleration_amplitude, 'nm')}{mark('acceleration_amplitude')} "
            f"(V_a = {design.acceleration_velocity * 1e3:.4g} mm/s); from the "
            f"{hz(design.response_frequency)} saw-tooth response: "
            f"f_s = {fmt(design.micro_vibration_frequency, 'kHz')}, "
            f"V_r = {design.runner_velocity * 1e3:.4g} mm/s, u_x,max = {fmt(design.presliding, 'nm')}")


def _region_band(args, result, options) -> dict | None:
    """The runs of the drives at the fit's region a fitted --drive file records (none: None): the band
    of the runner's position over time, and of the final position, steps and steady velocity."""
    import numpy as np

    from passmd.cli.drive import region_drives

    drives = region_drives(args, load_cell=bool(args.load_cell))
    if not drives:
        return None
    runs = [result] + [simulate(args, d, options)[0] for d in drives]
    positions = np.array([r.runner_position for r in runs])
    steps = np.array([r.step_sizes for r in runs]) if runs[0].step_sizes.size else np.zeros((len(runs), 0))
    record = {"points": len(drives),
              "final_position_m": [float(min(r.final_position for r in runs)),
                                   float(max(r.final_position for r in runs))],
              "step_sizes_low_m": steps.min(axis=0).tolist(), "step_sizes_high_m": steps.max(axis=0).tolist()}
    if args.steady:
        from passmd.protocols.velocity import steady_velocity

        velocities = [steady_velocity(r)["velocity_m_per_s"] for r in runs]
        record["steady_velocity_m_per_s"] = [float(min(velocities)), float(max(velocities))]
    return {"record": record, "low": positions.min(axis=0), "high": positions.max(axis=0)}


def _band_text(band: dict) -> str:
    """The band of a fitted drive's run in one line."""
    text = (f"over the estimate and {band['points']} points of the region: final position "
            f"{fmt(band['final_position_m'][0], 'nm')} … {fmt(band['final_position_m'][1], 'nm')}")
    if band["step_sizes_low_m"]:
        text += (f", last step {fmt(band['step_sizes_low_m'][-1], 'nm')} … "
                 f"{fmt(band['step_sizes_high_m'][-1], 'nm')}")
    if "steady_velocity_m_per_s" in band:
        low, high = band["steady_velocity_m_per_s"]
        text += f", steady velocity {low * 1e3:.4g} … {high * 1e3:.4g} mm/s"
    return text


def write_outputs(args, result, figure=None, band=None) -> None:
    """The time series to --csv and the positions' plot to --plot, written together or not at all,
    never over a file unless --overwrite (:func:`passmd.cli.streams.create_outputs`; a device or pipe
    such as /dev/stdout is written to). ``figure(result, title)``: the plot (default
    :func:`passmd.plots.trace.positions_figure`); ``band``: the runner position's ``low`` and ``high``
    over a fit's region (:func:`_region_band`), two more CSV columns and a shaded band."""
    writers = {}
    if args.csv:
        frame = result.to_frame()
        if band is not None:
            frame["runner_position_band_low_m"] = band["low"]
            frame["runner_position_band_high_m"] = band["high"]
        writers[args.csv] = lambda tmp: frame.to_csv(tmp, index=False)
    if args.plot:
        from passmd.plots.trace import positions_figure

        wave = result.waveform
        title = (f"{wave.kind}, A = {fmt(wave.amplitude, 'nm')}, f = {hz(wave.frequency)}, "
                 f"{wave.periods} periods\n{describe(result.drive)}")
        fig = (figure or positions_figure)(result, title)
        if band is not None:
            ax = fig.axes[0]
            ax.fill_between(result.time * 1e3, band["low"] * 1e9, band["high"] * 1e9, color="C1", alpha=0.25,
                            lw=0, label="runner x_r over the fit's 95 % region")
            ax.legend(fontsize=8)
        fmt_ = Path(args.plot).suffix.lstrip(".").lower()
        writers[args.plot] = lambda tmp: fig.savefig(tmp, dpi=150, format=fmt_)
    if writers:
        create_outputs(writers, _named(args), overwrite=args.overwrite)


def run_run(args, out) -> int:
    drive = build_drive(args, **({"load_cell": True} if args.load_cell else {}))  # else the file's
    options = check_run_options(args, drive)
    check_memory(args)
    check_output_paths(args)
    result, design = simulate(args, drive, options)
    ring = runner_ringing(drive, options.amplitude, options.frequency)  # a simulation too
    startup.resume()
    summary = result.summary()
    summary["wall_time_s"] = float(result.wall_time)
    if design is not None:  # Eq. 15's parameters, derived from this drive's saw-tooth response
        from passmd.model.optimized_waveform import highest_fitting_frequency

        summary["design"] = design.as_dict()
        summary["eq15_highest_frequency_Hz"] = highest_fitting_frequency(
            design, float(summary["amplitude_m"]), drive)
        summary["design_given_by_options"] = [q.field for q in EQ15_OVERRIDES
                                              if getattr(args, q.dest) is not None]
    if args.steady:  # the book's steady-velocity protocol, on this same run
        from passmd.protocols.velocity import steady_velocity

        steady = steady_velocity(result)
        summary["steady"] = {**steady, "step_m": steady["velocity_m_per_s"] / float(summary["frequency_Hz"])}
    summary["ringing"] = ring
    check_results(summary)
    check_run_bounds(summary, drive, float(summary["amplitude_m"]))
    band = _region_band(args, result, options)
    if band is not None:
        summary["band"] = band.pop("record")
    write_outputs(args, result, band=band)
    if args.json:
        emit_json({"command": "run", "waveform": args.waveform, "flyback": drive.amplifier.flyback,
                   "protocol": "steady" if args.steady else "from rest",
                   "drive": drive_record(drive), **summary}, out)
        return 0
    rows = [
        ("waveform", f"{args.waveform}, A = {fmt(summary['amplitude_m'], 'nm')}, "
                     f"f = {fmt(summary['frequency_Hz'], 'kHz')}, {summary['periods']} periods"),
        ("final position", fmt(summary["final_position_m"], "nm")),
        ("step per period", nm(summary["step_sizes_m"]) if summary["step_sizes_m"] else "– (one period)"),
        ("back-step per period", nm(summary["back_steps_m"])),
    ]
    if design is not None:
        rows.insert(1, ("Eq. 15 design", design_row(design, summary["design_given_by_options"])))
        highest = hz(summary["eq15_highest_frequency_Hz"], down=True)
        rows.insert(2, ("Eq. 15 fits", f"up to {highest} for this drive at "
                                       f"A = {fmt(summary['amplitude_m'], 'nm')}"))
    if "steady" in summary:
        steady = summary["steady"]
        rows.append(("steady velocity", f"{steady['velocity_m_per_s'] * 1e3:.6g} mm/s (second half's period "
                                        f"means; step {fmt(steady['step_m'], 'nm')}, drift "
                                        f"{steady['velocity_drift']:.2g})"))
    if "mean_velocity_m_per_s" in summary:
        rows.append(("mean velocity from rest", f"{summary['mean_velocity_m_per_s'] * 1e3:.6g} mm/s"))
    if "generated_force_N" in summary:
        rows.append(("generated force", fmt(summary["generated_force_N"], "N")))
    if "band" in summary:
        rows.append(("fit's 95 % region", _band_text(summary["band"])))
    rows.append(("runner ringing", ringing_text(ring, "the step")))
    over = [b for b in summary["back_steps_m"] if b > float(summary["amplitude_m"])]
    if over and ring["ringing_affects_steps"]:
        rows.append(("back-step > A", f"{len(over)} back-step{'s' * (len(over) > 1)} exceed the amplitude "
                                      f"(up to {fmt(max(over), 'nm')}): the runner's swing at the fly-back "
                                      "adds to it"))
    rows.append(("integrator", f"{summary['integrator_steps']} steps, {summary['wall_time_s']:.3g} s"))
    emit_rows(f"passmd run — {describe(drive)}", [*rows, *drive_rows(drive)], out)
    return 0
