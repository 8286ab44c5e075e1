"""passmd: reproducible replication of Nguyen et al. (2018), Coatings 8, 62.

"Improvements of Piezo-Actuated Stick–Slip Micro-Drives: Modeling and Driving
Waveform". One folder per domain, and one per book chapter under ``experiments``:

``model``
    parameters (Tables 1–2), closed forms (Eqs. 1, 7–14), the MDR contact (Eqs. 4–6),
    waveforms and the Eq. 15 design, drive files, protocol defaults
``solver``
    the hybrid simulation (Eqs. 2–3), its integration schemes and numba kernels
``protocols``
    the paper's measurements: critical amplitude, stall force, velocity, Eq. 15 design, fit
``experiments``
    each chapter's figure data, claim extractors and facts; the figure table
``ledger``
    the paper's claims, their checks, the assumption space and the verdicts
``plots``, ``report``, ``cli``
    drawing, the book's helpers, the ``passmd`` command line
``runtime``
    cache, sweeps, run configuration, units, provenance, input checks

Which may import which is the ``layers`` contract of ``pyproject.toml`` (import-linter).

The names a drive designer needs are exported here, loaded on first use: ``Drive``,
``paper_drive``, ``sawtooth``, ``simulate``, ``Simulation``, ``drive_theory``,
``critical_amplitude``, ``generated_force``, ``optimized_design``, ``optimized`` and
``highest_fitting_frequency`` (Eq. 15's design, waveform and where it fits), ``RunConfig``,
``load_drive``/``drive_toml`` (read and write a drive file; ``EXAMPLE_DRIVE_FILE``, the book's
worked example), ``contact_arrangement`` (each contact group's side, angle and normal force),
``compute_map`` (what ``passmd sweep`` computes), ``stick_ringing`` (the runner's swing after a
fly-back), ``diagnose`` (why a result departs from its closed form or trend, one cause removed at a
time), and ``fit``/``read_measurements`` (calibrate free drive parameters to measurements).
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
    "Drive": "passmd.model.parameters",
    "paper_drive": "passmd.model.parameters",
    "sawtooth": "passmd.model.waveforms",
    "simulate": "passmd.solver.simulation",
    "Simulation": "passmd.solver.simulation",
    "drive_theory": "passmd.model.theory",
    "critical_amplitude": "passmd.protocols.critical_amplitude",
    "generated_force": "passmd.protocols.stall",
    "optimized_design": "passmd.protocols.eq15",
    "optimized": "passmd.model.optimized_waveform",
    "highest_fitting_frequency": "passmd.model.optimized_waveform",
    "RunConfig": "passmd.runtime.config",
    "load_drive": "passmd.model.drive_file",
    "drive_toml": "passmd.model.drive_file",
    "EXAMPLE_DRIVE_FILE": "passmd.model.drive_file",
    "contact_arrangement": "passmd.model.theory",
    "compute_map": "passmd.protocols.maps",
    "stick_ringing": "passmd.protocols.ringing",
    "diagnose": "passmd.protocols.diagnosis",
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
