"""``passmd ledger``: the replication ledger: every claim's computed category and evidence."""

from __future__ import annotations

import datetime
import textwrap
from pathlib import Path

from passmd.cli.configuration import run_config
from passmd.cli.options import FilePath, add_overwrite_option, add_sweep_options
from passmd.cli.output import JSON_HELP, check_output_file, emit_json
from passmd.cli.result_bounds import check_table
from passmd.cli.streams import check_new_outputs, check_outputs, create_outputs
from passmd.runtime.cache import DEFAULT_CACHE_DIR, describe_default_cache_dir
from passmd.runtime.config import ENVIRONMENT, PROFILES

__all__ = ["add_parser", "run_ledger"]

_EPILOG = textwrap.dedent(f"""\
    Computes (or reads from the cache: ${ENVIRONMENT['cache_dir']}, else
    {describe_default_cache_dir()}; the book built with nox uses ./{DEFAULT_CACHE_DIR}/
    of the repository) every figure's results at --profile and evaluates every claim of
    passmd/data/reference/claims.csv on the product of the readings of passmd.ledger.readings it
    depends on; each claim is judged at its held-out reading (the joint reading chosen, by the
    same rule, from all the other claims) and the counts come from those states; the in-sample
    joint reading (chosen with every claim) is shown beside them. Studies (rows that are not
    sentences of the paper) and rows implied by another (counted with it) are shown, not counted.

    --json keys: profile, summary, counts{{category: n (held out), fragile, not informative, about
    the experiment, counted with their family, studies}}, joint_reading{{reading{{axis[@section]:
    value}}, described, holding, equivalent_points, claims, points, covered_points, decided_points,
    chosen_from, tied_readings, best_single_point, held_out_counts{{category: n}},
    in_sample_gain[], ties[], runner_ups[{{reading, described, holding, equivalent_points, margin}}],
    variants[{{left_out, claims_left_out[], claims_added[], reading, described, holding, claims}}]}},
    conflicting_pairs[{{claims, first_holds_at, second_holds_at, example}}],
    tensions[{{separated_by[], sides[{{holds_only_at, claims[], linked[]}}], pairs}}],
    claims[{{claim, figure, category, basis, study_of, family, counted, verdict, why, evidence[],
    reason, depends_on[], readings{{reading: state}}, points[{{reading, state, score, detail,
    outside}}], held_out_reading{{axis: value}}, held_out_described, held_out_state, default_state,
    joint_state, margin, margin_text, holds_at, fails_at, undecided_at, decided_at, fragile,
    fragile_reason, outside, informative, not_informative, fraction_holds, best_reading, tolerance,
    check, paper_<SI unit>, ours_<SI unit>, ours_text, abs_deviation_<SI unit>, rel_deviation
    (fraction)}}]""")


def add_parser(command) -> None:
    p = command("ledger", "the replication ledger: every claim's computed category and evidence", _EPILOG)
    p.add_argument("--profile", choices=PROFILES, default="quick",
                   help="resolution: quick (CI) or paper (the paper's grids) (default: quick)")
    p.add_argument("--write-baseline", metavar="CSV", default=None, action=FilePath,
                   help="also write the categories as a baseline CSV (default: none)")
    p.add_argument("--write-drive", metavar="TOML", default=None, action=FilePath,
                   help="also write the joint reading as a drive file: its drive axes as keys, its "
                        "protocol axes as the commands' options in its header (default: none)")
    p.add_argument("--write-evaluation", metavar="PMC", default=None, action=FilePath,
                   help="also write the evaluated ledger as a checksummed data file keyed on the profile "
                        "and the package's code and data, which the book's chapters read instead of "
                        "evaluating every claim again (nox -s book) (default: none)")
    add_overwrite_option(p)
    add_sweep_options(p)
    p.add_argument("--json", action="store_true", help=JSON_HELP)
    p.set_defaults(handler=run_ledger)


def _given(args) -> list[tuple[str, str]]:
    """(option, path) of --write-baseline, --write-drive and --write-evaluation, where given."""
    return [(option, name) for option, name in (("--write-baseline", args.write_baseline),
                                                ("--write-drive", args.write_drive),
                                                ("--write-evaluation", args.write_evaluation))
            if name is not None]


