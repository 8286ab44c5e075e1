"""The table of every assumption: values the paper does not give, where each is defined.

Each module that makes an assumption defines it next to the code that uses it, as a
module-level tuple ``ASSUMPTIONS`` of :class:`~passmd.model.tables.Assumption` records;
:func:`all_assumptions` concatenates those tuples from the explicit list
:data:`ASSUMPTION_MODULES`, in the order the book's assumptions tables show them.
"""

from __future__ import annotations

from types import ModuleType

import passmd.experiments.force_generation.figures
import passmd.experiments.waveform_optimum.figures
import passmd.experiments.waveform_velocity.figures
from passmd.ledger import reference
from passmd.model import arrangement, contact, optimized_waveform, parameters, tables, waveforms
from passmd.model.tables import Assumption
from passmd.protocols import critical_amplitude, diagnosis, stall

__all__ = ["ASSUMPTION_MODULES", "all_assumptions"]

#: Every module that defines ``ASSUMPTIONS``: the model, then the protocols and experiments
#: in the paper's order (Sections 2–5).
ASSUMPTION_MODULES: tuple[ModuleType, ...] = (
    tables,
    parameters,
    arrangement,
    contact,
    waveforms,
    reference,
    critical_amplitude,
    passmd.experiments.waveform_velocity.figures,
    passmd.experiments.force_generation.figures,
    stall,
    passmd.experiments.waveform_optimum.figures,
    optimized_waveform,
    diagnosis,
)


def all_assumptions() -> dict[str, Assumption]:
    """Every assumption by key, in the order of :data:`ASSUMPTION_MODULES`.

    Raises
    ------
    ValueError
        If two modules define an assumption with the same key.
    """
    table: dict[str, Assumption] = {}
    for module in ASSUMPTION_MODULES:
        for assumption in module.ASSUMPTIONS:
            if assumption.key in table:
                raise ValueError(
                    f"assumption key = {assumption.key!r} is defined twice (again in {module.__name__})"
                )
            table[assumption.key] = assumption
    return table
