"""What the regression snapshots compare with: the stated accuracies, and the one finer run.

Every snapshot check takes its tolerances from :func:`tolerances`, which maps a column to the
accuracy :mod:`passmd.experiments.model_numerics.facts` states for its quantity (positions, forces,
velocities, frequencies and times, slip shares, critical amplitudes). A column the integrator
does not compute (inputs, closed forms, flags) is compared to :data:`EXACT`: only
floating-point rounding may differ. So a snapshot locks the physics to the integrator's
stated accuracy, and any scheme at least as accurate passes it; the ``*_finer_run_passes``
tests show a run with the step halved does (:func:`finer_run`, the one place the tests ask
for a finer run).
"""

from __future__ import annotations

import contextlib

import pytest

from passmd.experiments.model_numerics import facts
from passmd.model.parameters import Drive
from passmd.runtime.config import RunConfig
from passmd.solver import simulation
from passmd.solver.steps import DEFAULT_SCHEME, resolve_scheme

#: Columns computed without the integrator (inputs, closed forms, booleans): rounding only.
EXACT = {"rtol": 1e-9, "atol": 1e-12}
#: Load-cell stiffness of the force drives (N/m): converts the force accuracy to a length.
LOAD_CELL_STIFFNESS = Drive().load_cell_stiffness
#: How much finer :func:`finer_run` integrates by default: the step halved.
FINER = 2.0


def position(scale: float = 1.0) -> dict:
    return {"rtol": 0.0, "atol": facts.POSITION_ACCURACY * scale}


def force(scale: float = 1.0) -> dict:
    return {"rtol": facts.STALL_FORCE_RTOL, "atol": facts.FORCE_ACCURACY * scale}


def critical_amplitude(bracket_width: float, scale: float = 1.0) -> dict:
    """A critical amplitude or onset found to ``bracket_width`` (m), in units of ``scale`` per m."""
    width = facts.CRITICAL_AMPLITUDE_BRACKETS * bracket_width
    return {"rtol": 0.0, "atol": (width + facts.POSITION_ACCURACY) * scale}


def tolerances(columns, *, amplitudes=(), bracket_width: float = 0.0, forces_in_length=()) -> dict:
    """Tolerance of each column from its unit suffix and the stated accuracies.

    ``amplitudes``: columns that are critical amplitudes or onsets (searched to ``bracket_width``
    m). ``forces_in_length``: length columns that are a stall force over the load-cell stiffness.
    Unlisted columns: lengths (``_m``, ``_nm``) are positions; ``_N``/``_mN`` stall forces;
    ``_m_per_s`` velocities; ``_Hz`` and times (``_s``, ``_us``) relative to FREQUENCY_RTOL;
    ``slip_share`` columns SLIP_SHARE_ACCURACY; the rest :data:`EXACT`.
    """
    out = {}
    for col in columns:
        nano = 1e9 if col.endswith("_nm") else 1.0
        if col in amplitudes:
            out[col] = critical_amplitude(bracket_width, nano)
        elif col in forces_in_length:
            atol = facts.FORCE_ACCURACY / LOAD_CELL_STIFFNESS * nano
            out[col] = {"rtol": facts.STALL_FORCE_RTOL, "atol": atol}
        elif col.endswith("_m_per_s"):
            out[col] = {"rtol": 0.0, "atol": facts.VELOCITY_ACCURACY}
        elif col.endswith(("_m", "_nm")):
            out[col] = position(nano)
        elif col.endswith(("_N", "_mN")):
            out[col] = force(1e3 if col.endswith("_mN") else 1.0)
        elif col.endswith(("_Hz", "_s", "_us")):
            out[col] = {"rtol": facts.FREQUENCY_RTOL, "atol": 0.0}
        elif "slip_share" in col:
            out[col] = {"rtol": 0.0, "atol": facts.SLIP_SHARE_ACCURACY}
        else:
            out[col] = dict(EXACT)
    return out


def numeric(frame):
    """The non-text columns of ``frame``, booleans as 0/1, index 0..n−1 (label strings are not locked)."""
    out = frame.select_dtypes(exclude=["object", "string"]).reset_index(drop=True)
    for col in out.columns:
        if out[col].dtype == bool:
            out[col] = out[col].astype(int)
    return out


@contextlib.contextmanager
def finer_run(factor: float = FINER):
    """Within the block every simulation runs ``factor`` times finer.

    Patches ``simulation.Simulation``, which ``simulation.simulate`` and the stall protocol
    construct: each run's scheme is refined by ``factor`` (:class:`passmd.solver.steps.Scheme`
    ``refine``: explicit steps divided by it, the error-controlled step's local tolerance by its
    fourth power, so that step shrinks about ``factor`` times); a fixed ``dt`` is divided by it.
    Sweeps inside must run serially with a cache of their own (:func:`finer_config`).
    """
    default = simulation.Simulation

    class Finer(default):
        def __init__(self, *args, scheme=DEFAULT_SCHEME, **kwargs):
            scheme = resolve_scheme(scheme)
            if scheme.dt:
                finer = scheme.replace(dt=scheme.dt / factor)
            else:
                finer = scheme.replace(refine=scheme.refine * factor)
            super().__init__(*args, scheme=finer, **kwargs)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(simulation, "Simulation", Finer)
        yield


def finer_config(cache_dir, profile: str = "quick") -> RunConfig:
    """A run configuration for :func:`finer_run`: serial (workers would not see the patch), with
    a cache of its own (the default run's cached results would be returned)."""
    return RunConfig(profile=profile, executor="serial", cache_dir=cache_dir, progress=False)