def _named(args) -> dict[str, str]:
    """path -> the option as typed (``--write-drive joint.toml``)."""
    return {name: f"{option} {name}" for option, name in _given(args)}


def _check_outputs(args, config) -> None:
    """The output files, before the ledger is computed: files in existing
    directories, not there already (unless --overwrite), not the claims table the ledger reads, the
    sweep log or the file standard output goes to, nor each other."""
    from passmd.ledger.claims import CLAIMS_PATH

    if not _given(args):
        return
    for option, name in _given(args):
        check_output_file(option, name)
    named = _named(args)
    check_outputs({**{typed: name for name, typed in named.items()},
                   f"{ENVIRONMENT['sweep_log']} {config.sweep_log}": config.sweep_log},
                  inputs={f"the claims table {CLAIMS_PATH}": CLAIMS_PATH})
    check_new_outputs(named, overwrite=args.overwrite)


def _write(evaluated, joint, args) -> None:
    """--write-baseline (the categories), --write-drive (the joint reading) and --write-evaluation (the
    evaluated ledger, :mod:`passmd.report.stored_evaluation`), written together or not at all, never
    over a file unless --overwrite (:func:`passmd.cli.streams.create_outputs`)."""
    from passmd.ledger.baseline import baseline_csv
    from passmd.ledger.joint_drive import joint_drive_file
    from passmd.report import stored_evaluation

    texts = {}
    if args.write_baseline:
        command = f"passmd ledger --profile {args.profile}{' --overwrite' * args.overwrite}"
        header = (f"ledger categories, {args.profile} profile; produced {datetime.date.today().isoformat()} "
                  f"by\n{command} --write-baseline {args.write_baseline}")
        texts[args.write_baseline] = baseline_csv(evaluated, header)
    if args.write_drive:
        texts[args.write_drive] = joint_drive_file(joint["reading"], args.profile)
    writers = {name: lambda tmp, text=text: Path(tmp).write_text(text, encoding="utf-8", newline="")
               for name, text in texts.items()}
    if args.write_evaluation:
        data = stored_evaluation.encode(evaluated, args.profile)
        writers[args.write_evaluation] = lambda tmp: Path(tmp).write_bytes(data)
    create_outputs(writers, _named(args), overwrite=args.overwrite)


def run_ledger(args, out) -> int:
    """Every claim of the paper with its computed category, values and evidence (Sections 4–6)."""
    config = run_config(args)
    _check_outputs(args, config)  # (before the ledger's modules load)
    from passmd.report import evaluation, ledger_views

    results = evaluation.collect_results(config)
    for name, table in results.items():  # finite before anything is written, as run and theory check
        check_table(name, table)
    evaluated = evaluation.evaluate(results=results)
    counts = evaluation.headline(evaluated)
    joint = evaluated.attrs["joint"]
    if _given(args):
        _write(evaluated, joint, args)
    if args.json:
        emit_json({"command": "ledger", "profile": args.profile, "summary": ledger_views.summary(evaluated),
                   "counts": counts, "joint_reading": evaluation.joint_record(joint),
                   "conflicting_pairs": evaluated.attrs["conflicts"], "tensions": evaluated.attrs["tensions"],
                   "claims": evaluation.records(evaluated)}, out)
        return 0
    out.write(f"passmd ledger — profile {args.profile}: {ledger_views.summary(evaluated)}\n")
    for line in ledger_views.held_out_sentences(evaluated) + ledger_views.joint_sentences(joint):
        out.write(line + "\n")
    out.write("counts: " + ", ".join(f"{n} {s}" for s, n in counts.items()) + "\n")
    out.write(f"{len(evaluated.attrs['conflicts'])} pairs of claims never hold together, in "
              f"{len(evaluated.attrs['tensions'])} tensions:\n")
    for line in ledger_views.tension_sentences(evaluated):
        out.write(f"  {line}\n")
    for row in evaluated.itertuples():
        basis = " (closed form)" if row.basis == "closed form" else ""
        study = f" (study of {row.study_of}, not counted)" if row.study_of else ""
        fragile = f"\n  fragile: {row.fragile_reason}" if row.fragile else ""
        out.write(f"\n{row.claim}: {row.status}{basis}{study}\n  {row.verdict}{fragile}\n")
        for item in (e for e in row.evidence.split(" | ") if e):
            out.write(f"  - {item}\n")
    return 0
