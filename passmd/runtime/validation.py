"""Input checks shared by every public entry point.

Each check raises :class:`InputError` (a :class:`ValueError`) whose message names the
parameter, the offending value (a plain number) and the allowed range, e.g.::

    runner_mass = -0.003 is out of range: must be a finite number > 0 (kg)

and whose attributes carry the same parts, so that an entry point can say it again in
the user's terms (the command line names the option the value came from).
"""

from __future__ import annotations

import math
from decimal import ROUND_CEILING, ROUND_FLOOR, Decimal, localcontext
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


class InputError(ValueError):
    """A refused input: the message for the library's caller, the parts for an entry point.

    Attributes
    ----------
    name : str
        The checked quantity as the raising code names it: a parameter, or a record field,
        dotted for a part of a drive (``"runner_mass"``, ``"actuator.damping_ratio"``).
    value : object
        The refused value (SI).
    unit : str
        SI unit of ``value`` and ``limits`` (``""`` or ``"–"``: dimensionless).
    limits : tuple of (str, float)
        What is allowed, e.g. ``((">", -1.0), ("<", 0.5))``; empty when no range applies.
    why : str
        Why the limit (``"plausible range: …"``, ``"hard limit: …"``); ``""`` if the range says it.
    soft : bool
        Whether ``allow_extrapolation`` lifts the limit.
    quantity : str
        For a quantity computed from an input: what it is (``"the damping ratio ζ = …"``);
        ``""`` when ``name`` is itself an input.
    source, source_value, source_limits
        The input ``quantity`` was computed from (named like ``name``), its value, and the
        limits on it that keep ``quantity`` allowed (SI).
    sources : tuple of str
        Several inputs a quantity comes from together (no single limit); ``detail`` says
        what is wrong with them.
    detail : str
        The message without the inputs' names.
    """

    def __init__(self, message: str = "", *, name: str = "", value=None, unit: str = "", limits=(),
                 why: str = "", soft: bool = False, quantity: str = "", source: str | None = None,
                 source_value=None, source_limits=(), sources=(), detail: str = ""):
        super().__init__(message)
        self.name, self.value, self.unit, self.limits = name, value, unit, tuple(limits)
        self.why, self.soft, self.quantity, self.detail = why, soft, quantity, detail
        self.source, self.source_value, self.source_limits = source, source_value, tuple(source_limits)
        self.sources = tuple(sources)

    def derived_from(self, source: str, source_value, per: float, quantity: str) -> InputError:
        """This error, for a quantity proportional to an input: ``quantity = source / per``.

        ``per`` (> 0) is the input per unit of the quantity, so the limits carry over as
        ``bound · per``.
        """
        self.quantity, self.source, self.source_value = quantity, source, source_value
        self.source_limits = tuple((op, bound * per) for op, bound in self.limits)
        return self


def shown(value) -> str:
    """``value`` as a message shows it: numbers plain (``1e+300``, never ``np.float64(…)``)."""
    if isinstance(value, (bool, np.bool_)):
        return repr(bool(value))
    if isinstance(value, (int, np.integer)):
        return repr(int(value))
    if isinstance(value, (Real, np.floating)):
        return repr(float(value))
    return repr(value)


def limits_of(lower, upper, lower_open, upper_open) -> tuple[tuple[str, float], ...]:
    """``(("op", bound), …)`` of a range; ``None`` leaves a side open."""
    parts = []
    if lower is not None:
        parts.append((">" if lower_open else ">=", float(lower)))
    if upper is not None:
        parts.append(("<" if upper_open else "<=", float(upper)))
    return tuple(parts)


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
    number = not isinstance(value, bool) and isinstance(value, (Real, np.floating, np.integer))
    if number:
        v = float(value)
        bad = not math.isfinite(v)
        if not bad and lower is not None:
            bad = v <= lower if lower_open else v < lower
        if not bad and upper is not None:
            bad = v >= upper if upper_open else v > upper
        if not bad:
            return v
    # the message is built only for a value refused (checks run on every simulation's inputs)
    rng = _describe(lower, upper, lower_open, upper_open)
    rng = f" {rng}" if rng else ""
    suffix = f" ({unit})" if unit else ""
    limits = limits_of(lower, upper, lower_open, upper_open)
    if not number:
        raise InputError(f"{name} = {shown(value)} is not a number: must be a finite number{rng}{suffix}",
                         name=name, value=value, unit=unit, limits=limits)
    raise InputError(f"{name} = {shown(value)} is out of range: must be a finite number{rng}{suffix}",
                     name=name, value=v, unit=unit, limits=limits)


