"""The core layer of the package stays light and self-contained.

The simulator's modules (parameters, closed forms, contact, waveforms, dynamics and their
numba kernels) are what every command, sweep worker and chapter imports first. Importing
one of them must load neither pandas nor matplotlib (seconds of start-up in each process
of a parallel sweep) and no module of a higher layer (protocols, experiments, figures,
plots, ledger, presentation, command line): the package is layered one way, core at the
bottom. Each import runs in a fresh interpreter, so nothing another test imported counts.
"""

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
