"""Calibration: the drive parameters that make the simulator reproduce measurements.

Measurements (:func:`~passmd.protocols.fit.measurements.read_measurements`) are rows of a CSV
whose column names carry their units: the conditions ``amplitude_nm``, ``preload_N``,
``frequency_Hz``, ``radius_mm`` and one measured quantity per row, each with an optional
standard deviation ``<quantity>_sd``:

``step_nm``
    Steady step of a saw-tooth (below :data:`passmd.protocols.velocity.STEP_PROTOCOL_BELOW`:
    mean step of a run of three periods from rest, Fig. 9a; above: the steady-velocity
    protocol's step, Figs. 9b/10).
``velocity_mm_per_s``
    The same protocols' velocity (step × f).
``critical_amplitude_nm``
    Critical amplitude A_c of Section 4.1 (:func:`passmd.protocols.critical_amplitude.critical_amplitude`,
    with the reading ``"steady"`` or ``"first"``; no A_c up to the full stroke reads as A_max).
``force_N``
    Generated force at stall against the load cell (Section 4.2, :mod:`passmd.protocols.stall`).
``position_nm``
    Runner position after three saw-tooth periods from rest (Fig. 9a's protocol).

Optional columns ``contacts`` (1 or 6) and ``actuator_model`` (``rigid`` or ``flexible``) set a
row's drive like ``preload_N`` and ``radius_mm``; the text columns ``id``, ``source_section``,
``source_quote`` and ``notes`` (where a row comes from) are allowed and ignored.

Estimator (:func:`~passmd.protocols.fit.estimator.fit`): weighted least squares,
``scipy.optimize.least_squares`` (trust-region reflective, bounded, optional robust loss) over
the logarithms of the free parameters, so that parameters spanning decades are scaled alike.
Every model evaluation runs through :func:`passmd.runtime.sweep.run` (parallel and cached); the
residual Jacobian is a forward difference of relative step
:data:`~passmd.protocols.fit.estimator.JACOBIAN_STEP`, evaluated in the same sweep as its base
point. A coarse global pass (a scrambled Sobol design of
:data:`~passmd.protocols.fit.estimator.GLOBAL_STARTS` points over the bounds, one sweep) picks
the starts, so that a kink of the stick–slip response does not trap the local search. A free
parameter whose residuals oscillate on the Jacobian's scale
(:data:`~passmd.protocols.fit.estimator.ROUGHNESS_LIMIT`; the step of a flexible drive against
k_p) is then scanned around the estimate, the others re-minimised, and a lower point restarts
the local search. When a profile still meets a lower cost than the estimate, the fit says it has
not converged to the global minimum and claims no intervals.

Uncertainty: standard errors from the Jacobian at the optimum (``s² (JᵀJ)⁻¹``, with ``s²`` the
residual variance when no standard deviations are given, else 1), the correlation matrix, and a
95 % interval per parameter from its profile likelihood: the parameter is moved from the
estimate until the least-squares cost, re-minimised over the other free parameters, has risen by
the 95 % quantile of χ²₁ (known standard deviations) or of F(1, n − p) (residual variance
estimated). A parameter is *not identifiable* when its profile stays below that rise up to a
bound (a flat profile), when the Jacobian is rank deficient, or when its correlation with
another parameter exceeds :data:`~passmd.protocols.fit.result.CORRELATION_LIMIT` in magnitude.

The code: :mod:`~passmd.protocols.fit.measurements` (the measurement files),
:mod:`~passmd.protocols.fit.free_parameters` (what may be fitted),
:mod:`~passmd.protocols.fit.prediction` (the model's values),
:mod:`~passmd.protocols.fit.estimator` (:func:`~passmd.protocols.fit.estimator.fit`) and
:mod:`~passmd.protocols.fit.result` (:class:`~passmd.protocols.fit.result.FitResult`, the fitted
drive file); every public name is importable from ``passmd.protocols.fit``."""

from passmd.protocols.fit.checks import check_rows
from passmd.protocols.fit.estimator import (
    DISTINCT,
    GLOBAL_POINTS_PER_PARAMETER,
    LOCAL_STARTS,
    LOSSES,
    MAX_BASINS,
    REFIT_MARGIN,
    REFITS,
    fit,
)
from passmd.protocols.fit.free_parameters import FREE_PARAMETERS, KEEPS, FreeParameter, default_bounds
from passmd.protocols.fit.measurements import ANNOTATIONS as ANNOTATIONS
from passmd.protocols.fit.measurements import (
    CONDITIONS,
    MEASURED,
    MeasurementError,
    Measurements,
    measurements_from_rows,
    read_measurements,
    write_measurements,
)
from passmd.protocols.fit.measurements import MODELS as MODELS
from passmd.protocols.fit.measurements import READINGS as READINGS
from passmd.protocols.fit.prediction import predict, predict_point
from passmd.protocols.fit.problem import GN_STEP_LIMIT, JACOBIAN_STEPS, LOCAL_EVALUATIONS
from passmd.protocols.fit.profiles import (
    BOTTOM_DROP,
    BOTTOM_FIRST,
    BOTTOM_RESOLUTION,
    BOTTOM_STEPS,
    FILL_BATCH,
    FILL_SAFETY,
    FINE_SPACING,
    PROFILE_MIN_POINTS,
    PROFILE_SPACING,
)
from passmd.protocols.fit.regions import BASIN_PROMINENCE
from passmd.protocols.fit.result import (
    CORRELATION_LIMIT,
    REJECT_P,
    FitResult,
    fitted_drive_file,
    goodness_of_fit,
)
from passmd.runtime.validation import InputError as InputError

__all__ = [
    "BOTTOM_DROP",
    "BOTTOM_FIRST",
    "BOTTOM_RESOLUTION",
    "BOTTOM_STEPS",
    "BASIN_PROMINENCE",
    "CONDITIONS",
    "CORRELATION_LIMIT",
    "DISTINCT",
    "FILL_BATCH",
    "FILL_SAFETY",
    "FINE_SPACING",
    "FREE_PARAMETERS",
    "GLOBAL_POINTS_PER_PARAMETER",
    "GN_STEP_LIMIT",
    "JACOBIAN_STEPS",
    "KEEPS",
    "LOCAL_EVALUATIONS",
    "LOCAL_STARTS",
    "LOSSES",
    "MAX_BASINS",
    "MEASURED",
    "PROFILE_MIN_POINTS",
    "PROFILE_SPACING",
    "REFITS",
    "REFIT_MARGIN",
    "REJECT_P",
    "FitResult",
    "FreeParameter",
    "Measurements",
    "MeasurementError",
    "check_rows",
    "default_bounds",
    "fit",
    "fitted_drive_file",
    "goodness_of_fit",
    "measurements_from_rows",
    "predict",
    "predict_point",
    "read_measurements",
    "write_measurements",
]
