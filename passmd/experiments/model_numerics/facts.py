"""Facts the numerics chapter quotes (glue names → numbers), the integrator's stated accuracies and the
stored speed benchmarks.

Small functions of the tidy tables of :mod:`passmd.experiments.model_numerics.figures` (convergence,
energy balance, settle windows, rigid Coulomb limit) and of the stored speed benchmark
(:func:`benchmark_table`): the integrator's step plan per configuration, fitted convergence orders and
error floors, energy residuals, Coulomb-limit gaps and rates, and the speed numbers against their
targets. Display units: nm, µs, ns, ms, %.

The accuracies the default integrator guarantees for what the figures report (``*_ACCURACY``,
``*_RTOL``) are checked by running the quick figure data again with the step halved (error-controlled
tolerance ÷ 16): every reported value moves by well under its stated accuracy, so any integrator at
least as accurate reproduces the figures within them. The regression snapshots compare with them
(``tests/snapshot_accuracy.py``), the claims and the chapters quote them.

The benchmark scripts' stored results (``benchmarks/bench_<name>.py``, written to the package data
``passmd/data/benchmarks/<name>.json``) are read by :func:`benchmark_results`; speed is measured by
those scripts, never by the tests.
"""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd

from passmd.experiments.model_numerics.figures import CONFIGURATIONS, EXPECTED_COULOMB_RATE, MASS_FLYBACKS
from passmd.model import theory
from passmd.model.parameters import Drive
from passmd.protocols import stall
from passmd.runtime.inputs import read_text
from passmd.runtime.units import from_si
from passmd.runtime.validation import check_choice
from passmd.solver import steps
from passmd.solver.setup import contact_groups

#: Positions, steps and back-steps (m): :data:`passmd.solver.steps.CONVERGED_ACCURACY`, the
#: settled position's distance from a much finer run. Halving the step moved no quick step,
#: back-step or settled position (Figs. 5a, 7–10) by more than 0.012 nm.
POSITION_ACCURACY = steps.CONVERGED_ACCURACY
#: Stall forces (N): the stall criterion's absolute tolerance
#: (:data:`passmd.protocols.stall.STALL_ABS_TOLERANCE`) — a finer run may stop a few periods
#: earlier or later, anywhere within it — plus :data:`STALL_FORCE_RTOL` of the force. The
#: integrator's own share, k_l·POSITION_ACCURACY ≈ 1 µN, is far below; halving the step moved
#: no quick force of Fig. 7 by more than 0.018 mN.
FORCE_ACCURACY = stall.STALL_ABS_TOLERANCE
#: Relative part of the stall-force accuracy (:data:`passmd.protocols.stall.STALL_REL_TOLERANCE`).
STALL_FORCE_RTOL = stall.STALL_REL_TOLERANCE
#: Steady velocities (m/s): a step per period accurate to POSITION_ACCURACY at the fastest
#: step frequency of Figs. 9b–10 (130 kHz), 6.5 µm/s. Halving the step moved none by more
#: than 1.4 µm/s.
VELOCITY_ACCURACY = POSITION_ACCURACY * 130e3
#: Micro-vibration frequencies and times (Eq. 15's t_s, t_a; turning points; the stall cycle's
#: full-slip time), relative: read off the recorded samples, so quantised to the record
#: spacing, which follows the step. Halving the step moved f_s and Eq. 15's times by at most
#: 3.2e-6 and the full-slip time by one record spacing, 1.5e-4; 1e-3 leaves a factor 6.
FREQUENCY_RTOL = 1e-3
#: Slip shares (fraction of a contact's radius sliding): they change fastest at the turning
#: points where Fig. 8 reads them, by up to 0.006 when the step was halved (their means and
#: maxima over a phase by 0.0004); 0.02 leaves a factor 3.
SLIP_SHARE_ACCURACY = 0.02
#: Critical amplitudes and force onsets, in final bracket widths of their search (its
#: ``tolerance``) plus POSITION_ACCURACY: the integrator's error can flip a bisection decision
#: only at an amplitude within that error of the switch, which moves the reported midpoint by
#: one width. Halving the step changed no quick critical amplitude or onset (Figs. 5–7).
CRITICAL_AMPLITUDE_BRACKETS = 1.0

#: Benchmark results shipped with the package (``passmd/data/benchmarks/<name>.json``).
BENCHMARKS = ("before_after", "book", "contact", "driving_waveform", "dynamics", "fit", "fit_coverage",
              "ledger", "scaling", "settling", "sweep_map")


