"""A one-line notice on stderr when the simulation kernels start compiling.

The first simulation after installing (or after the kernels' source changed) compiles the
numba kernels once, which takes ≈ 15–20 s on a laptop core; without a word the command looks
hung. numba alone knows when it compiles (a miss in its on-disk cache, whatever the cache is
keyed by): :func:`notice_on_compile` listens for the ``"numba:compile"`` event numba broadcasts
then, and writes the notice at the first one of the command.
"""

from __future__ import annotations

import sys

__all__ = ["NOTICE", "disarm", "notice_on_compile"]

NOTICE = "compiling the simulation kernels (≈ 20 s, once) …"

_listener = None


def notice_on_compile(stream=None) -> None:
    """Write :data:`NOTICE` once to ``stream`` (stderr; never stdout) if numba compiles from
    now on; called after a command's options are checked, so a refusal stays one line."""
    global _listener
    if _listener is None:
        from numba.core import event

        class Notice(event.Listener):
            def on_start(self, ev) -> None:
                if self.stream is not None:
                    stream, self.stream = self.stream, None
                    try:
                        stream.write(f"passmd: {NOTICE}\n")
                        stream.flush()
                    except (OSError, ValueError):  # a closed or failing stderr: the compile goes on
                        pass

            def on_end(self, ev) -> None:
                pass

        _listener = Notice()
        event.register("numba:compile", _listener)
    _listener.stream = stream or sys.stderr


def disarm() -> None:
    """Forget the stream of the command that armed the notice, when that command returns: a
    later compile in the same process (a caller running commands in-process) must not write to
    a stream that belonged to a finished command, and may have been closed since."""
    if _listener is not None:
        _listener.stream = None
