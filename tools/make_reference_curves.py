"""Write the paper's closed-form reference curves (Figs. 5b, 6a–c) into passmd/data/reference/.

Usage: ``python tools/make_reference_curves.py --overwrite [--out DIR]`` (``--overwrite`` replaces the
tables already there; without it a table there is refused and none is written). The tables are computed by
:func:`passmd.ledger.reference.closed_form_curves` (Eqs. 1, 7–14 of Nguyen et al. 2018 via
``passmd.model.theory``) on ``passmd.model.tables.PRELOAD_GRIDS``; ``tests/test_reference.py``
fails if the committed files and a fresh computation disagree. The default target is the
repository's reference data folder (package data of ``passmd``), found from this file's
location, never the installed package.
"""

import argparse
import sys
from pathlib import Path

from passmd.ledger.reference import write_reference_curves
from passmd.runtime.scripts import ScriptError, run_script

REPOSITORY_REFERENCE_DIR = Path(__file__).resolve().parents[1] / "passmd" / "data" / "reference"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=REPOSITORY_REFERENCE_DIR,
                        help=f"target folder (default: {REPOSITORY_REFERENCE_DIR})")
    parser.add_argument("--overwrite", action="store_true",
                        help="replace the tables already there (default: off: a table there is refused)")
    args = parser.parse_args()
    try:
        written = write_reference_curves(args.out, overwrite=args.overwrite)
    except FileExistsError as exc:
        raise ScriptError(f"{exc.filename} is already there: pass --overwrite to replace the tables "
                          "(none was written)") from None
    for path in written:
        print("wrote", path)


if __name__ == "__main__":
    sys.exit(run_script(main))
