"""The assumptions table: every module's ASSUMPTIONS collected explicitly, none missed, none twice."""

from __future__ import annotations

import importlib
import pkgutil

import pytest

import passmd
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
    assert list(table)[:2] == ["actuator_viscosity", "preload_grids"]  # the drive's parameters first


def test_a_key_defined_twice_is_an_error(monkeypatch):
    first = assumptions.ASSUMPTION_MODULES[0]
    monkeypatch.setattr(assumptions, "ASSUMPTION_MODULES", (first, first))
    with pytest.raises(ValueError, match="defined twice"):
        assumptions.all_assumptions()
