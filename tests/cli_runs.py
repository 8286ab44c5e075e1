"""Running the command line in the test process: the one helper the test modules share."""

from __future__ import annotations

import contextlib
import io

from passmd import cli


def run_main(argv) -> tuple[int, str, str]:
    """(status, stdout, stderr) of ``passmd argv`` in this process (argparse's exits included)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            status = cli.main(list(argv))
        except SystemExit as exc:  # argparse: --help, usage errors
            status = exc.code
    return status, out.getvalue(), err.getvalue()
