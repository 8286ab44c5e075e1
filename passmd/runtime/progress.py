"""Progress of long work on standard error: a bar on a terminal, a line every few seconds elsewhere.

:func:`bar` is a :class:`tqdm.std.tqdm` that shows nothing for work ending within
:data:`DELAY` seconds. On a terminal it redraws in place; anywhere else (a log file, a pipe,
a CI console) it writes one whole line at most every :data:`LINE_INTERVAL` seconds: the
fraction done, the elapsed time and, once a whole unit is done, the estimated time left.
A closed standard error (``2>&-``) gets a disabled bar. Worker processes of a parallel sweep
show nothing (:func:`in_worker`): their parent shows the sweep's progress. tqdm is imported
only when a bar is made, so short runs never load it.
"""

from __future__ import annotations

import sys

__all__ = ["DELAY", "LINE_INTERVAL", "bar", "in_worker", "is_terminal"]

#: Seconds of work before anything is shown: shorter work prints nothing.
DELAY = 2.0
#: Least seconds between two progress lines when standard error is not a terminal.
LINE_INTERVAL = 5.0


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
    if stream is None or is_terminal(stream):
        return tqdm(**common, file=stream, dynamic_ncols=True,
                    bar_format="{l_bar}{bar}| " + count + " {unit}s [{elapsed}<{remaining}]")

    class Lines(tqdm):
        """Time left from the average rate once a whole unit is done: within one simulated period
        the steps crowd where the waveform turns, so its first fraction says little."""

        @property
        def format_dict(self):
            values = super().format_dict
            n, total, done = values["n"], values["total"], values["n"] - values["initial"]
            if done >= 1 and total:
                values["left"] = f"about {self.format_interval(values['elapsed'] * (total - n) / done)} left"
            else:
                values["left"] = f"time left known after the first {unit}"
            return values

    # miniters=0: every update may print, at most one line per LINE_INTERVAL
    return Lines(**common, file=_Lines(stream), mininterval=LINE_INTERVAL, miniters=0,
                 bar_format="{desc}: {percentage:.1f}% (" + count + " {unit}s) after {elapsed}, {left}")