def check_positive(name: str, value, unit: str = "") -> float:
    """Return ``float(value)`` if it is finite and strictly positive."""
    return check_range(name, value, 0.0, lower_open=True, unit=unit)


def check_count(name: str, value, minimum: int = 1) -> int:
    """Return ``int(value)`` if it is an integer >= ``minimum`` (booleans are not counts)."""
    integral = isinstance(value, (int, np.integer)) or (
        isinstance(value, (float, np.floating)) and math.isfinite(value) and float(value).is_integer())
    if isinstance(value, (bool, np.bool_)) or not integral or value < minimum:
        raise InputError(f"{name} = {shown(value)} is out of range: must be an integer >= {minimum}",
                         name=name, value=value, limits=((">=", minimum),))
    return int(value)


def check_choice(name: str, value, choices) -> str:
    """Return ``value`` if it is one of ``choices``."""
    if value not in choices:
        allowed = ", ".join(repr(c) for c in choices)
        raise InputError(f"{name} = {shown(value)} is not allowed: must be one of {allowed}", name=name,
                         value=value)
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
        raise InputError(
            f"{name} contains {format_number(first)}, which is out of range: every element must be a "
            f"finite number{rng}{suffix}", name=name, value=first, unit=unit,
            limits=limits_of(lower, upper, lower_open, False))
    return arr


#: How to move an input to satisfy a limit, by the limit's operator (``{}``: the input's name).
LIMIT_VERBS = {">": "raise {} above", ">=": "raise {} to at least", "<": "lower {} below",
               "<=": "lower {} to at most"}


def safe_bound(op: str, bound: float, digits: int = 4) -> str:
    """``bound`` to ``digits`` significant digits, rounded so that the stated limit stays true.

    A lower limit (``>``, ``>=``) is rounded up, an upper one down: any value the rounded
    limit allows, the exact one allows too.
    """
    if bound == 0.0 or not math.isfinite(bound):
        return f"{bound:g}"
    exact = Decimal(bound)
    step = Decimal(1).scaleb(exact.adjusted() - digits + 1)
    rounded = exact.quantize(step, rounding=ROUND_CEILING if op.startswith(">") else ROUND_FLOOR)
    return f"{float(rounded):.{digits}g}"


def file_message(exc: InputError) -> str:
    """``exc`` in a drive file's terms: a quantity derived from a key (the damping ratio from
    ``actuator.viscosity``, :meth:`InputError.derived_from`) names the key, its value as read and
    the key's limit in SI."""
    if not (exc.quantity and exc.source and exc.limits):
        return str(exc)
    unit = f" {exc.unit}" if exc.unit and exc.unit != "–" else ""
    limits = " and ".join(f"{op} {safe_bound(op, bound)}{unit}" for op, bound in exc.limits)
    text = (f"{exc.quantity} derived from {exc.source} = {shown(exc.source_value)} is "
            f"{float(exc.value):.4g}, out of range: must be {limits}" + (f" ({exc.why})" if exc.why else ""))
    remedies = [f"{LIMIT_VERBS[op].format(exc.source)} {safe_bound(op, bound)} (SI)"
                for op, bound in exc.source_limits[:1]]
    remedies += ["allow_extrapolation = true goes beyond it"] if exc.soft else []
    return text + (f"; {', or '.join(remedies)}" if remedies else "")
