"""The assumptions table: every module's ASSUMPTIONS collected explicitly, none missed, none twice;
each row says the default a user of the package gets."""

from __future__ import annotations

import importlib
import inspect
import math
import pkgutil
import re

import numpy as np
import pytest

import passmd
from passmd.model import tables
from passmd.model.mdr_contact import MDRContact
from passmd.model.tables import Assumption
from passmd.report import assumptions


def _modules_defining_assumptions() -> set[str]:
    names = set()
    for info in pkgutil.walk_packages(passmd.__path__, prefix="passmd."):
        if info.name.endswith("__main__") or info.name.startswith("passmd.cli"):
            continue  # running __main__ would start the command line
        module = importlib.import_module(info.name)
        if "ASSUMPTIONS" in vars(module) and module.__name__ == info.name:
            names.add(info.name)
    return names


def test_every_module_with_assumptions_is_listed():
    """A module that defines ASSUMPTIONS but is missing from the explicit list would drop out of the book."""
    listed = {module.__name__ for module in assumptions.ASSUMPTION_MODULES}
    assert _modules_defining_assumptions() == listed


def test_all_assumptions_concatenates_the_tuples_in_order():
    table = assumptions.all_assumptions()
    expected = [a.key for module in assumptions.ASSUMPTION_MODULES for a in module.ASSUMPTIONS]
    assert list(table) == expected
    assert all(isinstance(a, Assumption) and a.rationale and a.sensitivity for a in table.values())


def test_the_table_opens_with_what_the_paper_leaves_out_of_its_tables():
    """Before any protocol or chapter, the reader meets the gaps in Tables 1–2: the drive itself."""
    table = list(assumptions.all_assumptions())
    assert table[:len(tables.ASSUMPTIONS)] == [a.key for a in tables.ASSUMPTIONS]


def _default(function, parameter):
    return inspect.signature(function).parameters[parameter].default


def _preload_grids(text: str) -> dict[float, np.ndarray]:
    """``{R (m): preloads (N)}`` of the table's "0.1–1.0 at R = 1 mm and …, in steps of 0.1" (unit N)."""
    step = float(re.search(r"in steps of ([\d.]+)", text)[1])
    grids = {}
    for low, high, radius in re.findall(r"([\d.]+)–([\d.]+) at R = ([\d.]+) mm", text):
        count = round((float(high) - float(low)) / step) + 1
        grids[float(radius) * 1e-3] = float(low) + step * np.arange(count)
    return grids


def test_the_table_states_the_defaults_a_user_gets():
    """Each row whose default is a number says the number the package runs with."""
    table = assumptions.all_assumptions()
    drive = passmd.Drive()
    # ζ of the actuator's viscosity c_p = 2·ζ·√(k_p m_a)
    zeta = float(re.search(r"ζ = ([\d.]+) \(dimensionless\)$", table["actuator_viscosity"].value)[1])
    act = drive.actuator
    assert act.viscosity == pytest.approx(2 * zeta * math.sqrt(act.stiffness * act.mass), rel=1e-12)
    # the preload grids of Figs. 5b and 6
    assert table["preload_grids"].unit == "N"
    grids = _preload_grids(table["preload_grids"].value)
    assert grids.keys() == tables.PRELOAD_GRIDS.keys()
    for radius, preloads in tables.PRELOAD_GRIDS.items():
        np.testing.assert_allclose(grids[radius], preloads, rtol=0, atol=1e-12)
    assert float(table["molybdenum_poisson"].value) == tables.MOLYBDENUM.poissons_ratio
    # the fly-back: the amplifier's voltage and slew rate
    volts, slew = re.search(r"· ([\d.]+) V / \(([\d.]+) V/µs\)$", table["flyback_duration"].value).groups()
    amplifier = drive.amplifier
    assert (float(volts), float(slew) * 1e6) == (amplifier.peak_to_peak_voltage, amplifier.slew_rate)
    # the settled position: the last part of each stick phase
    share = float(re.search(r"last ([\d.]+)% of each stick phase", table["settled_position"].value)[1])
    assert share / 100 == _default(passmd.sawtooth, "settle_fraction")
    capacity = int(re.match(r"(\d+) reversal points", table["reversal_stack_capacity"].value)[1])
    assert capacity == _default(MDRContact, "capacity")
    threshold = table["critical_amplitude_step_threshold"]
    assert threshold.unit == "nm"
    assert float(threshold.value) * 1e-9 == pytest.approx(_default(passmd.critical_amplitude, "threshold"),
                                                          rel=1e-12)


def test_a_key_defined_twice_is_an_error(monkeypatch):
    first = assumptions.ASSUMPTION_MODULES[0]
    monkeypatch.setattr(assumptions, "ASSUMPTION_MODULES", (first, first))
    with pytest.raises(ValueError, match="defined twice"):
        assumptions.all_assumptions()
