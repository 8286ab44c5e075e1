"""Calibration: the drive parameters that make the simulator reproduce measurements.

Measurements (:func:`~passmd.protocols.fit.measurements.read_measurements`) are rows of a CSV
whose column names carry their units: the conditions ``amplitude_nm``, ``preload_N``,
``frequency_Hz``, ``radius_mm`` and one measured quantity per row, each with an optional
standard deviation ``<quantity>_sd``:

``step_nm``
    Steady step of a running drive under a saw-tooth, what a test stand measures once the drive
    runs: below :data:`passmd.protocols.velocity.STEP_PROTOCOL_BELOW` the step of a run continued
    until it repeats itself from one period to the next
    (:func:`passmd.protocols.velocity.settled_step`); above it the steady-velocity protocol's
    velocity / f (Figs. 9b/10).
``velocity_mm_per_s``
    The same protocols' velocity (steady step × f).
``critical_amplitude_nm``
    Critical amplitude A_c of Section 4.1 (:func:`passmd.protocols.critical_amplitude.critical_amplitude`,
    with the reading ``"steady"`` or ``"first"``; no A_c up to the full stroke reads as A_max).
``force_N``
    Generated force at stall against the load cell (Section 4.2, :mod:`passmd.protocols.stall`).
``position_nm``
    Runner position after three saw-tooth periods from rest (Fig. 9a's protocol): a measurement of
    a start from rest, not of a running drive (its first step carries the start-up transient).

Optional columns ``contacts`` (1 or 6) and ``actuator_model`` (``rigid`` or ``flexible``) set a
row's drive like ``preload_N`` and ``radius_mm``; the text columns ``id``, ``source_section``,
``source_quote`` and ``notes`` (where a row comes from) are allowed and ignored. Every row is
checked against the drive before anything is simulated (:func:`~passmd.protocols.fit.checks.check_rows`).
The fly-back of the simulated saw-tooth is the drive's rule (:attr:`passmd.model.tables.Amplifier.flyback`).

Estimator (:func:`~passmd.protocols.fit.estimator.fit`): weighted least squares over the logarithms
of the free parameters, every model evaluation one cached sweep point per parameter set (per part
of its rows when a batch has too few sets to keep the workers busy;
:mod:`~passmd.protocols.fit.prediction`). The whole range is searched before anything is refined:
a global pass (:data:`~passmd.protocols.fit.estimator.GLOBAL_POINTS_PER_PARAMETER` Sobol points per
free parameter), local searches from its distinct best points, then each parameter's profile over
its whole bounds (:mod:`~passmd.protocols.fit.profiles`: a coarse grid, fine sampling wherever a
tooth of a comb of minima could hide within the 95 % level, the bottom of every low minimum). The
estimate is the lowest point found anywhere.

Uncertainty (:mod:`~passmd.protocols.fit.regions`): a parameter's 95 % region is every value whose
profile, or the local profile of a basin (a local minimum within the level), lies within
:func:`~passmd.protocols.fit.estimator.region_level` above the minimum — the 95 % quantile of χ²
with p degrees of freedom for p free parameters (σ given), or p · F(p, n − p) (σ estimated, the
cost in units of the residual variance): the projection of the joint 95 % region, one interval or
several separate pieces. Several pieces mean the parameter is
not uniquely identified; :func:`~passmd.protocols.fit.next_measurement.separating_row` computes the
added row that best separates the basins. A region reaching a bound means not identifiable. With σ
given, the minimum is tested against χ² with n − p degrees of freedom
(:func:`~passmd.protocols.fit.result.goodness_of_fit`): below p =
:data:`~passmd.protocols.fit.result.REJECT_P` the model does not describe the data and no interval
is called calibrated. Local standard errors (``s² (JᵀJ)⁻¹``) and the correlation matrix are reported
beside the regions.

The code: :mod:`~passmd.protocols.fit.measurements` (the measurement files),
:mod:`~passmd.protocols.fit.checks` (rows against the drive), :mod:`~passmd.protocols.fit.free_parameters`
(what may be fitted), :mod:`~passmd.protocols.fit.prediction` (the model's values),
:mod:`~passmd.protocols.fit.problem`, :mod:`~passmd.protocols.fit.profiles`,
:mod:`~passmd.protocols.fit.regions`, :mod:`~passmd.protocols.fit.next_measurement`,
:mod:`~passmd.protocols.fit.estimator` (:func:`~passmd.protocols.fit.estimator.fit`) and
:mod:`~passmd.protocols.fit.result` (:class:`~passmd.protocols.fit.result.FitResult`, the fitted
drive file); every public name is importable from ``passmd.protocols.fit``."""

import importlib

#: Every public name, by the module that defines it. They load on first use (module
#: ``__getattr__``, PEP 562): the command line builds ``--free`` from :data:`FREE_PARAMETERS`
#: without importing the estimator and the simulator.
_MODULES = {
    "checks": ("TRAVEL_FACTOR", "check_rows"),
    "estimator": ("DISTINCT", "GLOBAL_POINTS_PER_PARAMETER", "LOCAL_STARTS", "LOSSES", "MAX_BASINS",
                  "POLISH_CANDIDATES", "PROGRESS_INTERVAL", "REFIT_MARGIN", "REFITS", "fit", "region_level"),
    "free_parameters": ("FREE_PARAMETERS", "KEEPS", "FreeParameter", "default_bounds", "plausible_bounds"),
    "measurements": ("CONDITIONS", "MAX_ROWS", "MEASURED", "MeasurementError", "Measurements",
                     "measurements_from_rows", "read_measurements", "write_measurements"),
    "prediction": ("predict", "predict_point"),
    "problem": ("GN_STEP_LIMIT", "JACOBIAN_STEPS", "LOCAL_EVALUATIONS"),
    "profiles": ("BOTTOM_DROP", "BOTTOM_FIRST", "BOTTOM_MAX", "BOTTOM_RESOLUTION", "BOTTOM_STEPS",
                 "FILL_BATCH", "FILL_FIRST", "FILL_SAFETY", "FINE_SPACING", "PROBE_POINTS",
                 "PROFILE_MIN_POINTS", "PROFILE_SPACING", "SMOOTH_DEPARTURE"),
    "regions": ("BASIN_PROMINENCE",),
    "result": ("CORRELATION_LIMIT", "REJECT_P", "FitResult", "fitted_drive_file", "goodness_of_fit"),
}
_MODULE_OF = {name: f"passmd.protocols.fit.{module}" for module, names in _MODULES.items() for name in names}
#: Names of other modules, importable from here too and documented where they are defined.
_MODULE_OF.update(dict.fromkeys(("ANNOTATIONS", "MODELS", "READINGS"), "passmd.protocols.fit.measurements"))
_MODULE_OF["InputError"] = "passmd.runtime.validation"

__all__ = sorted(name for names in _MODULES.values() for name in names)


def __getattr__(name: str):
    if name in _MODULE_OF:
        value = getattr(importlib.import_module(_MODULE_OF[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'passmd.protocols.fit' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_MODULE_OF))
