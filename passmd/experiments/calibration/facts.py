"""What the calibration chapter quotes of a fit: its 95 % regions as text."""

from __future__ import annotations

__all__ = ["region_text"]


def region_text(estimate: dict, scale: float = 1.0, unit: str = "") -> str:
    """A fit's 95 % region as the chapter writes it: its pieces ``"a–b, c–d unit"``, the values
    divided by ``scale`` (``estimate``: one entry of ``FitResult.estimates``)."""
    text = ", ".join(f"{a / scale:.4g}–{b / scale:.4g}" for a, b in estimate["intervals"])
    return f"{text} {unit}" if unit else text
