"""The benchmark scripts' stored results (``benchmarks/bench_<name>.py``, written to the package
data ``passmd/data/benchmarks/<name>.json``):
:func:`~passmd.experiments.numerics.benchmarks.benchmark_results` reads one script's file as stored,
:func:`~passmd.experiments.numerics.benchmarks.benchmark_table` the integrator's speed benchmark as a table.
Speed is measured by those scripts, never by the tests; the chapters read it from here.
"""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path

import pandas as pd

from passmd.runtime.inputs import read_text
from passmd.runtime.validation import check_choice

#: Benchmark results shipped with the package (``passmd/data/benchmarks/<name>.json``).
BENCHMARKS = ("contact", "driving_waveform", "dynamics", "fit", "fit_coverage")


def benchmark_results(name: str, path: str | Path | None = None) -> dict:
    """One benchmark script's last results (``benchmarks/bench_<name>.py``), as stored.

    Parameters
    ----------
    name : {"contact", "driving_waveform", "dynamics", "fit", "fit_coverage"}
        The benchmark (``fit_coverage``: ``benchmarks/bench_fit_coverage.py``).
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
    return df
