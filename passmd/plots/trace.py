"""The picture ``passmd run --plot`` and ``passmd force --plot`` write: piezo and runner positions
against time (:class:`passmd.solver.results.SimulationResult`)."""

from __future__ import annotations

from matplotlib.figure import Figure

from passmd.runtime.units import from_si

__all__ = ["positions_figure"]


def positions_figure(result, title: str) -> Figure:
    """x_p and x_r of a run against time, in nm and ms; ``title`` names the waveform and the drive."""
    fig = Figure(figsize=(7, 4), layout="constrained")
    ax = fig.add_subplot()
    t_ms = result.time * 1e3
    ax.plot(t_ms, from_si(result.piezo_position, "nm"), label="piezo x_p (the waveform)", lw=0.8)
    ax.plot(t_ms, from_si(result.runner_position, "nm"), label="runner x_r", lw=0.8)
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("position [nm]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=9)
    return fig