def benchmark_results(name: str, path: str | Path | None = None) -> dict:
    """One benchmark script's last results (``benchmarks/bench_<name>.py``), as stored.

    Parameters
    ----------
    name : str
        One of :data:`BENCHMARKS`: ``benchmarks/bench_<name>.py``'s record.
    path : path-like, optional
        A results file to read instead of the one installed with the package
        (``passmd/data/benchmarks/<name>.json``, package data, which the benchmark
        scripts write by default when run from the repository).

    Returns
    -------
    dict
        As the script wrote it (``{"meta": {...}, "rows": [...]}`` for the speed benchmarks).
    """
    check_choice("name", name, BENCHMARKS)
    if path is None:
        resource = resources.files("passmd") / "data" / "benchmarks" / f"{name}.json"
        if not resource.is_file():
            raise FileNotFoundError(
                f"{resource} is missing: run `python benchmarks/bench_{name}.py` in the repository"
            )
        return json.loads(read_text(Path(str(resource)), "benchmark record"))
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"{path} is missing: run `python benchmarks/bench_{name}.py --out {path}`")
    return json.loads(read_text(path, "benchmark record"))


def benchmark_table(path: str | Path | None = None) -> pd.DataFrame:
    """The speed benchmark's last results (``benchmarks/bench_dynamics.py``), as a table.

    Reads :func:`benchmark_results` ``("dynamics", path)``; ``df.attrs["meta"]`` holds the
    machine and settings it was measured with, ``df.attrs["across_processes"]`` the headline
    configuration timed in several fresh processes (empty if the file predates it).
    """
    data = benchmark_results("dynamics", path)
    df = pd.DataFrame(data["rows"])
    df.attrs["meta"] = data.get("meta", {})
    df.attrs["across_processes"] = data.get("across_processes", {})
    df.attrs["headline"] = data.get("headline", {})
    return df



def step_plan_table() -> pd.DataFrame:
    """The integrator's steps (:func:`passmd.solver.steps.step_plan`) for each of
    :data:`~passmd.experiments.model_numerics.figures.CONFIGURATIONS`.

    Columns: ``configuration``, stiffest mode (kHz), stability limit 2/ω, fine and coarse step and
    the longest error-controlled step (ns; :data:`passmd.solver.steps.LONGEST_OMEGA_DT` over the
    runner mode's ω, whatever the local error allows).
    """
    rows = []
    for label, contacts, model in CONFIGURATIONS:
        drive = Drive(contacts=contacts, actuator_model=model)
        k_max = theory.drive_theory(drive)["tangential_stiffness_N_per_m"]
        _, mult = contact_groups(drive)
        plan = steps.step_plan(drive, max(k_max), float(np.dot(mult, k_max)))
        rows.append({
            "configuration": label,
            "stiffest mode (kHz)": from_si(plan.stiffest_frequency, "kHz"),
            "stability limit 2/ω (ns)": from_si(plan.stability_limit, "ns"),
            "fine step (ns)": from_si(plan.fine_step, "ns"),
            "coarse step (ns)": from_si(plan.coarse_step, "ns"),
            "longest controlled step (ns)": from_si(plan.longest_step, "ns"),
        })
    return pd.DataFrame(rows)


def fitted_convergence_order(rows: pd.DataFrame) -> float:
    """Order p of |error| ∝ h^p: least-squares slope over the runs at the default step or finer."""
    fit = rows[(rows["error_m"] != 0) & (rows["resolution"] >= 1.0)]
    return float(-np.polyfit(np.log(fit["resolution"]), np.log(np.abs(fit["error_m"])), 1)[0])


#: A run of the error-controlled scheme enters its fitted order only if its error exceeds this
#: multiple of the scheme's floor (the largest error of its finest runs, where it no longer
#: approaches the reference): within it, the floor and not the step sets the error. At 3 the floor
#: is at most a third of any error that enters the fit.
FLOOR_FACTOR = 3.0
#: Coarsest resolution in the error-controlled scheme's fitted order. Coarser, the tolerance
#: (resolution⁻⁴ times the default) lets many steps reach the longest step
#: (:data:`passmd.solver.steps.LONGEST_OMEGA_DT` over ω), which it then no longer sets: at 0.25 the
#: runs change when that bound is raised, at 0.5 and finer they hardly do.
CONTROLLED_FIT_COARSEST = 0.5


