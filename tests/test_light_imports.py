"""The simulator and the command line load only what they need.

Which module may import which is the import-linter contracts' business (pyproject.toml, run
by ``nox -s lint``). What they cannot see is what an import loads at run time, third-party
modules included: importing any module of the model or the solver (what every command, sweep
worker and chapter imports first) must load neither pandas nor matplotlib (seconds of start-up
in each process of a parallel sweep). Each import runs in a fresh interpreter, so nothing
another test imported counts.

The command line builds on the same rule: its parser and every command module load only
what a command needs when it runs (CONTRIBUTING, "Architecture"), so ``passmd run`` reaches its
first integrator step without pandas, matplotlib, pint, Dask or tqdm (the progress bar
only on a terminal), and ``passmd --help`` without the simulator.
"""

import json
import pkgutil
import subprocess
import sys

import pytest

import passmd.model
import passmd.solver


def _modules(*packages) -> list[str]:
    """Every module of ``packages``, the packages themselves included."""
    return [name for package in packages
            for name in (package.__name__, *(info.name for info in pkgutil.iter_modules(
                package.__path__, package.__name__ + ".")))]


#: The simulator: the drive's model (parameters, closed forms, contacts, waveforms, drive files)
#: and the solver with its numba kernels.
SIMULATOR = _modules(passmd.model, passmd.solver)

#: Modules the simulator and the ``run`` command do not need (other commands, the book, plots,
#: unit parsing beyond the display units, sweeps, progress bars on a terminal).
HEAVY = ("pandas", "matplotlib", "pint", "dask", "distributed", "tqdm")

_PROBE = """
import importlib, json, sys
importlib.import_module(sys.argv[1])
print(json.dumps(sorted(m for m in json.loads(sys.argv[2]) if m in sys.modules)))
"""


def test_the_simulator_is_found():
    assert {"passmd.model.parameters", "passmd.model.mdr_contact", "passmd.solver.simulation",
            "passmd.solver.kernels"} <= set(SIMULATOR)


@pytest.mark.parametrize("module", SIMULATOR)
def test_simulator_module_loads_no_heavy_module(module):
    done = subprocess.run(
        [sys.executable, "-c", _PROBE, module, json.dumps(HEAVY)],
        capture_output=True, text=True, check=True,
    )
    assert json.loads(done.stdout) == [], f"importing {module} loads {done.stdout.strip()}"


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
from passmd.solver import kernels
heavy = json.loads(sys.argv[1])
loaded = {}
integrate = kernels.integrate
def first_step(*args, **kwargs):
    loaded.setdefault("first_step", [m for m in heavy if m in sys.modules])
    return integrate(*args, **kwargs)
kernels.integrate = first_step
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
