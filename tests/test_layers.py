"""The core layer of the package stays light and self-contained.

The simulator's modules (parameters, closed forms, contact, waveforms, dynamics and their
numba kernels) are what every command, sweep worker and chapter imports first. Importing
one of them must load neither pandas nor matplotlib (seconds of start-up in each process
of a parallel sweep) and no module of a higher layer (protocols, experiments, figures,
plots, ledger, presentation, command line): the package is layered one way, core at the
bottom. Each import runs in a fresh interpreter, so nothing another test imported counts.
Imports inside functions count too: the sources are read for every import statement.

The command line builds on the same rule: its parser and every command module load only
what a command needs when it runs (CONTRIBUTING, "Architecture"), so ``passmd run`` reaches its
first integrator step without pandas, matplotlib, pint, Dask or tqdm (the progress bar
only on a terminal), and ``passmd --help`` without the simulator.
"""

import ast
import importlib.util
import json
import subprocess
import sys

import pytest

#: The modules on the simulator's path (the kernels included).
KERNEL_PATH = (
    "passmd.model.parameters",
    "passmd.model.theory",
    "passmd.model.hertz",
    "passmd.model.contact",
    "passmd.model.mdr_contact",
    "passmd.model.contact_kernels",
    "passmd.model.waveforms",
    "passmd.model.optimized_waveform",
    "passmd.solver.steps",
    "passmd.solver.simulation",
    "passmd.solver.setup",
    "passmd.solver.results",
    "passmd.solver.kernels",
)

#: The packages of the simulator's path: the model, the solver and the runtime beneath them.
CORE_PACKAGES = ("passmd.model", "passmd.solver", "passmd.runtime")


def _outside_core(modules) -> list[str]:
    """The passmd modules of ``modules`` outside the simulator's packages (the root excepted)."""
    return sorted(m for m in modules
                  if m != "passmd" and not any(m == p or m.startswith(p + ".") for p in CORE_PACKAGES))


#: Modules the simulator and the ``run`` command do not need (other commands, the book, plots,
#: unit parsing beyond the display units, sweeps, progress bars on a terminal).
HEAVY = ("pandas", "matplotlib", "pint", "dask", "distributed", "tqdm")

_PROBE = """
import importlib, json, sys
importlib.import_module(sys.argv[1])
print(json.dumps(sorted(m for m in sys.modules if m == "passmd" or m.startswith("passmd."))))
print(json.dumps(sorted(m for m in json.loads(sys.argv[2]) if m in sys.modules)))
"""


@pytest.mark.parametrize("module", KERNEL_PATH)
def test_core_module_imports_no_heavy_module_or_higher_layer(module):
    done = subprocess.run(
        [sys.executable, "-c", _PROBE, module, json.dumps(HEAVY)],
        capture_output=True, text=True, check=True,
    )
    loaded, heavy = (json.loads(line) for line in done.stdout.splitlines())
    assert heavy == [], f"importing {module} loads {heavy}"
    assert module in loaded  # the probe imported what it should
    assert _outside_core(loaded) == [], f"importing {module} loads higher layers: {_outside_core(loaded)}"


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
    assert _outside_core(names) == [], f"{module} imports higher layers: {_outside_core(names)}"


@pytest.mark.parametrize("module", ["passmd.model.waveforms", "passmd.model.optimized_waveform"])
def test_waveform_constructors_never_reach_the_simulator(module):
    """Waveforms are pure constructors (Eq. 15's design from a simulated response lives in
    passmd.protocols.eq15): their modules import nothing of the simulator."""
    path = importlib.util.find_spec(module).origin
    with open(path, encoding="utf-8") as source:
        names = _imported_passmd_modules(ast.parse(source.read()))
    simulator = {"passmd.solver.simulation", "passmd.solver.kernels", "passmd.solver.steps",
                 "passmd.model.contact", "passmd.model.mdr_contact"}
    assert not names & simulator, f"{module} imports {sorted(names & simulator)}"


# Builds the parser and parses a ``run`` command line, as ``passmd`` does before dispatching.
_PARSER_PROBE = """
import json, sys
from passmd.cli import make_parser
args = make_parser().parse_args(["run", "--periods", "1"])
assert args.handler.__name__ == "run_run", args.handler
print(json.dumps(sorted(m for m in json.loads(sys.argv[1]) if m in sys.modules)))
"""


def test_command_line_parser_loads_no_heavy_module_nor_the_simulator():
    """Every command module is imported to build the parser: none may load a heavy module, and
    ``passmd --help`` or a usage error needs no numba."""
    done = subprocess.run(
        [sys.executable, "-c", _PARSER_PROBE, json.dumps([*HEAVY, "numba", "scipy"])],
        capture_output=True, text=True, check=True,
    )
    assert json.loads(done.stdout) == []


# Runs ``passmd run`` in this fresh interpreter; prints the heavy modules loaded when the command
# enters the integrator (the checking wrapper ``kernels.integrate``, which
# passmd.solver.simulation looks up at call time) and when the command has printed its result.
_RUN_PROBE = """
import contextlib, io, json, sys
from passmd import cli
from passmd.solver import kernels as kern
heavy = json.loads(sys.argv[1])
loaded = {}
integrate = kern.integrate
def first_step(*args, **kwargs):
    loaded.setdefault("first_step", [m for m in heavy if m in sys.modules])
    return integrate(*args, **kwargs)
kern.integrate = first_step
with contextlib.redirect_stdout(io.StringIO()):
    status = cli.main(sys.argv[2:])
loaded["end"] = [m for m in heavy if m in sys.modules]
print(json.dumps({"status": status, **loaded}))
"""


def test_run_command_loads_no_heavy_module(tmp_path):
    """``passmd run`` (one period of a one-contact rigid drive: a cheap run; a quantity with its
    unit) loads no heavy module, neither before its first integrator step nor up to its printed
    result."""
    argv = ["run", "--periods", "1", "--contacts", "1", "--actuator", "rigid", "--frequency", "100Hz",
            "--max-points", "2", "--json"]
    done = subprocess.run(
        [sys.executable, "-c", _RUN_PROBE, json.dumps(HEAVY), *argv],
        capture_output=True, text=True, check=True, cwd=tmp_path,
    )
    report = json.loads(done.stdout.splitlines()[-1])
    assert report["status"] == 0, done.stderr
    assert report["first_step"] == [], f"passmd run loads {report['first_step']} before its first step"
    assert report["end"] == [], f"passmd run loads {report['end']}"