def fitted_order_above_floor(rows: pd.DataFrame, factor: float = FLOOR_FACTOR,
                             coarsest: float = CONTROLLED_FIT_COARSEST) -> tuple[float, float]:
    """Order p of |error| ∝ h^p of one step control, fitted above its error floor.

    The floor is the largest |error| of the control's finest runs (all configurations); the
    least-squares slope is taken over the runs at ``coarsest`` resolution or finer whose |error|
    exceeds ``factor`` times the floor. Returns (p, floor in m).

    Raises
    ------
    ValueError
        Fewer than two resolutions above the floor: coarser runs are needed to fit an order.
    """
    finest = rows[rows["resolution"] == rows["resolution"].max()]
    floor = float(np.abs(finest["error_m"]).max())
    fit = rows[(np.abs(rows["error_m"]) > factor * floor) & (rows["resolution"] >= coarsest)]
    if fit["resolution"].nunique() < 2:
        raise ValueError(f"only {fit['resolution'].nunique()} resolution(s) with an error above {factor:g} "
                         f"times the floor of {floor:.3g} m: run coarser resolutions to fit an order")
    order = -np.polyfit(np.log(fit["resolution"]), np.log(np.abs(fit["error_m"])), 1)[0]
    return float(order), floor


def convergence_facts(conv: pd.DataFrame) -> dict:
    """Numbers the convergence paragraphs quote
    (:func:`~passmd.experiments.model_numerics.figures.model_convergence`).

    Explicit schemes (adaptive and fixed): ``conv_order`` and ``conv_max_err_nm``, their order
    and largest error at the default step (nm); ``adaptive_vs_fixed_nm``, their largest
    difference (flexible); ``adaptive_saving``, fixed over adaptive steps. Quasi-static step:
    ``quasi_order``, ``quasi_max_err_nm`` and ``quasi_saving`` (adaptive over its steps).
    Error-controlled scheme: ``ctrl_order`` and ``ctrl_floor_nm`` (:func:`fitted_order_above_floor`),
    ``ctrl_floor_rigid_nm`` and ``ctrl_floor_flexible_nm`` (the largest error of its finest runs
    with rigid and with flexible actuators), ``ctrl_max_err_nm`` (its largest error at the
    default tolerance), ``ctrl_rejected_pct`` (the largest share of its steps rejected there,
    %), ``ctrl_saving_adaptive`` and ``ctrl_saving_fixed`` (explicit adaptive and fixed steps
    over its own, six contacts, flexible) and ``ctrl_saving_rigid`` (fixed over its own, six
    contacts, rigid). Savings are at the default step, for six flexible contacts unless said.
    """
    explicit = conv[conv["step_control"].isin(("adaptive", "fixed"))]
    default = explicit[explicit["resolution"] == 1.0]
    quasi = conv[conv["step_control"] == "quasi-static"]
    controlled = conv[conv["step_control"] == "controlled"]
    ctrl_default = controlled[controlled["resolution"] == 1.0]
    ctrl_order, ctrl_floor = fitted_order_above_floor(controlled)
    ctrl_finest = controlled[controlled["resolution"] == controlled["resolution"].max()]
    ctrl_flexible = ctrl_finest["configuration"].str.contains("flexible")
    adaptive = conv[conv["step_control"] == "adaptive"]
    adaptive = adaptive.set_index(["configuration", "resolution"])["final_position_m"]
    fixed = conv[(conv["step_control"] == "fixed") & conv["configuration"].str.contains("flexible")]
    fixed = fixed.set_index(["configuration", "resolution"])["final_position_m"]
    counts = conv[conv["resolution"] == 1.0].set_index(["configuration", "step_control"])["steps"]
    six, six_rigid = "six contacts, flexible", "six contacts, rigid"
    return {
        "conv_order": fitted_convergence_order(explicit),
        "quasi_order": fitted_convergence_order(quasi),
        "quasi_max_err_nm": float(np.abs(quasi[quasi["resolution"] == 1.0]["error_m"]).max() * 1e9),
        "conv_max_err_nm": float(np.abs(default["error_m"]).max() * 1e9),
        "adaptive_vs_fixed_nm": float(np.abs(adaptive.reindex(fixed.index) - fixed).max() * 1e9),
        "adaptive_saving": float(counts[(six, "fixed")] / counts[(six, "adaptive")]),
        "quasi_saving": float(counts[(six, "adaptive")] / counts[(six, "quasi-static")]),
        "ctrl_order": ctrl_order,
        "ctrl_floor_nm": ctrl_floor * 1e9,
        "ctrl_floor_rigid_nm": float(np.abs(ctrl_finest[~ctrl_flexible]["error_m"]).max() * 1e9),
        "ctrl_floor_flexible_nm": float(np.abs(ctrl_finest[ctrl_flexible]["error_m"]).max() * 1e9),
        "ctrl_max_err_nm": float(np.abs(ctrl_default["error_m"]).max() * 1e9),
        "ctrl_rejected_pct": float((ctrl_default["rejected_steps"] / ctrl_default["steps"]).max() * 100),
        "ctrl_saving_adaptive": float(counts[(six, "adaptive")] / counts[(six, "controlled")]),
        "ctrl_saving_fixed": float(counts[(six, "fixed")] / counts[(six, "controlled")]),
        "ctrl_saving_rigid": float(counts[(six_rigid, "fixed")] / counts[(six_rigid, "controlled")]),
    }


