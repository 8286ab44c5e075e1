"""Check an installed passmd wheel from outside the repository (``nox -s wheel`` runs this).

Run with the fresh environment's Python, in a folder outside the repository. Fails (exit
status 1) when the package is imported from the repository instead of the installation,
when its version disagrees with the installed metadata, when package data (reference
data, benchmark results) is missing, or when the commands a user runs first fail. What it
runs, each must exit with 0:

* ``passmd --version`` (prints the metadata's version);
* ``passmd theory --json`` (closed forms);
* the claims loader: ``passmd.ledger.claims.load_claims()`` and every reference curve of
  ``passmd.ledger.reference.CURVES``, plus the benchmark results the book reads;
* ``passmd ledger --profile quick --json`` (every claim's computed category; with
  ``--ledger-cache DIR`` it reads the simulation cache the test session filled, whose keys
  hold for the installed package too: they hash the same source files);
* ``passmd figure fig9a --profile quick`` (a paper figure's CSV and PNG, with provenance).

Usage: ``python tools/check_installed_wheel.py --repo /path/to/repository``.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from importlib import metadata
from pathlib import Path


def _run(*args: str) -> str:
    print("$", " ".join(args), flush=True)
    result = subprocess.run(args, capture_output=True, text=True, check=False)
    sys.stdout.write(result.stdout[-2000:])
    if result.returncode != 0:
        sys.stdout.write(result.stderr[-4000:])
        raise SystemExit(f"FAILED (exit status {result.returncode}): {' '.join(args)}")
    return result.stdout


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repo", type=Path, required=True, help="the repository (must not be imported from)")
    parser.add_argument("--ledger-cache", type=Path, default=None,
                        help="simulation cache for the ledger command (default: $PASSMD_CACHE_DIR)")
    args = parser.parse_args(argv)
    repo = args.repo.resolve()

    import passmd
    from passmd.experiments.model_numerics import facts
    from passmd.ledger import reference
    from passmd.ledger.claims import CLAIMS_PATH, load_claims
    from passmd.runtime import provenance

    location = Path(passmd.__file__).resolve()
    if repo in location.parents or Path.cwd().resolve() == repo or repo in Path.cwd().resolve().parents:
        raise SystemExit(f"FAILED: passmd imported from {location} or run inside the repository {repo}")
    print(f"passmd {passmd.__version__} imported from {location.parent}")
    if metadata.version("passmd") != passmd.__version__:
        raise SystemExit(f"FAILED: metadata version {metadata.version('passmd')} != {passmd.__version__}")

    exe = str(Path(sys.executable).parent / "passmd")
    out = _run(exe, "--version")
    if out.strip() != f"passmd {passmd.__version__}":
        raise SystemExit(f"FAILED: passmd --version printed {out.strip()!r}")
    theory = json.loads(_run(exe, "theory", "--json"))
    print("theory keys:", ", ".join(sorted(theory)[:6]), "...")

    claims = load_claims()
    print(f"claims.load_claims(): {len(claims)} claims from {CLAIMS_PATH}")
    for name in reference.CURVES:
        table = reference.load_reference_curve(name)
        print(f"reference.load_reference_curve({name!r}): {len(table)} rows")
    for name in facts.BENCHMARKS:
        record = facts.benchmark_results(name)  # a record, or a list of runs (ledger, book)
        shown = f"{len(record)} runs" if isinstance(record, list) else f"keys {', '.join(record)}"
        print(f"facts.benchmark_results({name!r}): {shown}")
    print(f"facts.speed_budgets(): {len(facts.speed_budgets())} budgets")

    cache = ["--cache-dir", str(args.ledger_cache)] if args.ledger_cache else []
    ledger_out = json.loads(_run(exe, "ledger", "--profile", "quick", "--json", *cache))
    if len(ledger_out["claims"]) != len(claims):
        evaluated = len(ledger_out["claims"])
        raise SystemExit(f"FAILED: passmd ledger evaluated {evaluated} of {len(claims)} claims")
    print(f"passmd ledger --profile quick: {ledger_out['summary']}")

    figure = json.loads(_run(exe, "figure", "fig9a", "--profile", "quick", "--json"))
    header = Path(figure["csv"]).read_text(encoding="utf-8").splitlines()[:3]
    installed = f"none: installed package, version {passmd.__version__}"  # no checkout: the release
    assert provenance.commit_or_version() == installed, provenance.commit_or_version()
    expected = [f"# passmd_version: {passmd.__version__}", f"# git_commit: {installed}", "# profile: quick"]
    if header != expected:
        raise SystemExit(f"FAILED: provenance header of {figure['csv']} is {header}, expected {expected}")
    if not Path(figure["png"]).is_file():
        raise SystemExit(f"FAILED: {figure['png']} was not written")
    print(f"passmd figure fig9a: {figure['rows']} rows, {figure['csv']}, {figure['png']}")
    print("installed wheel: ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
