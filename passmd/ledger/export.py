"""The evaluated ledger as plain records with SI keys: what ``passmd ledger --json`` prints."""

from __future__ import annotations

import math
import re

import numpy as np
import pandas as pd

from passmd.ledger.claims import is_number

__all__ = ["SI_UNITS", "records"]


#: SI name and factor of each claim unit, for machine-readable output (keys carry the SI unit).
SI_UNITS = {"nm": ("m", 1e-9), "mm/s": ("m_per_s", 1e-3), "kHz": ("Hz", 1e3), "mN": ("N", 1e-3),
            "N/m": ("N_per_m", 1.0), "%": ("percent", 1.0), "µs": ("s", 1e-6), "periods": ("periods", 1.0),
            "": ("", 1.0)}


def records(evaluated: pd.DataFrame) -> list[dict]:
    """The ledger as plain records with SI keys (``passmd ledger --json``).

    Per claim: ``claim``, ``category``, ``basis``, ``verdict``, ``evidence`` (list),
    ``reason``, ``depends_on`` (list), ``readings`` (``{reading: state}``), ``points`` (every
    evaluated reading as ``{axis: value}`` of its axes, with state, score and detail),
    ``held_out_reading`` (the reading it is judged at, ``{axis: value}`` of its axes: the joint reading
    chosen without it), ``held_out_described``, ``held_out_state``, ``why`` (the one reason there),
    ``family`` (the lead of its family) and ``counted``, ``default_state``, ``joint_state`` (at the
    in-sample joint reading), ``margin`` and ``margin_text``, ``holds_at``, ``fails_at``,
    ``undecided_at`` and ``decided_at``, ``fragile``, ``informative`` and ``not_informative``,
    ``fraction_holds``,
    ``best_reading``, ``tolerance`` (as shown), and, where numeric, ``paper_<si>``,
    ``ours_<si>`` and ``abs_deviation_<si>`` in SI units (e.g. ``ours_m``, ``paper_m_per_s``),
    ``rel_deviation`` as a fraction. Non-numeric values are null, with ``ours_text`` as shown.
    """
    points = pd.DataFrame(evaluated.attrs.get("points", []),
                          columns=["claim", "reading", "point", "state", "detail", "outside", "score"])
    out = []
    for row in evaluated.itertuples():
        si, factor = SI_UNITS.get(row.unit, (re.sub(r"[^A-Za-z0-9]+", "_", row.unit), 1.0))
        suffix = f"_{si}" if si else ""

        def number(value, factor=factor):
            if isinstance(value, (int, float, np.floating)) and not isinstance(value, bool):
                return float(value) * factor if math.isfinite(value) else None
            return None

        stated = str(row.paper).split(" ")[0]  # the number the paper states, before its unit
        paper = number(float(stated)) if is_number(stated) else None
        mine = points[points["claim"] == row.claim]
        depends = [d for d in row.depends_on.split(";") if d]
        held = next((p for p, r in zip(mine["point"], mine["reading"], strict=True)
                     if r == row.held_out_reading), {}) if len(mine) else {}
        out.append({
            "claim": row.claim, "figure": row.figure, "category": row.status, "basis": row.basis,
            "verdict": row.verdict, "evidence": [e for e in row.evidence.split(" | ") if e],
            "reason": row.reason, "depends_on": [d for d in row.depends_on.split(";") if d],
            "readings": dict(zip(mine["reading"], mine["state"], strict=True)),
            "points": [{"reading": p, "state": st, "detail": d, "outside": o,
                        "score": float(sc) if sc is not None and math.isfinite(sc) else None}
                       for p, st, sc, d, o in zip(mine["point"], mine["state"], mine["score"], mine["detail"],
                                                  mine["outside"], strict=True)],
            "held_out_reading": {k: held[k] for k in depends if k in held},
            "held_out_described": row.held_out_reading, "held_out_state": row.held_out_state, "why": row.why,
            "family": row.family, "counted": bool(row.counted),
            "default_state": row.default_state, "joint_state": row.joint_state,
            "margin": None if not math.isfinite(row.margin) else float(row.margin),
            "margin_text": row.margin_text, "holds_at": int(row.holds_at), "fails_at": int(row.fails_at),
            "undecided_at": int(row.undecided_at), "decided_at": int(row.decided_at),
            "fragile": bool(row.fragile), "fragile_reason": row.fragile_reason, "outside": row.outside,
            "study_of": row.study_of, "informative": bool(row.informative),
            "not_informative": row.not_informative,
            "fraction_holds": None if not math.isfinite(row.fraction_holds) else float(row.fraction_holds),
            "best_reading": row.best_reading, "tolerance": row.tolerance, "check": row.check,
            f"paper{suffix}": paper, f"ours{suffix}": number(row.ours), "ours_text": row.ours_text,
            f"abs_deviation{suffix}": number(row.abs_deviation),
            "rel_deviation": None if not math.isfinite(row.rel_deviation) else float(row.rel_deviation),
        })
    return out