def energy_facts(energy: pd.DataFrame, explicit: pd.DataFrame) -> dict:
    """Numbers of the energy-balance paragraph, from two
    :func:`~passmd.experiments.model_numerics.figures.energy_balance_table` runs.

    ``energy`` is the default (error-controlled) scheme, ``explicit`` the same runs with
    ``scheme="adaptive"``. Returns the largest |relative residual| of ``energy``
    (``energy_max_rel``; ``energy_exact_max_rel`` and ``energy_discrete_max_rel`` per contact
    model) and of ``explicit`` (``energy_explicit_max_rel``), their ratio
    (``energy_tighter``: explicit over default), and the smallest and largest factor by which
    a default run's residual exceeds the explicit scheme's on the same run
    (``energy_ratio_min``, ``energy_ratio_max``).
    """
    keys = ["configuration", "contact_model"]
    if not energy[keys].reset_index(drop=True).equals(explicit[keys].reset_index(drop=True)):
        raise ValueError("explicit must list the same runs as energy, in the same order")
    default = energy["relative_residual"].abs().to_numpy()
    other = explicit["relative_residual"].abs().to_numpy()
    ratio = default / other
    exact = (energy["contact_model"] == "exact").to_numpy()
    return {"energy_max_rel": float(default.max()),
            "energy_exact_max_rel": float(default[exact].max()),
            "energy_discrete_max_rel": float(default[~exact].max()),
            "energy_explicit_max_rel": float(other.max()),
            "energy_tighter": float(other.max() / default.max()),
            "energy_ratio_min": float(ratio.min()), "energy_ratio_max": float(ratio.max())}


def settle_facts(sens: pd.DataFrame) -> dict:
    """Largest spread of the mean step over the settle windows: nm and % of the mean
    (:func:`~passmd.experiments.model_numerics.figures.settle_fraction_sensitivity`)."""
    spread = sens.groupby("configuration")["mean_step_m"].agg(lambda v: v.max() - v.min())
    mean = sens.groupby("configuration")["mean_step_m"].mean()
    return {"settle_spread_nm": float(spread.max() * 1e9),
            "settle_spread_rel": float((spread / mean).max() * 100)}


def coulomb_facts(coulomb: pd.DataFrame, refined: pd.DataFrame) -> dict:
    """Numbers the Coulomb-limit paragraph quotes, from
    :func:`~passmd.experiments.model_numerics.figures.model_coulomb_limit` and the same run at half the
    time step (``refined``): gaps (nm, % of A_c), fly-back times (µs), rates."""
    k = np.array(sorted(coulomb["scale"].unique()))
    by = coulomb.set_index(["configuration", "scale"])
    paper, slow = "six contacts, paper slew rate fly-back", "six contacts, slow fly-back"
    change = np.abs(refined["difference_m"] - coulomb["difference_m"])
    slow_tf = coulomb[coulomb["flyback"] == "slow"]["flyback_time_s"]
    return {
        "cl_scale_max": float(k[-1]),
        "cl_refined_nm": float(change.max() * 1e9),
        "cl_refined_rel": float((change / np.abs(coulomb["difference_m"])).max() * 100),
        "cl_tf_paper_us": float(by.loc[(paper, k[0]), "flyback_time_s"] * 1e6),
        "cl_tf_slow_min_us": float(slow_tf.min() * 1e6),
        "cl_tf_slow_max_us": float(slow_tf.max() * 1e6),
        "cl_six_paper_limit_nm": float(by.loc[(paper, k[0]), "coulomb_step_m"] * 1e9),
        "cl_six_paper_gap0_nm": float(-by.loc[(paper, k[0]), "difference_m"] * 1e9),
        "cl_six_paper_gap0_ratio": float(-by.loc[(paper, k[0]), "difference_m"]
                                         / by.loc[(paper, k[0]), "presliding_m"] * 100),
        "cl_six_paper_gap_last_nm": float(-by.loc[(paper, k[-1]), "difference_m"] * 1e9),
        "cl_six_slow_limit_nm": float(by.loc[(slow, k[0]), "coulomb_step_m"] * 1e9),
        "cl_six_slow_gap_last_nm": float(abs(by.loc[(slow, k[-1]), "difference_m"]) * 1e9),
        "cl_rate_min": float(coulomb["rate"].min()),
        "cl_rate_max": float(coulomb["rate"].max()),
        "cl_expected": float(EXPECTED_COULOMB_RATE),
    }


