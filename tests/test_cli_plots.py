"""Every kind of PNG the command line writes, drawn and read back through matplotlib's objects.

The kinds: ``run``/``force --plot`` (positions against time), ``sweep --out`` curves (one axis, with
the closed form), heat maps with a one-signed and with a diverging scale (two axes, cells with no
value, not steady or below the resolution), and ``fit --out``'s fit.png. Each is written by the
command (a PNG that decodes and is not blank) and its figure is checked as a reader sees it: every
axis labelled with a unit, tick labels on both axes, a legend whose every entry says something, a
colour bar with a label and, when it is diverging, ticks on both sides of zero around a scale
symmetric about it; a sweep's title names what varies and not the value it had in the base drive.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest
from cli_runs import run_main

from passmd.model.parameters import Drive

#: A drive whose runs cost milliseconds: one contact, rigid actuators.
CHEAP = ("--contacts", "1", "--actuator", "rigid")


def run_cli(*argv) -> tuple[int, str]:
    status, out, err = run_main(argv)
    return status, out + err


def png_shows_something(path) -> None:
    from PIL import Image

    with Image.open(path) as picture:
        assert picture.format == "PNG" and min(picture.size) > 100
        low, high = picture.convert("L").getextrema()
    assert low < high, f"{path} is blank"


def _ticks(axis) -> list[str]:
    return [t.get_text() for t in axis.get_ticklabels() if t.get_text() and t.get_visible()]


def readable(fig) -> dict:
    """Check a figure as a reader sees it (module docstring); return its texts for further checks."""
    fig.canvas.draw()  # tick labels and layout as saved
    bars = [ax for ax in fig.axes if ax.get_label() == "<colorbar>"]
    plots = [ax for ax in fig.axes if ax not in bars]
    texts = {"titles": [], "legend": [], "bars": []}
    for ax in plots:
        assert ax.get_ylabel().strip(), f"an axis without a y label in {ax.get_title()!r}"
        shared = ax.get_shared_x_axes().get_siblings(ax)
        assert any(other.get_xlabel().strip() for other in shared), f"no x label: {ax.get_title()!r}"
        # a column of shared x axes labels its bottom one only
        assert max(len(_ticks(other.xaxis)) for other in shared) >= 2, f"x ticks: {ax.get_title()!r}"
        assert len(_ticks(ax.yaxis)) >= 2, f"fewer than two y tick labels in {ax.get_title()!r}"
        texts["titles"].append(ax.get_title())
        legend = ax.get_legend()
        if legend is not None:
            entries = [t.get_text() for t in legend.get_texts()]
            assert entries and all(e.strip() for e in entries), entries
            texts["legend"] += entries
    for bar in bars:
        mesh = next(c for c in fig.axes[0].collections + [m for ax in plots for m in ax.collections]
                    if getattr(c, "colorbar", None) is not None and c.colorbar.ax is bar)
        label = mesh.colorbar.ax.get_ylabel()
        assert label.strip() and "[" in label, label
        ticks = [float(t.get_text().replace("−", "-")) for t in bar.yaxis.get_ticklabels() if t.get_text()]
        norm = mesh.norm
        if norm.vmin < 0 < norm.vmax:  # diverging: symmetric, zero in the middle, ticks either side
            assert norm.vmin == pytest.approx(-norm.vmax, rel=1e-12)
            assert min(ticks) < 0 < max(ticks) and 0.0 in ticks, ticks
        texts["bars"].append(label)
    texts["suptitle"] = fig._suptitle.get_text() if fig._suptitle is not None else ""
    return texts


def test_run_plot_names_positions_time_and_the_run(tmp_path):
    from passmd.model import waveforms
    from passmd.plots.trace import positions_figure
    from passmd.solver import simulation

    status, text = run_cli("run", *CHEAP, "--periods", "2", "--plot", str(tmp_path / "run.png"))
    assert status == 0, text
    png_shows_something(tmp_path / "run.png")
    drive = Drive(contacts=1, actuator_model="rigid")
    result = simulation.simulate(drive, waveforms.sawtooth(drive.actuator.full_stroke_amplitude, 100.0, drive,
                                                         periods=2), max_points=200)
    texts = readable(positions_figure(result, "sawtooth, A = 202 nm"))
    ax = positions_figure(result, "t").axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("time [ms]", "position [nm]")
    assert texts["legend"] == ["piezo x_p (the waveform)", "runner x_r"]


def test_force_plot_is_written_too(tmp_path):
    status, text = run_cli("force", *CHEAP, "--amplitude", "150nm", "--periods", "20", "--plot",
                           str(tmp_path / "force.png"))
    assert status == 0, text
    png_shows_something(tmp_path / "force.png")


def _sweep(tmp_path, name, *argv):
    prefix = tmp_path / name
    status, text = run_cli("sweep", *argv, "--executor", "serial", "--cache-dir", str(tmp_path / "cache"),
                           "--out", str(prefix), "--json")
    assert status == 0, text
    png_shows_something(f"{prefix}.png")
    data = json.loads(text[text.index("{"):])
    return data, pd.DataFrame(data["rows"])


def _figure(data, table, quantity, **options):
    """The figure ``sweep`` drew, drawn again from its JSON (the same function, the same table)."""
    import argparse

    from passmd.cli.commands.sweep import parse_vary
    from passmd.cli.notes import sweep_figure
    from passmd.protocols.maps import MAP_QUANTITIES

    args = argparse.Namespace(quantity=quantity, reading=options.get("reading"),
                              waveform=options.get("waveform"), design_response=None)
    axes = [parse_vary(a["typed"]) for a in data["axes"]]
    table = table.astype({c: float for c in table.columns if table[c].dtype == object and c.endswith("_m")},
                         errors="ignore")
    return sweep_figure(args, axes, MAP_QUANTITIES[quantity], table, options.get("title", "title\nline 2"))


def test_sweep_curve_names_what_varies_and_the_reading(tmp_path):
    data, table = _sweep(tmp_path, "ac", "critical-amplitude", *CHEAP, "--vary", "preload=0.2N,0.4N,0.6N",
                         "--reading", "first")
    from passmd.cli.commands.sweep import parse_vary
    from passmd.cli.notes import sweep_title
    from passmd.protocols.maps import MAP_QUANTITIES

    title = sweep_title(MAP_QUANTITIES["critical-amplitude"], [parse_vary("preload=0.2N,0.4N,0.6N")],
                        Drive(preload=0.2, contacts=1, actuator_model="rigid"))
    assert title == "critical amplitude A_c over preload\nR = 1 mm, μ = 0.2, 1 contact, rigid actuators"
    texts = readable(_figure(data, table, "critical-amplitude", reading="first", title=title))
    assert texts["titles"] == [title]
    assert texts["legend"][:2] == ["critical amplitude A_c, first reading", "closed form (Eqs. 7–8, 11–12)"]
    status, text = run_cli("sweep", "critical-amplitude", *CHEAP, "--vary", "preload=0.2N,0.4N,0.6N",
                           "--reading", "first", "--executor", "serial", "--cache-dir",
                           str(tmp_path / "cache"))
    header = text.splitlines()[0]
    assert "F_p =" not in header and "R = 1 mm" in header  # the base drive's preload is not the curve's


def test_heat_map_marks_cells_that_are_not_values(tmp_path):
    """Amplitudes below the critical amplitude make no measurable step: hatched and named, not coloured;
    a one-signed quantity keeps a sequential scale."""
    data, table = _sweep(tmp_path, "v", "step", *CHEAP, "--vary", "frequency=100Hz,300Hz,1kHz",
                         "--vary", "amplitude=10nm,120nm,202nm")
    fig = _figure(data, table, "step")
    texts = readable(fig)
    assert texts["bars"] == ["steady step (velocity / f) [nm]"]
    assert any(t.startswith("|value| below the measurable step (0.5 nm)") for t in texts["legend"]), texts
    mesh = fig.axes[0].collections[0]
    low = np.ma.getmaskarray(mesh.get_array()).reshape(3, 3)[0]  # the 10 nm row: no colour
    assert low.all() and not np.ma.getmaskarray(mesh.get_array()).reshape(3, 3)[2].any()


def test_diverging_map_is_symmetric_about_zero_and_names_missing_cells():
    """A synthetic gain map: negative and positive cells, one tiny negative value, missing cells."""
    from passmd.plots.sweep_map import MapAxis, cell_marks, map_figure

    f, a = np.meshgrid([1e3, 1e4, 1e5], [50e-9, 100e-9, 150e-9, 200e-9], indexing="ij")
    gain = (a * 1e9 - 120) * 1e-5
    gain[0, 0] = -1e-9  # |gain| far below the resolution (0.5 nm × 1 kHz): not a value
    gain = gain.ravel().tolist()
    gain[-1] = None  # Eq. 15 gives no waveform there
    table = pd.DataFrame({"frequency_Hz": f.ravel(), "amplitude_m": a.ravel(), "gain_m_per_s": gain})
    value = MapAxis("gain_m_per_s", "Eq. 15 gain", "mm/s", scale=1e-3)
    marks = cell_marks(table, value, 0.5e-9 * table["frequency_Hz"], missing_label="no value: no waveform",
                       resolution_label="below the resolution")
    assert marks.unresolved.tolist().count(True) == 1 and marks.missing[-1]
    fig = map_figure(table, [MapAxis("frequency_Hz", "frequency", "kHz", log=True),
                             MapAxis("amplitude_m", "amplitude", "nm")], value, "gain\ndrive", marks=marks)
    texts = readable(fig)
    assert texts["legend"] == ["no value: no waveform", "below the resolution"]
    mesh = fig.axes[0].collections[0]
    assert mesh.norm.vmax == pytest.approx(max(abs(g) for g in gain if g is not None and abs(g) > 1e-6) * 1e3)


def test_fit_png_is_written_and_labelled(tmp_path, monkeypatch):
    import passmd
    from passmd.plots.fit import fit_figure
    from passmd.protocols import fit

    monkeypatch.setenv("PASSMD_CACHE_DIR", str(tmp_path / "cache"))
    truth = Drive(contacts=1, actuator_model="rigid", friction_coefficient=0.25)
    rows = [[str(a), str(p), "100", "0", "0.5"] for p in (0.2, 0.4) for a in (60, 120)]
    header = ["amplitude_nm", "preload_N", "frequency_Hz", "step_nm", "step_nm_sd"]
    data = fit.measurements_from_rows(header, rows)
    data = fit.Measurements(**{**vars(data), "value": fit.predict(truth, data, executor="serial",
                                                               cache=tmp_path / "cache")})
    fit.write_measurements(tmp_path / "data.csv", data)
    status, text = run_cli("fit", str(tmp_path / "data.csv"), "--free", "mu", *CHEAP,
                           "--executor", "serial", "--out", str(tmp_path / "out"))
    assert status == 0, text
    png_shows_something(tmp_path / "out" / "fit.png")
    result = passmd.fit(Drive(contacts=1, actuator_model="rigid"), data, ["friction_coefficient"],
                        executor="serial", cache=tmp_path / "cache")
    texts = readable(fit_figure(result.residual_table()))
    assert texts["suptitle"].strip() and texts["legend"]
    assert math.isfinite(result.estimates["friction_coefficient"]["value"])
