"""Scripts outside the command line (``benchmarks/*.py``, ``tools/*.py``) under its failure contract.

:func:`run_script` runs a script's ``main`` so that any failure ends in one line on stderr naming
the script and what failed, with exit status 1 (130 on Ctrl-C), never a traceback
(``PASSMD_DEBUG=1`` shows it); :func:`child_json` reads the JSON a child process printed, and turns
a child that failed or printed nothing into such a failure, with the child's own last line.
"""

from __future__ import annotations

import json
import os
import sys
from collections.abc import Callable

__all__ = ["ScriptError", "child_json", "run_script"]


class ScriptError(RuntimeError):
    """A script's step failed; the message is the one line to print."""


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def child_json(done, what: str, *, stream: str = "stdout", line: int | None = None):
    """The JSON ``done`` (a ``subprocess.CompletedProcess`` run with ``text=True``) printed on ``stream``
    (``line``: only that line of it); :class:`ScriptError` naming ``what`` if the child failed or its
    output is not JSON."""
    text = getattr(done, stream) or ""
    errors = (done.stderr or "").strip().splitlines()
    if done.returncode != 0:
        last = _one_line(errors[-1]) if errors else "no message"
        raise ScriptError(f"{what} failed (exit status {done.returncode}): {last}")
    lines = text.splitlines()
    chosen = text if line is None else (lines[line] if -len(lines) <= line < len(lines) else "")
    try:
        return json.loads(chosen)
    except ValueError:
        shown = _one_line(chosen)[:200] or "nothing"
        raise ScriptError(f"{what} printed {shown!r} on its {stream}, not the JSON record expected") from None


def run_script(main: Callable[[], int | None], name: str | None = None) -> int:
    """``main()``'s exit status; a failure is one line ``NAME: error: ...`` and status 1 (Ctrl-C: 130)."""
    name = name or os.path.basename(sys.argv[0])
    try:
        return int(main() or 0)
    except KeyboardInterrupt:
        sys.stderr.write(f"{name}: interrupted\n")
        return 130
    except SystemExit:
        raise
    except Exception as exc:  # noqa: BLE001 - the one line is the point
        if os.environ.get("PASSMD_DEBUG"):
            raise
        where = f" ({exc.filename})" if isinstance(exc, OSError) and exc.filename else ""
        text = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        kind = "" if isinstance(exc, (ScriptError, OSError)) else f"{type(exc).__name__}: "
        sys.stderr.write(f"{name}: error: {kind}{_one_line(text)}{where}\n")
        return 1
