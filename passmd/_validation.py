"""Input checks shared by every public entry point.

Each check raises :class:`ValueError` whose message names the parameter, the
offending value and the allowed range, e.g.::

    runner_mass = -0.003 is out of range: must be a finite number > 0 (kg)
"""

from __future__ import annotations

import math
from decimal import Decimal, localcontext
from numbers import Real

import numpy as np


def format_number(value, scale: float = 1.0) -> str:
    """``value / scale`` as text that reads back as exactly that float: ``:g`` where six digits
    are exact (``0.5``, ``1e-09``), else the shortest round-trip digits (``0.4999999999999``).

    The division is decimal (``repr`` of both), so ``format_number(2.5e-4, 1e-3)`` is ``0.25``,
    not 0.25000000000000006: a range message never shows a value equal to a bound it violates.
    """
    x = float(value)
    if scale != 1.0 and math.isfinite(x):
        with localcontext() as ctx:
            ctx.prec = 60
            x = float(Decimal(repr(x)) / Decimal(repr(float(scale))))
    short = f"{x:g}"
    return short if not math.isfinite(x) or float(short) == x else repr(x)


def _shown(value) -> str:
    """``repr`` of a value, numpy scalars shown as the Python number they hold."""
    if isinstance(value, np.floating):
        return repr(float(value))
    if isinstance(value, np.integer):
        return repr(int(value))
    return repr(value)


def _describe(lower, upper, lower_open, upper_open) -> str:
    parts = []
    if lower is not None:
        parts.append(f"{'>' if lower_open else '>='} {format_number(lower)}")
    if upper is not None:
        parts.append(f"{'<' if upper_open else '<='} {format_number(upper)}")
    return " and ".join(parts)


def check_range(
    name: str,
    value,
    lower: float | None = None,
    upper: float | None = None,
    *,
    lower_open: bool = False,
    upper_open: bool = False,
    unit: str = "",
) -> float:
    """Return ``float(value)`` if it is a finite real number inside the range.

    Parameters
    ----------
    name : str
        Parameter name used in the error message (the package's own name, e.g.
        ``"runner_mass"``).
    value : real
        The value to check.
    lower, upper : float or None
        Bounds; ``None`` leaves that side open.
    lower_open, upper_open : bool
        Whether the bound itself is excluded.
    unit : str
        Unit shown in the error message.
    """
    rng = _describe(lower, upper, lower_open, upper_open)
    rng = f" {rng}" if rng else ""
    suffix = f" ({unit})" if unit else ""
    if isinstance(value, bool) or not isinstance(value, (Real, np.floating, np.integer)):
        raise ValueError(
            f"{name} = {_shown(value)} is not a number: must be a finite number{rng}{suffix}"
        )
    v = float(value)
    bad = not math.isfinite(v)
    if not bad and lower is not None:
        bad = v <= lower if lower_open else v < lower
    if not bad and upper is not None:
        bad = v >= upper if upper_open else v > upper
    if bad:
        raise ValueError(f"{name} = {_shown(value)} is out of range: must be a finite number{rng}{suffix}")
    return v


def check_positive(name: str, value, unit: str = "") -> float:
    """Return ``float(value)`` if it is finite and strictly positive."""
    return check_range(name, value, 0.0, lower_open=True, unit=unit)


def check_count(name: str, value, minimum: int = 1) -> int:
    """Return ``int(value)`` if it is an integer >= ``minimum`` (booleans are not counts)."""
    integral = isinstance(value, (int, np.integer)) or (
        isinstance(value, (float, np.floating)) and math.isfinite(value) and float(value).is_integer())
    if isinstance(value, (bool, np.bool_)) or not integral or value < minimum:
        raise ValueError(f"{name} = {value!r} is out of range: must be an integer >= {minimum}")
    return int(value)


def check_choice(name: str, value, choices) -> str:
    """Return ``value`` if it is one of ``choices``."""
    if value not in choices:
        allowed = ", ".join(repr(c) for c in choices)
        raise ValueError(f"{name} = {value!r} is not allowed: must be one of {allowed}")
    return value


def check_array(name: str, values, lower=None, upper=None, *, lower_open=False, unit="") -> np.ndarray:
    """Return ``values`` as a float array after checking every element is finite and in range."""
    try:
        arr = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        arr = None
    if arr is None or np.asarray(values).dtype.kind in "bSU":  # no strings, no booleans
        raise ValueError(f"{name} = {values!r:.80} is not a number: must be a finite number or an array of "
                         "finite numbers")
    if arr.size == 0:
        return arr
    rng = _describe(lower, upper, lower_open, False)
    rng = f" {rng}" if rng else ""
    suffix = f" ({unit})" if unit else ""
    bad = ~np.isfinite(arr)
    if lower is not None:
        bad |= (arr <= lower) if lower_open else (arr < lower)
    if upper is not None:
        bad |= arr > upper
    if bad.any():
        first = float(arr.flat[int(np.flatnonzero(bad.ravel())[0])])
        raise ValueError(
            f"{name} contains {format_number(first)}, which is out of range: every element must be a "
            f"finite number{rng}{suffix}"
        )
    return arr
