"""passmd: reproducible replication of Nguyen et al. (2018), Coatings 8, 62.

"Improvements of Piezo-Actuated Stick–Slip Micro-Drives: Modeling and Driving
Waveform". Its modules follow the paper's structure, in layers from the model up (the
``layers`` contract of ``pyproject.toml``, checked by import-linter):

core
    ``parameters`` (Tables 1–2, drive records), ``defaults`` (protocol defaults), ``config``
    (run configuration), ``theory`` (Hertz, Cattaneo–Mindlin, Eqs. 1 and 7–14), ``contact``
    (MDR contact with memory, Eqs. 4–6), ``waveforms`` and ``optimized_waveform`` (saw-tooth,
    Eq. 15), ``dynamics`` and ``time_steps`` (runner and actuators, Eqs. 2–3), ``reference``,
    ``readings``, ``cache``, ``units``, ``provenance``, ``drive_file`` (drive files, TOML)
protocols
    ``protocols`` (critical-amplitude search, stall criterion, step and velocity, Eq. 15
    design), ``sweep`` (parallel, cached grids), ``claims`` and ``checks`` (the ledger's
    schema and checks), ``mdr_validation``
plots
    ``plots`` (a figure's data to a matplotlib figure)
figures
    ``figures`` (the figure table), ``experiments`` (compute functions, claim extractors,
    chapter facts), ``ledger`` (claims against results), ``assumptions``
presentation
    ``publish`` (the chapters' glue), ``ledger_views``
entry points
    ``cli`` (the ``passmd`` command line), ``__main__``

The names a drive designer needs are exported here, loaded on first use: ``Drive``,
``paper_drive``, ``sawtooth``, ``simulate``, ``Simulation``, ``drive_theory``,
``critical_amplitude``, ``generated_force``, ``optimized_design``, ``RunConfig``,
``load_drive``/``drive_toml`` (read and write a drive file), and ``fit``/``read_measurements``
(calibrate free drive parameters to measurements).
"""

#: The version: its one source (pyproject.toml reads it, ``dynamic = ["version"]``; CITATION.cff
#: and CHANGELOG.md name it, and tests/test_packaging.py checks they agree).
__version__ = "0.1.0"

#: The replicated paper, as cited in the book and the command line's help.
PAPER_CITATION = (
    "X.-H. Nguyen, T.-H. Mau, I. Meyer, B.-L. Dang, H.-P. Pham, "
    "\"Improvements of Piezo-Actuated Stick–Slip Micro-Drives: Modeling and Driving "
    "Waveform\", Coatings 8(2), 62 (2018), doi:10.3390/coatings8020062"
)

#: The names a drive designer needs, re-exported from their modules. They load on first use
#: (module ``__getattr__``, PEP 562), so ``import passmd`` and the command line's start-up do
#: not import the simulator.
_API = {
    "Drive": "passmd.parameters",
    "paper_drive": "passmd.parameters",
    "sawtooth": "passmd.waveforms",
    "simulate": "passmd.dynamics",
    "Simulation": "passmd.dynamics",
    "drive_theory": "passmd.theory",
    "critical_amplitude": "passmd.protocols.critical_amplitude",
    "generated_force": "passmd.protocols.stall",
    "optimized_design": "passmd.protocols.eq15",
    "RunConfig": "passmd.config",
    "load_drive": "passmd.drive_file",
    "drive_toml": "passmd.drive_file",
    "fit": "passmd.protocols.fit",
    "read_measurements": "passmd.protocols.fit",
}

__all__ = ["PAPER_CITATION", "__version__", *_API]


def __getattr__(name: str):
    if name in _API:
        import importlib

        value = getattr(importlib.import_module(_API[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'passmd' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_API))
