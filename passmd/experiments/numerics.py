"""Trust in the integrator: time-step convergence, energy balance, cost (model chapter).

These are not paper figures; they back every figure's numbers. Each function returns a
tidy DataFrame in SI units.
"""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path

import pandas as pd

from passmd import dynamics, waveforms
from passmd._validation import check_choice
from passmd.parameters import Drive

#: Configurations the numerics are shown for: (label, contacts, actuator model).
CONFIGURATIONS = (
    ("one contact, rigid", 1, "rigid"),
    ("one contact, flexible", 1, "flexible"),
    ("six contacts, rigid", 6, "rigid"),
    ("six contacts, flexible", 6, "flexible"),
)

#: Refinement factors of the default step (1 = the default).
RESOLUTIONS = {"quick": (0.5, 1.0, 2.0, 4.0), "paper": (0.25, 0.5, 1.0, 2.0, 4.0, 8.0)}


def convergence_study(
    amplitude: float = 150e-9,
    frequency: float = 100.0,
    periods: int = 3,
    resolutions=RESOLUTIONS["quick"],
    preload: float = 0.4,
    hemisphere_radius: float = 1e-3,
    step_controls=("adaptive", "fixed"),
) -> pd.DataFrame:
    """Runner position after ``periods`` saw-tooth periods against the time-step refinement.

    For each configuration the finest run is the reference; ``error_m`` is the difference
    to it. Flexible actuators are run with the adaptive step (default) and with the fixed
    fine step, so the table also shows what the adaptation costs in accuracy; with
    ``"quasi-static"`` in ``step_controls`` also with the quasi-static actuator step
    (``simulate(..., quasi_static=True)``).

    Returns
    -------
    DataFrame
        Columns ``configuration, step_control, resolution, fine_step_s, coarse_step_s,
        steps, final_position_m, error_m``.
    """
    rows = []
    for label, contacts, model in CONFIGURATIONS:
        drive = Drive(
            hemisphere_radius=hemisphere_radius, preload=preload, contacts=contacts, actuator_model=model
        )
        wf = waveforms.sawtooth(amplitude, frequency, drive, periods=periods)
        controls = tuple(step_controls) if model == "flexible" else ("fixed",)
        for control in controls:
            for r in resolutions:
                if control == "fixed" and model == "flexible" and r > 2.0:
                    continue  # the fixed fine step at r > 2 costs minutes and adds nothing
                res = dynamics.simulate(drive, wf, resolution=r, adaptive=control != "fixed",
                                        quasi_static=control == "quasi-static", max_points=2)
                rows.append(
                    {
                        "configuration": label,
                        "step_control": control,
                        "resolution": float(r),
                        "fine_step_s": res.fine_step,
                        "coarse_step_s": res.coarse_step,
                        "steps": res.steps,
                        "final_position_m": res.final_position,
                    }
                )
    df = pd.DataFrame(rows)
    # reference: the finest run of each configuration (adaptive for flexible actuators)
    finest = df.loc[df.groupby("configuration")["resolution"].idxmax()]
    ref = finest.set_index("configuration")["final_position_m"]
    df["error_m"] = df["final_position_m"] - df["configuration"].map(ref)
    return df


def energy_balance_table(
    amplitude: float = 150e-9, frequency: float = 1000.0, periods: int = 3
) -> pd.DataFrame:
    """Energy balance W_in = E_kin + E_el + W_contact + W_damp of each configuration.

    Runs with the exact contact and with the discrete contact (N = 200 springs).
    """
    rows = []
    for label, contacts, model in CONFIGURATIONS:
        drive = Drive(contacts=contacts, actuator_model=model)
        wf = waveforms.sawtooth(amplitude, frequency, drive, periods=periods)
        for contact in ("exact", "discrete"):
            res = dynamics.simulate(drive, wf, contact_model=contact, springs=200, max_points=2)
            bal = res.energy_balance()
            rows.append({"configuration": label, "contact_model": contact, **bal})
    return pd.DataFrame(rows)


#: Benchmark results shipped with the package (``passmd/data/benchmarks/<name>.json``).
BENCHMARKS = ("contact", "driving_waveform", "dynamics")


def benchmark_results(name: str, path: str | Path | None = None) -> dict:
    """One benchmark script's last results (``benchmarks/bench_<name>.py``), as stored.

    Parameters
    ----------
    name : {"contact", "driving_waveform", "dynamics"}
        The benchmark.
    path : path-like, optional
        A results file to read instead of the one installed with the package
        (``passmd/data/benchmarks/<name>.json``, package data, which the benchmark
        scripts write by default when run from the repository).

    Returns
    -------
    dict
        ``{"meta": {...}, "rows": [...]}`` as the script wrote it.
    """
    check_choice("name", name, BENCHMARKS)
    if path is None:
        resource = resources.files("passmd") / "data" / "benchmarks" / f"{name}.json"
        if not resource.is_file():
            raise FileNotFoundError(
                f"{resource} is missing: run `python benchmarks/bench_{name}.py` in the repository"
            )
        return json.loads(resource.read_text(encoding="utf-8"))
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"{path} is missing: run `python benchmarks/bench_{name}.py --out {path}`")
    return json.loads(path.read_text(encoding="utf-8"))


def benchmark_table(path: str | Path | None = None) -> pd.DataFrame:
    """The speed benchmark's last results (``benchmarks/bench_dynamics.py``), as a table.

    Reads :func:`benchmark_results` ``("dynamics", path)``; ``df.attrs["meta"]`` holds the
    machine and settings it was measured with.
    """
    data = benchmark_results("dynamics", path)
    df = pd.DataFrame(data["rows"])
    df.attrs["meta"] = data.get("meta", {})
    return df


def settle_fraction_sensitivity(
    fractions=(0.1, 0.2, 0.4), amplitude: float = 150e-9, frequency: float = 100.0, periods: int = 4
) -> pd.DataFrame:
    """Step sizes for several settle windows (assumption ``settled_position``).

    The settled position averages x_r − x_p over the last ``fraction`` of each stick phase;
    the table shows how much the mean step of the last ``periods − 1`` periods depends on it.
    """
    rows = []
    for label, contacts, model in CONFIGURATIONS:
        drive = Drive(contacts=contacts, actuator_model=model)
        for fraction in fractions:
            wf = waveforms.sawtooth(amplitude, frequency, drive, periods=periods, settle_fraction=fraction)
            res = dynamics.simulate(drive, wf, max_points=2)
            rows.append({"configuration": label, "settle_fraction": float(fraction),
                         "mean_step_m": float(res.step_sizes.mean())})
    return pd.DataFrame(rows)