def coulomb_side(coulomb: pd.DataFrame) -> str:
    """Where the simulated steps lie against the Coulomb limit: "below" or "on both sides of"."""
    return "below" if (coulomb["difference_m"] < 0).all() else "on both sides of"


def coulomb_rising_gaps(coulomb: pd.DataFrame) -> list[str]:
    """Each place where the gap to the Coulomb limit grows from one stiffness factor to the next."""
    rising = []
    for label, g in coulomb.groupby("configuration", sort=False):
        ordered = g.sort_values("scale")
        gap = np.abs(ordered["difference_m"].to_numpy())
        scales = ordered["scale"].to_numpy()
        rising += [f"{label}: {gap[i] * 1e9:.3f} nm at k = {scales[i]:g} → {gap[i + 1] * 1e9:.3f} nm at "
                   f"k = {scales[i + 1]:g}" for i in np.flatnonzero(np.diff(gap) >= 0)]
    return rising


#: Speed targets of the integrator: ms per 100 Hz period of the
#: six-contact flexible drive with the default (error-controlled) step and the exact contact,
#: which a sweep of the assumption space needs, and ns per fixed step (exact contact).
TARGET_MS_PER_PERIOD, TARGET_NS_PER_STEP = 1.0, 25.0
#: Speed target against a plain fixed-step velocity-Verlet code of the same model
#: (``benchmarks/verlet_baseline.py``): the default's marginal cost per 100 Hz period of the
#: six-contact flexible drive this many times smaller.
TARGET_BASELINE_RATIO = 150.0


def headline_facts(bench: pd.DataFrame) -> dict:
    """The headline of the speed benchmark (:func:`benchmark_table`'s ``attrs["headline"]``): ms per
    100 Hz period of the integration loop (CPU time) for the plain Verlet code, the default and the
    scheme it replaced, their ratios, the same ratio of wall times, the rounds, the load average
    and the target ratio."""
    head = bench.attrs["headline"]
    loop, wall = head["ms_per_period"]["loop"], head["ratios"]["wall"]
    return {"head_baseline_ms": loop["baseline"], "head_default_ms": loop["controlled"],
            "head_reference_ms": loop["reference"],
            "head_ratio": head["ratios"]["loop"]["baseline_over_default"],
            "head_ratio_wall": wall["baseline_over_default"],
            "head_before_after": head["ratios"]["loop"]["reference_over_default"],
            "head_rounds": head["rounds"], "head_load": head["load_average_before"][0],
            "head_default_err_nm": head["error_vs_fixed_fine_nm"]["controlled"],
            "head_baseline_err_nm": head["error_vs_fixed_fine_nm"]["baseline"],
            "target_ratio": TARGET_BASELINE_RATIO}


def scaling_facts(data: dict) -> dict:
    """Numbers the scaling paragraph quotes from ``benchmarks/bench_scaling.py``'s record
    (:func:`benchmark_results` ``("scaling")``): ms per 100 Hz period with 1, 6 and 24 independent
    contacts and ns per step per contact state, the frequency range's cost per simulated ms, the
    sweep's cost per point and start-up, Dask's cost per task and start-up, and the 10⁶-point plan."""
    contacts = pd.DataFrame(data["contacts"])
    own = contacts[~contacts["shared_side_state"]].set_index("contacts")
    per_state = np.polyfit(own["contact_states"], own["ns_per_step"], 1)
    freq = pd.DataFrame(data["frequency"]).set_index("frequency_Hz")
    out = {f"scale_{n}_ms": float(own.loc[n, "ms_per_100Hz_period"]) for n in own.index}
    shared = contacts[contacts["shared_side_state"]].set_index("contacts")
    out.update({f"scale_{n}_shared_ms": float(shared.loc[n, "ms_per_100Hz_period"]) for n in shared.index})
    out.update({"scale_ns_per_state": float(per_state[0]), "scale_ns_base": float(per_state[1]),
                "scale_f_low_Hz": float(freq.index.min()), "scale_f_high_kHz": float(freq.index.max()) / 1e3,
                "scale_low_ms_per_ms": float(freq["ms_per_simulated_ms"].iloc[0]),
                "scale_high_ms_per_ms": float(freq["ms_per_simulated_ms"].iloc[-1]),
                "scale_high_fine_pct": 100 * float(freq["fine_share"].iloc[-1]),
                "scale_low_fine_pct": 100 * float(freq["fine_share"].iloc[0]),
                "sweep_ms_per_point": 1e3 * data["sweep"]["s_per_point"],
                "sweep_start_s": data["sweep"]["start_s"], "sweep_workers": data["sweep"]["workers"]})
    if data.get("dask"):
        plan = data["dask_plan"]
        out.update({"dask_ms_per_task": 1e3 * data["dask"]["s_per_task"],
                    "dask_start_s": data["dask"]["start_s"],
                    "dask_points_per_task": plan["points_per_task"], "dask_tasks": plan["tasks"],
                    "dask_share_pct": 100 * plan["scheduler_share"],
                    "dask_unbatched_pct": 100 * plan["unbatched_scheduler_share"],
                    "dask_core_hours": plan["core_hours"], "dask_plan_points": plan["points"],
                    "dask_ms_per_point": 1e3 * plan["s_per_point_one_core"]})
    return out


