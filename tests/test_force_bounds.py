"""Every force the stall protocol reports respects the Coulomb bound μΣF_N (Section 4.2, Eq. 1).

Over one period m_r Δv = T (F̄_fric − k·x̄_r) and each contact's friction is at most μF_N, so a
stall (periodic, Δv = 0) has k·x̄_r = F̄_fric ≤ μΣF_N: the stall force, and the force any
credible extrapolation leads to, stay within μΣF_N. Results are compared with μΣF_N plus the
integrator's accuracy (:func:`passmd.protocols.stall.bound_margin`, k times the 0.05 nm of
``passmd.solver.steps.CONVERGED_ACCURACY``): that is the only slack a computed result has.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys

import numpy as np
import pytest

from passmd.model.parameters import paper_drive
from passmd.model.tables import PRELOAD_GRIDS
from passmd.protocols import stall

#: The sweep: one preload per decade over four decades, one stiffness per decade over three.
PRELOADS = (1e-3, 1e-2, 1e-1, 1.0, 10.0)
STIFFNESSES = (2.5e2, 2.5e3, 2.5e4, 2.5e5)
MODELS = (("rigid", 0.3), ("flexible", 0.2))
#: First check and longest run of a sweep point (periods): short, so that the sweep also holds
#: runs cut short, whose extrapolations must be withheld or within the bound.
SWEEP_PERIODS = (17, 64)


def _drive(preload, model="flexible", mu=0.2, stiffness=2.5e4):
    return paper_drive(1e-3, preload, actuator_model=model, friction_coefficient=mu, load_cell=True,
                       load_cell_stiffness=stiffness, allow_extrapolation=True)


def _force(drive, initial_periods, max_periods):
    return stall.generated_force(drive, drive.actuator.full_stroke_amplitude, 100.0,
                                 initial_periods=initial_periods, max_periods=max_periods)


def _assert_within_bound(out, drive):
    """The invariants of a result: stall force, mean friction and extrapolation within μΣF_N."""
    limit, margin = stall.coulomb_bound(drive), stall.bound_margin(drive)
    force = abs(out["generated_force_N"])
    assert out["coulomb_bound_N"] == limit
    assert abs(out["mean_friction_N"]) <= limit + margin
    if out["converged"]:
        assert force <= limit + margin, "stall force above the Coulomb bound"
    if out["remaining_force_N"] is None:
        assert out["remaining_force_note"], "a withheld extrapolation says why"
    else:
        assert out["remaining_force_note"] is None
        assert force + out["remaining_force_N"] <= limit + margin, "extrapolation above the Coulomb bound"
    # A load-cell mean above the bound is only ever the runner's swing in a run that has not stalled,
    # with nothing extrapolated from it.
    assert force <= limit + margin or (not out["converged"] and out["remaining_force_N"] is None)


# --------------------------------------------------------------------------------------
# The sweep
# --------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def sweep():
    points = {}
    for model, mu in MODELS:
        for preload in PRELOADS:
            for k in STIFFNESSES:
                drive = _drive(preload, model, mu, k)
                points[(model, preload, k)] = (drive, _force(drive, *SWEEP_PERIODS))
    return points


def test_bound_holds_over_four_decades_of_preload_and_three_of_stiffness(sweep):
    """Full stroke, 1 mN … 10 N × k = 250 … 2.5·10⁵ N/m, rigid and flexible actuators.

    Why one point per decade suffices: what decides whether the bound binds is the runner's
    travel to it, x* = μΣF_N/k, against the stroke A = 202 nm and the contacts' presliding
    u* (0.4 nm at 1 mN, ~170 nm at 10 N). Over the grid x*/A runs from 10⁻² (1 mN, stiff
    cell: the bound is reached within a period and the stall force sits within 1 % of it,
    where a criterion stopping on the swing would pass it) through 1 … 100 (reached within
    the run, or cut short while still rising: extrapolations must be withheld) to 10⁵ (10 N,
    soft cell, and A below the critical amplitude: no steps). Each regime holds several
    grid points with both actuator models; the runs (≤ 64 periods, exact contact) take a few
    seconds in all. The assertions cover what no correct result can break; the counts make
    sure each regime is really in the sweep.
    """
    near_bound = withheld = extrapolated = 0
    for drive, out in sweep.values():
        _assert_within_bound(out, drive)
        ratio = out["generated_force_N"] / out["coulomb_bound_N"]
        near_bound += out["converged"] and ratio > 0.99
        withheld += out["remaining_force_N"] is None
        extrapolated += (not out["converged"]) and out["remaining_force_N"] is not None
    assert near_bound >= 8 and withheld >= 8 and extrapolated >= 2, (near_bound, withheld, extrapolated)


def test_tiny_preload_stalls_below_the_bound_with_both_models(sweep):
    """At 1 mN (μΣF_N = 0.85 mN rigid with μ = 0.3, 0.57 mN flexible with μ = 0.2) the drive stalls
    within 1 % under the bound, a little below it as mean friction at stall must be."""
    for model, _ in MODELS:
        drive, out = sweep[(model, 1e-3, 2.5e4)]
        assert out["converged"]
        assert 0.99 * out["coulomb_bound_N"] < out["generated_force_N"] <= out["coulomb_bound_N"]


def test_paper_preloads_keep_the_absolute_tolerance():
    """At the paper's preloads (both radii, μ = 0.2 and 0.3) the Coulomb-scaled tolerance is above the
    absolute 0.2 mN, so the criterion — and every Fig. 7 result — is the one the snapshots lock."""
    for radius, preloads in PRELOAD_GRIDS.items():
        for preload in preloads:
            for mu in (0.2, 0.3):
                drive = paper_drive(radius, float(preload), friction_coefficient=mu, load_cell=True)
                assert stall.STALL_BOUND_FRACTION * stall.coulomb_bound(drive) > stall.STALL_ABS_TOLERANCE


def test_a_run_cut_short_in_the_swing_is_not_a_stall():
    """1 mN, 17 periods: the runner reached the bound in the first periods and swings on the load cell.

    The absolute 0.2 mN tolerance (a third of μΣF_N here) took the swing for a stall at
    5.684e-4 N, above μΣF_N = 5.657e-4 N; the Coulomb-scaled one (2.8 µN) does not.
    """
    drive = _drive(1e-3)
    out = _force(drive, 17, 17)
    assert not out["converged"]
    assert out["generated_force_N"] > out["coulomb_bound_N"] + stall.bound_margin(drive)  # the swing
    assert out["mean_friction_N"] <= out["coulomb_bound_N"]
    assert out["remaining_force_N"] is None and "rises and falls" in out["remaining_force_note"]
    _assert_within_bound(out, drive)


# --------------------------------------------------------------------------------------
# The checks fail on counter-examples
# --------------------------------------------------------------------------------------


def _fabricated(drive, force_fraction, *, converged=True, friction_fraction=None, remaining=None):
    limit = stall.coulomb_bound(drive)
    return {"generated_force_N": force_fraction * limit, "converged": converged,
            "mean_friction_N": (force_fraction if friction_fraction is None else friction_fraction) * limit,
            "remaining_force_N": remaining, "remaining_force_note": None if remaining is not None else "why"}


def test_check_refuses_a_stall_force_above_the_bound():
    drive = _drive(0.4)
    stall.check_force_bounds(_fabricated(drive, 0.999), drive)  # below: passes
    margin = stall.bound_margin(drive) / stall.coulomb_bound(drive)
    stall.check_force_bounds(_fabricated(drive, 1 + 0.5 * margin), drive)  # within the accuracy
    with pytest.raises(stall.ForceBoundError, match="stall force .* exceeds the Coulomb bound"):
        stall.check_force_bounds(_fabricated(drive, 1.005, friction_fraction=0.99), drive)
    with pytest.raises(ValueError, match="found = .* is not a result of generated_force"):
        stall.check_force_bounds({"generated_force_N": 0.1}, drive)


def test_check_refuses_friction_and_extrapolations_above_the_bound():
    drive = _drive(0.4)
    limit = stall.coulomb_bound(drive)
    with pytest.raises(stall.ForceBoundError, match="mean friction"):
        stall.check_force_bounds(_fabricated(drive, 0.5, converged=False, friction_fraction=1.01), drive)
    with pytest.raises(stall.ForceBoundError, match="still to come"):
        stall.check_force_bounds(_fabricated(drive, 0.3, converged=False, remaining=2.09 * limit), drive)
    stall.check_force_bounds(_fabricated(drive, 0.3, converged=False, remaining=0.69 * limit), drive)
    # the runner's swing: a load-cell mean above the bound, not stalled, nothing extrapolated
    stall.check_force_bounds(_fabricated(drive, 1.005, converged=False, friction_fraction=0.998), drive)


def test_the_stall_criterion_refuses_a_flat_force_above_the_bound():
    flat = np.full(40, 1.01)  # in units of μΣF_N: flat, so tail and spread are zero
    estimate = stall.stall_estimate(flat)
    assert stall._stalled(estimate, 1.01, 0.2e-3, 2e-3)  # without the ceiling it would pass
    assert not stall._stalled(estimate, 1.01, 0.2e-3, 2e-3, ceiling=1.0)


@pytest.mark.parametrize(
    "series, converged, reason",
    [
        (0.2 + 1.0 * (1 - 0.97 ** np.arange(60)), False, "Coulomb bound"),  # heads for 1.2 μΣF_N
        (0.1 * np.arange(30), False, "undiminished"),  # linear rise
        # a damped swing of 16 periods: D₂/D₁ < 0
        (0.5 + 0.01 * 0.95 ** np.arange(60) * np.cos(np.pi * np.arange(60) / 8), False, "swings"),
        # a geometric approach (D₂/D₁ = 0.43) under a period-to-period zigzag
        (0.5 * (1 - 0.9 ** np.arange(60)) + 5e-4 * np.cos(np.pi * np.arange(60)), False, "rises and falls"),
        (0.5 * np.ones(10), True, "too few"),
    ],
    ids=["beyond-bound", "linear", "swing", "erratic", "too-few"],
)
def test_an_extrapolation_that_is_not_credible_is_withheld(series, converged, reason):
    """Series in units of μΣF_N (limit 1, margin 0); the reason is one line."""
    remaining, note = stall.credible_tail(series, stall.stall_estimate(series), converged, 1.0, 0.0)
    assert remaining is None and reason in note and "\n" not in note


def test_a_geometric_approach_below_the_bound_is_extrapolated_exactly():
    series = 0.8 * (1 - 0.97 ** np.arange(60))  # F∞ = 0.8 μΣF_N
    remaining, note = stall.credible_tail(series, stall.stall_estimate(series), False, 1.0, 0.0)
    assert note is None and remaining == pytest.approx(0.8 - series[-1], rel=1e-9)


# --------------------------------------------------------------------------------------
# The command line: the cases that once printed impossible forces (subprocesses)
# --------------------------------------------------------------------------------------


def _passmd(*argv):
    env = {**os.environ, "MPLBACKEND": "Agg"}
    return subprocess.run([sys.executable, "-m", "passmd", *argv], capture_output=True, text=True, env=env,
                          timeout=300)


def _text_force(text, label):
    """The first number (N) on the row ``label`` of the text output."""
    row = next(line for line in text.splitlines() if line.strip().startswith(label))
    return float(re.search(r"([-+0-9.e]+) N", row[len(label) + 2:]).group(1))


@pytest.mark.parametrize("as_json", [False, True], ids=["text", "json"])
def test_cli_tiny_preload_cut_short_is_not_reported_stalled(as_json):
    """`force --periods 17 --max-periods 17 --preload 1mN` printed "stalled" at 5.684e-4 N > μΣF_N."""
    done = _passmd("force", "--periods", "17", "--max-periods", "17", "--preload", "1mN",
                   *(["--json"] if as_json else []))
    assert done.returncode == 0, done.stderr
    if as_json:
        data = json.loads(done.stdout)
        assert data["converged"] is False and data["remaining_force_N"] is None
        assert data["generated_force_N"] is None and "transient" in data["generated_force_note"]
        assert data["coulomb_bound_N"] >= data["mean_friction_N"]
    else:
        assert "(stalled)" not in done.stdout and "NOT stalled after 17 periods" in done.stdout
        assert "not determined" in done.stdout and "a transient, not a stall force" in done.stdout
        bound = _text_force(done.stdout, "Coulomb bound μΣF_N")
        # the title and the drive rows name the preload, an input, not a reported force
        rows = "\n".join(line for line in done.stdout.splitlines()[1:]
                         if not line.lstrip().startswith(("drive ", "actuators ")))
        printed = [float(x) for x in re.findall(r"([-+]?[0-9.]+(?:e[-+]?[0-9]+)?) N(?!/)\b", rows)]
        assert printed and max(printed) <= bound, "a force above μΣF_N was printed"
        assert "still to come not estimated" in done.stdout and "still to come ≈" not in done.stdout


@pytest.mark.parametrize("as_json", [False, True], ids=["text", "json"])
def test_cli_tiny_preload_stalls_within_the_bound(as_json):
    done = _passmd("force", "--preload", "1mN", *(["--json"] if as_json else []))
    assert done.returncode == 0, done.stderr
    if as_json:
        data = json.loads(done.stdout)
        force, bound = data["generated_force_N"], data["coulomb_bound_N"]
        remaining = data["remaining_force_N"]
        assert data["converged"] is True
    else:
        assert "(stalled)" in done.stdout
        force = _text_force(done.stdout, "generated force k·x̄_r")
        bound = _text_force(done.stdout, "Coulomb bound μΣF_N")
        remaining = float(re.search(r"still to come ≈ ([-+0-9.e]+) N", done.stdout).group(1))
    assert 0.99 * bound < force <= bound and force + remaining <= bound * (1 + 1e-5)  # text: 6 digits


@pytest.mark.parametrize("stiffness", ["25000", "250"])
@pytest.mark.parametrize("as_json", [False, True], ids=["text", "json"])
def test_cli_cut_short_extrapolation_is_withheld(as_json, stiffness):
    """`force --actuator rigid --periods 17 --max-periods 17` printed "still to come ≈ 0.47 N"
    (0.38 N with `--load-cell-stiffness 250`) although μΣF_N = 0.226 N."""
    done = _passmd("force", "--actuator", "rigid", "--periods", "17", "--max-periods", "17",
                   "--load-cell-stiffness", stiffness, *(["--json"] if as_json else []))
    assert done.returncode == 0, done.stderr
    if as_json:
        data = json.loads(done.stdout)
        assert data["converged"] is False and data["remaining_force_N"] is None
        assert "Coulomb bound" in data["remaining_force_note"]
        assert data["generated_force_N"] < data["coulomb_bound_N"]
    else:
        assert "NOT stalled after 17 periods" in done.stdout and "still to come ≈" not in done.stdout
        assert re.search(r"still to come not estimated: .*Coulomb bound", done.stdout)
        force = _text_force(done.stdout, "generated force k·x̄_r")
        assert force < _text_force(done.stdout, "Coulomb bound μΣF_N")


# the old absolute criterion put back: it stops on the 1 mN swing; the bound check must refuse that
_OLD_CRITERION = """
import sys
from passmd import cli
from passmd.protocols import stall
criterion = stall._stalled
def absolute(estimate, force, abs_tol, rel_tol, ceiling=None):  # 0.2 mN, no ceiling
    return criterion(estimate, force, 2e-4, rel_tol)
stall._stalled = absolute
sys.exit(cli.main(sys.argv[1:]))
"""


@pytest.mark.parametrize("as_json", [False, True], ids=["text", "json"])
def test_cli_stall_force_above_the_bound_is_a_one_line_error(as_json):
    env = {**os.environ, "MPLBACKEND": "Agg"}
    argv = ["force", "--periods", "17", "--max-periods", "17", "--preload", "1mN"]
    argv += ["--json"] if as_json else []
    done = subprocess.run([sys.executable, "-c", _OLD_CRITERION, *argv],
                          capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 1 and done.stdout == ""
    assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr
    assert "stall force 0.000568442 N exceeds the Coulomb bound" in done.stderr
