"""The core layer of the package stays light and self-contained.

The simulator's modules (parameters, closed forms, contact, waveforms, dynamics and their
numba kernels) are what every command, sweep worker and chapter imports first. Importing
one of them must load neither pandas nor matplotlib (seconds of start-up in each process
of a parallel sweep) and no module of a higher layer (protocols, experiments, figures,
plots, ledger, presentation, command line): the package is layered one way, core at the
bottom. Each import runs in a fresh interpreter, so nothing another test imported counts.
Imports inside functions count too: the sources are read for every import statement.
"""

import ast
import importlib.util
import json
import subprocess
import sys

import pytest

#: The modules on the simulator's path (the kernels included).
KERNEL_PATH = (
    "passmd.parameters",
    "passmd.theory",
    "passmd.contact",
    "passmd._contact_kernels",
    "passmd.waveforms",
    "passmd.optimized_waveform",
    "passmd.time_steps",
    "passmd.dynamics",
    "passmd._dynamics_kernel",
)

#: The core layer: the only passmd modules a kernel-path import may load.
CORE = frozenset(
    KERNEL_PATH
    + (
        "passmd",
        "passmd.units",
        "passmd._validation",
        "passmd.config",
        "passmd.defaults",
        "passmd.cache",
        "passmd.provenance",
        "passmd.readings",
        "passmd.reference",
    )
)

HEAVY = ("pandas", "matplotlib")

_PROBE = """
import importlib, json, sys
importlib.import_module(sys.argv[1])
print(json.dumps(sorted(m for m in sys.modules if m == "passmd" or m.startswith("passmd."))))
print(json.dumps(sorted(m for m in json.loads(sys.argv[2]) if m in sys.modules)))
"""


@pytest.mark.parametrize("module", KERNEL_PATH)
def test_core_module_imports_no_pandas_matplotlib_or_higher_layer(module):
    done = subprocess.run(
        [sys.executable, "-c", _PROBE, module, json.dumps(HEAVY)],
        capture_output=True, text=True, check=True,
    )
    loaded, heavy = (json.loads(line) for line in done.stdout.splitlines())
    assert heavy == [], f"importing {module} loads {heavy}"
    assert module in loaded  # the probe imported what it should
    assert set(loaded) <= CORE, f"importing {module} loads higher layers: {sorted(set(loaded) - CORE)}"


def _imported_passmd_modules(tree: ast.Module) -> set[str]:
    """Every passmd module an import statement anywhere in ``tree`` names (functions included)."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names if a.name.split(".")[0] == "passmd")
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "passmd":
            names.add(node.module)
            if node.module == "passmd":  # from passmd import dynamics, ...
                names.update(f"passmd.{a.name}" for a in node.names)
    return names


@pytest.mark.parametrize("module", KERNEL_PATH)
def test_core_module_source_names_no_higher_layer(module):
    """No import statement of a core module, not even one inside a function, reaches up."""
    path = importlib.util.find_spec(module).origin
    with open(path, encoding="utf-8") as source:
        names = _imported_passmd_modules(ast.parse(source.read()))
    assert names <= CORE, f"{module} imports higher layers: {sorted(names - CORE)}"


@pytest.mark.parametrize("module", ["passmd.waveforms", "passmd.optimized_waveform"])
def test_waveform_constructors_never_reach_the_simulator(module):
    """Waveforms are pure constructors (Eq. 15's design from a simulated response lives in
    passmd.protocols.eq15): their modules import nothing of the simulator."""
    path = importlib.util.find_spec(module).origin
    with open(path, encoding="utf-8") as source:
        names = _imported_passmd_modules(ast.parse(source.read()))
    simulator = {"passmd.dynamics", "passmd._dynamics_kernel", "passmd.time_steps", "passmd.contact"}
    assert not names & simulator, f"{module} imports {sorted(names & simulator)}"
