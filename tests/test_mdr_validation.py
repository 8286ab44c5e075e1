"""Data of the "MDR validation" chapter: physics checks and regression snapshots.

Snapshots (pytest-regressions, tests/test_mdr_validation/) lock the figure data. The data
are deterministic; the tolerances only absorb last-digit differences of libm and NumPy
between machines:
* displacements: rtol 1e-9 (they are linspace multiples of u_max, no accumulation);
* forces: rtol 1e-7 with atol 1e-13 N (2e-12 of μF_N ≈ 0.057 N, for values near zero);
* relative errors: rtol 1e-5 with atol 1e-12 — they are differences of nearly equal forces,
  so rounding of 1e-16 in each force shows up as up to ~1e-8 of the smallest error (5e-8).
"""

import numpy as np
import pytest

from passmd.experiments.mdr_validation import figures
from passmd.model import theory
from passmd.model.parameters import Drive

ROUND = 1e-12  # identities that hold to rounding (exact model vs closed forms)
DISCRETE = 5e-3  # MDR chapter's acceptance bound: discrete within 0.5 % of μF_N for N >= 1000

DRIVE = Drive()
F_N = float(theory.normal_forces(DRIVE.preload, DRIVE.contacts)[0])
F_S = DRIVE.friction_coefficient * F_N

FORCE_TOL = {"rtol": 1e-7, "atol": 1e-13}
LENGTH_TOL = {"rtol": 1e-9, "atol": 1e-22}
ERROR_TOL = {"rtol": 1e-5, "atol": 1e-12}


def tolerances(df):
    tol = {}
    for col in df.columns:
        if col.endswith("_N"):
            tol[col] = FORCE_TOL
        elif col.endswith("_m"):
            tol[col] = LENGTH_TOL
        else:
            tol[col] = ERROR_TOL
    return tol


def test_spring_picture(dataframe_regression):
    df = figures.spring_picture()
    assert df["normal_force_N"].sum() == pytest.approx(F_N, rel=ROUND)
    # tangential spring forces never exceed μ times their normal force (Eq. 6 stick condition)
    limit = DRIVE.friction_coefficient * df["normal_force_N"] * (1 + ROUND)
    assert np.all(np.abs(df["tangential_force_N"]) <= limit)
    # the centre sticks, the rim slips back (unloading from 0.8 to 0.3 u_max)
    centre = np.abs(df["position_m"]) < 0.3 * df["position_m"].abs().max()
    assert not df.loc[centre, "slipping"].any()
    assert df["slipping"].iloc[0] and df["slipping"].iloc[-1]
    assert (df.loc[df["slipping"], "tangential_force_N"] < 0).all()  # slipping back
    out = df.assign(slipping=df["slipping"].astype(int))
    dataframe_regression.check(out, default_tolerance=ERROR_TOL, tolerances=tolerances(out))


def test_normal_validation(dataframe_regression):
    df = figures.normal_validation()
    # the grid's rim is at the Hertz radius of 2 F_N1: there d_max gives exactly the midpoint-rule
    # error of the parabola's integral, 1/(2 N^2)
    for n in (20, 100, 1000):
        assert df[f"rel_error_{n}"].iloc[-1] == pytest.approx(0.5 / n**2, rel=1e-6)
    assert df["rel_error_1000"].abs().max() < 1e-4
    dataframe_regression.check(df, tolerances=tolerances(df))


def test_virgin_validation(dataframe_regression):
    df = figures.virgin_validation()
    np.testing.assert_allclose(df["exact_N"], df["cattaneo_mindlin_N"], rtol=0, atol=ROUND * F_S)
    np.testing.assert_allclose(df["discrete_1000_N"], df["cattaneo_mindlin_N"], rtol=0, atol=DISCRETE * F_S)
    assert df["slip_share_exact"].iloc[0] == 0.0 and df["slip_share_exact"].iloc[-1] == 1.0
    dataframe_regression.check(df, tolerances=tolerances(df))


def test_hysteresis_validation(dataframe_regression):
    df = figures.hysteresis_validation()
    np.testing.assert_allclose(df["exact_N"], df["masing_N"], rtol=0, atol=ROUND * F_S)
    np.testing.assert_allclose(df["discrete_1000_N"], df["masing_N"], rtol=0, atol=DISCRETE * F_S)
    # both loops close: back at A the force is the virgin value at A again; at B after C too
    ends = df.groupby("segment")["masing_N"].last()
    assert ends[5] == pytest.approx(ends[0], rel=ROUND)
    assert ends[4] == pytest.approx(ends[2], rel=ROUND)
    dataframe_regression.check(df, tolerances=tolerances(df))


def test_hysteresis_path_rejects_a_minor_loop_outside_the_major_one():
    with pytest.raises(ValueError, match="minor loop"):
        figures.hysteresis_path(amplitude=0.5, minor_top=0.6)


def test_convergence(dataframe_regression):
    df = figures.convergence_validation()
    assert (df["max_error_rel"].diff().dropna() < 0).all()  # monotone in N
    assert df.loc[df["springs"] >= 1000, "max_error_rel"].max() < DISCRETE
    # N^-2 is the midpoint rule's order; the stick/slip kinks could lower it, the fit shows they
    # do not. ±0.2 covers the scatter of a log-log fit over 7 points.
    assert figures.fitted_order(df) == pytest.approx(2.0, abs=0.2)
    dataframe_regression.check(df, tolerances=tolerances(df))