def benchmark_facts(bench: pd.DataFrame) -> dict:
    """The speed numbers the performance paragraph quotes, from
    :func:`~benchmark_table`: ms per 100 Hz period (six
    flexible contacts, exact contact) with the default error-controlled step and with the
    explicit adaptive one, the periods each timed run lasted, the same default-step
    configuration's median over fresh processes and their number (``bench_six_flex_processes_ms``,
    ``bench_processes``; NaN and 0 if not measured), the largest ns per fixed step (exact), the
    machine's load average, and the targets."""
    spread = bench.attrs.get("across_processes", {})
    six_flex = bench[(bench["contacts"] == 6) & (bench["actuator"] == "flexible")
                     & (bench["contact_model"] == "exact")].set_index("step")
    fixed_exact = bench[(bench["step"] == "fixed") & (bench["contact_model"] == "exact")]
    return {
        "bench_six_flex_ms": float(six_flex.loc["controlled", "ms_per_100Hz_period"]),
        "bench_six_flex_adaptive_ms": float(six_flex.loc["adaptive", "ms_per_100Hz_period"]),
        "bench_periods": int(bench.attrs["meta"].get("periods_per_run", 1)),
        "bench_six_flex_processes_ms": float(spread.get("median_ms_per_100Hz_period", float("nan"))),
        "bench_processes": len(spread.get("ms_per_100Hz_period_per_process", [])),
        "bench_fixed_ns": float(fixed_exact["ns_per_step"].max()),
        "bench_load": float(bench.attrs["meta"].get("load_average_before", [float("nan")])[0]),
        "target_ms_per_period": TARGET_MS_PER_PERIOD,
        "target_ns_per_step": TARGET_NS_PER_STEP,
    }


def speed_budgets(records: dict | None = None) -> pd.DataFrame:
    """Each speed budget the benchmark scripts state, against their last stored measurement.

    ``records`` maps a :data:`BENCHMARKS` name to its record (default: :func:`benchmark_results`).
    One row per budget: ``measurement``, ``script``, ``measured``, ``budget``, ``unit``, ``holds``
    (measured within the budget: at most it, or at least it for a speed-up) and ``load`` (the
    1-minute load average before the measurement; above the 2 cores a budget missed is no proof).
    Every time is from an empty result cache (the period: the integration loop's CPU time, against
    ``benchmarks/verlet_baseline.py``); the ledger and book rows are the last cold runs of the paper
    profile, the memory row the largest resident set of one of the ledger's processes.
    """
    def record(name):
        return records[name] if records is not None else benchmark_results(name)

    head = record("dynamics")["headline"]
    fit, sweep = record("fit"), record("sweep_map")
    ledger = [r for r in record("ledger") if r.get("profile") == "paper" and r.get("cold", True)][-1]
    book = [r for r in record("book") if r.get("profile") == "paper" and "session_wall_s" in r][-1]
    rows = [
        ("100 Hz period vs plain Verlet", "dynamics",
         head["ratios"]["loop"]["baseline_over_default"], TARGET_BASELINE_RATIO, "× faster",
         head["load_average_before"][0]),
        ("fit: μ, k_p from 15 steps", "fit", fit["wall_time_s"], fit["budget_s"],
         "s", fit["load_average_before"][0]),
        ("24 × 24 velocity map", "sweep_map", sweep["cold"]["wall_s"], sweep["cold"]["target_s"],
         "s", sweep["cold"]["load_average_before"][0]),
        ("the map by passmd sweep", "sweep_map", sweep["cli_cold"]["wall_s"],
         sweep["cli_cold"]["target_s"], "s", sweep["cli_cold"]["load_average_before"][0]),
        ("paper ledger", "ledger", ledger["wall_time_s"], ledger["budget_s"], "s",
         ledger["load_average_before"][0]),
        ("paper ledger, memory", "ledger", ledger["peak_rss_mb"], ledger["memory_budget_mb"],
         "MB", ledger["load_average_before"][0]),
        ("paper book", "book", book["session_wall_s"], book["budget_s"], "s",
         book["load_average_before"][0]),
    ]
    out = pd.DataFrame(rows, columns=["measurement", "script", "measured", "budget", "unit", "load"])
    faster = out["unit"].str.startswith("×")
    within = np.where(faster, out["measured"] >= out["budget"], out["measured"] <= out["budget"])
    out.insert(5, "holds", within)
    out["script"] = "bench_" + out["script"] + ".py"
    return out


