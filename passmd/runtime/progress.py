"""Progress of long work on standard error: a bar on a terminal, a line every few seconds elsewhere.

:func:`bar` is a :class:`tqdm.std.tqdm` that shows nothing for work ending within
:data:`DELAY` seconds. On a terminal it redraws in place; anywhere else (a log file, a pipe,
a CI console) it writes one whole line at most every :data:`LINE_INTERVAL` seconds: the
fraction done, the elapsed time and, once :data:`MIN_DONE` units are done, the estimated time
left (the first units of a sweep or a search carry the start-up: the numba kernels' loading, a
pool's workers importing the package, the slowest run of a bisection at the full stroke).
A closed standard error (``2>&-``) gets a disabled bar. Worker processes of a parallel sweep
show nothing (:func:`in_worker`): their parent shows the sweep's progress. tqdm is imported
only when a bar is made, so short runs never load it.
"""

from __future__ import annotations

import sys

__all__ = ["DELAY", "LINE_INTERVAL", "MIN_DONE", "bar", "in_worker", "is_terminal", "time_left"]

#: Seconds of work before anything is shown: shorter work prints nothing.
DELAY = 2.0
#: Least seconds between two progress lines when standard error is not a terminal.
LINE_INTERVAL = 5.0
#: Units (points, runs, periods) done before a time left is estimated, from their average rate.
MIN_DONE = 3


def time_left(elapsed: float, done: float, left: float | None, unit: str, format_interval=None) -> str:
    """``"about 01:05 left"`` from the average rate of ``done`` units, or, before :data:`MIN_DONE`
    of them, what is known: ``"time left known after 3 points"``; ``left`` None: no total."""
    if left is None:
        return "time left unknown"
    if done < MIN_DONE:
        return f"time left known after {MIN_DONE} {unit}s"
    seconds = elapsed * max(left, 0.0) / done
    shown = format_interval(seconds) if format_interval else f"{seconds:.0f} s"
    return f"about {shown} left"


def is_terminal(stream) -> bool:
    """Whether ``stream`` is an open terminal."""
    isatty = getattr(stream, "isatty", None)
    try:
        return bool(isatty and isatty())
    except (OSError, ValueError):  # a closed file
        return False


def in_worker() -> bool:
    """Whether this process is a worker started by :mod:`multiprocessing` (a sweep's pool)."""
    import multiprocessing

    return multiprocessing.parent_process() is not None


class _Lines:
    """The file tqdm writes to off a terminal: each redraw (``\\r`` + status) becomes one line."""

    def __init__(self, stream):
        self.stream = stream

    def write(self, text: str) -> None:
        line = text.replace("\r", "").strip()
        if line:  # (tqdm clears its bar with blanks: nothing to write)
            self.stream.write(line + "\n")

    def flush(self) -> None:
        self.stream.flush()


def bar(total: float, *, unit: str, desc: str, initial: float = 0, fractional: bool = False,
        delay: float | None = None, stream=None):
    """A progress bar over ``total`` times ``unit`` on ``stream`` (default: standard error).

    Shown once ``delay`` seconds (default :data:`DELAY`) have passed. ``fractional``: the count
    advances in fractions of a unit (simulated periods) and is shown with one decimal. The bar
    is removed when closed (``leave=False``): the command's result follows it.
    """
    from tqdm.std import tqdm  # (tqdm.auto warns in notebook kernels without ipywidgets)

    stream = sys.stderr if stream is None else stream
    delay = DELAY if delay is None else delay
    decimals = 2 if total < 10 else 1 if total < 1000 else 0
    count = f"{{n:.{decimals}f}}/{{total:g}}" if fractional else "{n_fmt}/{total_fmt}"
    common = dict(total=total, initial=initial, unit=unit, desc=desc, leave=False, delay=delay,
                  disable=stream is None)

    class Bar(tqdm):
        """Time left from the average rate once :data:`MIN_DONE` units are done (not tqdm's
        smoothed rate of the first ones, which carry the start-up; within one simulated period
        the steps crowd where the waveform turns, so its first fraction says little either)."""

        @property
        def format_dict(self):
            values = super().format_dict
            n, total, done = values["n"], values["total"], values["n"] - values["initial"]
            values["left"] = time_left(values["elapsed"], done, None if total is None else total - n, unit,
                                       self.format_interval)
            return values

    if stream is None or is_terminal(stream):
        return Bar(**common, file=stream, dynamic_ncols=True,
                   bar_format="{l_bar}{bar}| " + count + " {unit}s [{elapsed}, {left}]")
    # miniters=0: every update may print, at most one line per LINE_INTERVAL
    return Bar(**common, file=_Lines(stream), mininterval=LINE_INTERVAL, miniters=0,
               bar_format="{desc}: {percentage:.1f}% (" + count + " {unit}s) after {elapsed}, {left}")