def missed_budgets(budgets: pd.DataFrame) -> str:
    """The rows of :func:`speed_budgets` that do not hold, as prose: ``"the fit: μ, k_p from 15 steps
    (32.3 s against 20 s, load 1.19)"``, joined by "and"; ``"none"`` when every budget holds."""
    return _in_prose([f"the {row.measurement} ({row.measured:.3g} {row.unit} against {row.budget:.3g} "
                      f"{row.unit}, load {row.load:.2f})" for row in budgets.itertuples() if not row.holds])


def before_after_table(data: dict | None = None) -> pd.DataFrame:
    """``benchmarks/bench_before_after.py``'s record as a table: per benchmark the wall time of the
    earlier revision and of the later one (s), measured in one run, their ratio and the 1-minute
    load average before each. ``attrs``: the two commits and the date."""
    data = benchmark_results("before_after") if data is None else data
    rows = [{"benchmark": name, "before (s)": run["before"]["wall_time_s"],
             "after (s)": run["after"]["wall_time_s"],
             "before / after": run["ratio_before_over_after"],
             "load before": run["before"]["load_average_before"][0],
             "load after": run["after"]["load_average_before"][0]}
            for name, run in data["benchmarks"].items()]
    out = pd.DataFrame(rows)
    out.attrs.update(before=data["before"], after=data["after"], date=data["date"])
    return out


def _mass_label(mass_kg: float) -> str:
    """A mass as the study's text writes it: µg below 1 mg, mg above."""
    return f"{mass_kg * 1e9:.3g} µg" if mass_kg < 1e-6 else f"{mass_kg * 1e6:.3g} mg"


def _in_prose(items: list[str]) -> str:
    """Items as a list in prose: ``"a, b and c"``, ``"none"`` for no item."""
    return " and ".join([", ".join(items[:-1]), items[-1]] if len(items) > 1 else items) or "none"


def _listed(masses) -> str:
    """Masses as a list in prose: ``"22 µg and 220 µg"``, ``"none"`` for no mass."""
    return _in_prose([_mass_label(m) for m in masses])


def mass_study_facts(study: pd.DataFrame) -> dict:
    """What the actuator-mass study (:func:`~passmd.experiments.model_numerics.figures.actuator_mass_study`)
    supports, as numbers and computed sentences.

    A mass is *consistent with Fig. 6b* when, under at least one fly-back rule, its simulated
    steady-state A_c lies within the tolerance of the ledger's claim
    (:func:`~passmd.experiments.model_numerics.figures.mass_study_tolerance`, the table's
    ``eq12_tolerance_rel``) of its Eq. 12. Returns the printed and the hemisphere's mass and their
    ratio, the tolerance (%) and the sentences: ``mass_grid_text`` (the masses), ``mass_ac_text``
    (which masses are consistent, each rule's A_c at the printed and the hemisphere's mass),
    ``mass_ringing_text`` (the heaviest actuator's natural frequencies and the runner's
    micro-vibration), ``mass_velocity_text`` (the saw-tooth's velocity at the highest frequency for the
    printed and the heaviest mass, and the heaviest's over the profile's frequencies),
    ``mass_verdict`` (whether the printed value is the consistent one and the hemisphere's not) and
    ``mass_hypothesis`` (whether the heaviest actuator, the one that rings near 110 kHz, is
    consistent).
    """
    tolerance = float(study["eq12_tolerance_rel"].iloc[0])
    per_mass = study.drop_duplicates("actuator_mass").sort_values("actuator_mass").set_index("actuator_mass")
    within = pd.DataFrame({rule: (per_mass[f"critical_amplitude_{rule}_m"] / per_mass["eq12_m"] - 1).abs()
                           <= tolerance for rule in MASS_FLYBACKS})
    consistent = within.any(axis=1)
    printed = float(per_mass.index[per_mass["printed"].astype(bool)][0])
    hemisphere = float(per_mass.index[per_mass["hemisphere"].astype(bool)][0])
    heaviest = float(per_mass.index.max())
    names = {"slew": "slew-rate", "fixed": "fixed"}

    def ac_at(mass):
        row = per_mass.loc[mass]
        found = ", ".join(f"{row[f'critical_amplitude_{rule}_m'] * 1e9:.1f} nm with the {names[rule]} "
                          "fly-back" for rule in MASS_FLYBACKS)
        return f"{found} against Eq. 12's {row['eq12_m'] * 1e9:.1f} nm"

    ac_text = (f"On this grid A_c lies within the ledger's ±{100 * tolerance:g} % of Eq. 12 (the tolerance "
               f"of Fig. 6b's claim) under some fly-back rule at {_listed(consistent.index[consistent])} and "
               f"under neither at {_listed(consistent.index[~consistent])}. At the printed "
               f"{_mass_label(printed)} it is {ac_at(printed)}; at a ruby hemisphere's own "
               f"{_mass_label(hemisphere)}, {ac_at(hemisphere)}.")
    heavy = per_mass.loc[heaviest]
    on_contact = sorted(heavy[f"actuator_on_contact_{side}_Hz"] / 1e3 for side in (1, 2))
    ringing_text = (f"An actuator of {_mass_label(heaviest)} rings at "
                    f"{heavy['actuator_frequency_Hz'] / 1e3:.0f} kHz on its own stiffness and at "
                    f"{on_contact[0]:.0f}–{on_contact[1]:.0f} kHz with its "
                    "contact's tangential stiffness in parallel, the printed one at "
                    f"{per_mass.loc[printed, 'actuator_frequency_Hz'] / 1e6:.2f} MHz; the runner's "
                    "micro-vibration after a fly-back stays between "
                    f"{per_mass['ringing_frequency_Hz'].min() / 1e3:.1f} and "
                    f"{per_mass['ringing_frequency_Hz'].max() / 1e3:.1f} kHz at every mass.")
    top = float(study["frequency_Hz"].max())
    v = study.set_index(["actuator_mass", "frequency_Hz"])["velocity_m_per_s"] * 1e3
    velocity_text = (f"At {top / 1e3:g} kHz the saw-tooth's steady velocity is {v[(printed, top)]:.1f} mm/s "
                     f"with the printed mass and {v[(heaviest, top)]:.1f} mm/s with {_mass_label(heaviest)}"
                     + (" (the runner moves backwards)." if v[(heaviest, top)] < 0 else "."))
    curve = study[study["actuator_mass"] == heaviest].sort_values("frequency_Hz")
    if len(curve) > 2:  # a curve over frequency, not two points
        peak = curve.loc[curve["velocity_m_per_s"].idxmax()]
        grid = ", ".join(f"{f / 1e3:g}" for f in curve["frequency_Hz"])
        velocity_text += (f" Over this profile's frequencies ({grid} kHz) the heaviest actuator's velocity "
                          f"is largest at the grid point {peak['frequency_Hz'] / 1e3:g} kHz "
                          f"({peak['velocity_m_per_s'] * 1e3:.1f} mm/s).")
    if consistent[printed] and not consistent[hemisphere]:
        change = (per_mass["eq12_m"].max() / per_mass["eq12_m"].min() - 1) * 100
        verdict = ("So the printed m_a is consistent with Fig. 6b's agreement and a hemisphere's own mass is "
                   "not: A_c with a heavy actuator falls below Eq. 12, whose mass factor (m_r + m_a)/m_r "
                   f"hardly moves it ({change:.2f} % over the grid). The book uses the printed value.")
    elif consistent[printed]:
        verdict = ("Both the printed m_a and a hemisphere's own mass are consistent with Fig. 6b's agreement "
                   "on this grid, so A_c cannot tell them apart. The book uses the printed value, as Table 2 "
                   "gives it.")
    else:
        verdict = ("The printed m_a is not consistent with Fig. 6b's agreement on this grid either. The book "
                   "uses the printed value, as Table 2 gives it.")
    hypothesis = (f"Section 5, however, uses rigid actuators; and at {_mass_label(heaviest)} A_c lies "
                  f"{'within' if consistent[heaviest] else 'outside'} the ledger's tolerance of Eq. 12"
                  + ("." if consistent[heaviest] else
                     ", so the actuator that would give the drive such a limit is not the one of Fig. 6b."))
    return {"mass_grid_text": _listed(per_mass.index), "mass_printed_ug": printed * 1e9,
            "mass_hemisphere_mg": hemisphere * 1e6,
            "mass_ratio": hemisphere / printed, "mass_tolerance_pct": 100 * tolerance,
            "mass_ac_text": ac_text, "mass_ringing_text": ringing_text, "mass_velocity_text": velocity_text,
            "mass_verdict": verdict, "mass_hypothesis": hypothesis}
