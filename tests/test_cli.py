"""The ``passmd`` command line, run as a user would.

Most tests call ``passmd.cli.main(argv)`` in-process with stdout captured (same code
path as the console script, and numba compiles once); a few run the real console
script and ``python -m passmd`` in a subprocess to check exit codes and that stderr
carries one line and no traceback.

``--json`` output is compared with the Python API *exactly*: the CLI calls the same
deterministic functions with the same SI inputs (units are converted by decimal
multiplication, so "0.25mm" is exactly 0.25e-3), and JSON round-trips floats exactly.
"""

import contextlib
import gc
import inspect
import io
import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from sweep_points import drive_theory_point

import passmd
from passmd import cli
from passmd.model.defaults import PROTOCOL
from passmd.model.mdr_contact import MDRContact
from passmd.model.parameters import Drive
from passmd.model.tables import ACTUATOR_DAMPING_RATIO, Material, actuator_for_radius
from passmd.model.theory import contact_moduli, drive_theory, runner_frequency
from passmd.runtime import provenance, sweep
from passmd.runtime.cache import Cache

SUBCOMMANDS = ["theory", "critical-amplitude", "run", "force", "contact", "figure"]


def run_cli(*argv):
    """(exit status, stdout) of ``passmd argv`` in this process."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out):  # argparse writes --help to sys.stdout
        try:
            status = cli.main(list(argv))
        except SystemExit as exc:  # argparse: --help, usage errors
            status = exc.code
    return status, out.getvalue()


def run_json(*argv):
    status, text = run_cli(*argv, "--json")
    assert status == 0, text
    return json.loads(text)


def console(*argv, module=False):
    """Run the installed console script (or ``python -m passmd``) in a subprocess."""
    if module:
        cmd = [sys.executable, "-m", "passmd", *argv]
    else:
        cmd = [str(Path(sys.executable).parent / "passmd"), *argv]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=300)


# --------------------------------------------------------------------------------------
# help
# --------------------------------------------------------------------------------------


def option_help(help_text: str) -> dict[str, str]:
    """Each option's help, wrapped lines joined: {"--preload": "F_p preload [N] ..."}."""
    blocks: dict[str, str] = {}
    current = None
    for line in help_text.splitlines():
        match = re.match(r"^  (-\S+)(.*)$", line)
        if match:
            current = match.group(1).split(",")[0].rstrip(",")
            if current == "-h":
                current = "--help"
            blocks[current] = match.group(2).strip()
        elif current and line.startswith("      "):
            blocks[current] += " " + line.strip()
        else:
            current = None
    return blocks


@pytest.mark.parametrize("command", SUBCOMMANDS)
def test_help_names_every_option_with_default(command):
    status, text = run_cli(command, "--help")
    assert status == 0
    blocks = option_help(text)
    blocks.pop("--help")
    assert blocks, text
    for flag, help_line in blocks.items():
        assert "default:" in help_line, f"{command} {flag}: {help_line}"
    # a unit other than SI takes no bare number, and its help says so
    quantities = {"--preload": "[N]", "--radius": "[mm; unit required]", "--mu": "[-]",
                  "--amplitude": "[nm; unit required]", "--frequency": "[kHz; unit required]",
                  "--normal-force": "[N]", "--path": "[nm; unit required]",
                  "--runner-modulus": "[GPa; unit required]", "--actuator-stiffness": "[N/m]",
                  "--runner-mass": "[g; unit required]"}
    for flag, unit in quantities.items():
        if flag in blocks:
            assert unit in blocks[flag], f"{command} {flag}: {blocks[flag]}"


def test_help_lists_all_overrides_and_json_keys():
    _, text = run_cli("run", "--help")
    blocks = option_help(text)
    for flag in ["--contacts", "--actuator", "--preload", "--radius", "--mu", "--actuator-stiffness",
                 "--actuator-mass", "--actuator-viscosity", "--runner-modulus", "--runner-poisson",
                 "--hemisphere-modulus", "--hemisphere-poisson", "--runner-mass", "--load-cell-stiffness",
                 "--waveform", "--amplitude", "--frequency", "--periods", "--json", "--csv", "--plot"]:
        assert flag in blocks, flag
    for key in ["final_position_m", "step_sizes_m", "mean_velocity_m_per_s", "back_steps_m"]:
        assert key in text
    _, text = run_cli("critical-amplitude", "--help")
    assert "critical_amplitude_m" in text and "analytic_critical_amplitude_m" in text
    _, text = run_cli("contact", "--help")
    assert "force_N" in text and "--springs" in option_help(text)


# --------------------------------------------------------------------------------------
# theory
# --------------------------------------------------------------------------------------


def test_theory_json_matches_api():
    data = run_json("theory")
    drive = Drive()
    expected = drive_theory(drive)
    for key, value in expected.items():
        assert data[key] == value, key
    assert data["runner_frequency_Hz"] == runner_frequency(drive, in_series=True)
    assert data["runner_frequency_rigid_actuators_Hz"] == runner_frequency(drive)
    assert data["drive"]["preload_N"] == drive.preload
    assert data["drive"]["actuator_viscosity_kg_per_s"] == drive.actuator.viscosity


@pytest.mark.parametrize("radius", ["0.25mm", "0.25 mm", "250um", "2.5e-4m"])
def test_unit_parsing_of_radius(radius):
    data = run_json("theory", "--radius", radius, "--preload", "200mN", "--contacts", "1",
                    "--actuator", "rigid")
    drive = Drive(hemisphere_radius=0.25e-3, preload=0.2, contacts=1, actuator_model="rigid")
    assert data["drive"]["hemisphere_radius_m"] == 0.25e-3
    assert data["drive"]["actuator_stiffness_N_per_m"] == drive.actuator.stiffness  # Table 2 row
    assert data["analytic_critical_amplitude_m"] == drive_theory(drive)["analytic_critical_amplitude_m"]


def test_overrides_reach_the_drive():
    data = run_json(
        "theory", "--runner-modulus", "310GPa", "--runner-poisson", "0.3", "--hemisphere-modulus", "400GPa",
        "--actuator-stiffness", "5e6", "--actuator-mass", "3e-5g", "--runner-mass", "5g", "--mu", "0.3",
    )
    table2 = actuator_for_radius(1e-3)
    k_p, m_a = 5e6, 3e-8
    d = data["drive"]
    assert (d["actuator_stiffness_N_per_m"], d["actuator_mass_kg"]) == (k_p, m_a)
    # viscosity not given: the assumed damping ratio is kept for the new k_p, m_a
    assert d["actuator_viscosity_kg_per_s"] == 2 * ACTUATOR_DAMPING_RATIO * math.sqrt(k_p * m_a)
    assert d["full_stroke_amplitude_m"] == table2.full_stroke_amplitude
    assert d["runner_mass_kg"] == 5e-3
    assert d["friction_coefficient"] == 0.3
    drive = Drive(hemisphere_material=Material(400e9, 0.33), runner_material=Material(310e9, 0.3))
    assert (data["E_star_Pa"], data["G_star_Pa"]) == contact_moduli(drive)
    viscous = run_json("theory", "--actuator-viscosity", "0.1 kg/s")
    assert viscous["drive"]["actuator_viscosity_kg_per_s"] == 0.1


def test_theory_human_output_in_display_units():
    status, text = run_cli("theory", "--contacts", "1")
    assert status == 0
    ac = drive_theory(Drive(contacts=1))["critical_amplitude_flexible_m"]
    assert f"{ac * 1e9:.6g} nm" in text
    assert "R = 1 mm, F_p = 0.4 N" in text


# --------------------------------------------------------------------------------------
# contact
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("springs", [None, 50])
def test_contact_json_matches_mdr_contact(springs):
    extra = [] if springs is None else ["--springs", str(springs)]
    data = run_json("contact", "--normal-force", "0.3N", "--radius", "0.5mm", "--mu", "0.25",
                    "--path", "0nm,30nm,-10nm,45nm,0.02um", *extra)
    E_star, G_star = contact_moduli(Drive())
    contact = MDRContact(0.3, 0.5e-3, E_star, G_star, 0.25, springs=springs)
    path = [0.0, 30e-9, -10e-9, 45e-9, 20e-9]
    assert data["displacement_m"] == path
    assert data["force_N"] == contact.path(np.array(path)).tolist()
    assert data["model"] == ("exact" if springs is None else "discrete")
    assert data["presliding_m"] == contact.presliding
    assert data["sliding_force_N"] == contact.sliding_force


def test_contact_human_output():
    status, text = run_cli("contact", "--path", "0nm,30nm,-10nm")
    assert status == 0
    assert "exact" in text and "μF_N = 0.08 N" in text


# --------------------------------------------------------------------------------------
# run, force (one-contact rigid runs are fast: ~10 ms per 100 Hz period)
# --------------------------------------------------------------------------------------


def simulate_summary(drive, amplitude, frequency, periods, flyback="slew", springs=None):
    from passmd.model import waveforms
    from passmd.solver import simulation

    wave = waveforms.sawtooth(amplitude, frequency, drive, periods=periods, flyback=flyback)
    result = simulation.simulate(drive, wave, contact_model="exact" if springs is None else "discrete",
                               springs=springs or 200)
    return result.summary()


def assert_summary_matches(data, expected):
    for key, value in expected.items():
        assert data[key] == value, key


def test_run_json_matches_simulate():
    data = run_json("run", "--contacts", "1", "--actuator", "rigid", "--amplitude", "0.1um",
                    "--frequency", "200Hz", "--periods", "3", "--preload", "0.3")
    drive = Drive(contacts=1, actuator_model="rigid", preload=0.3)
    assert_summary_matches(data, simulate_summary(drive, 100e-9, 200.0, 3))
    assert data["amplitude_m"] == 100e-9 and data["frequency_Hz"] == 200.0
    assert len(data["step_sizes_m"]) == 2
    assert data["mean_velocity_m_per_s"] > 0
    assert "generated_force_N" not in data


def test_run_optimized_waveform_matches_api():
    """`run --waveform optimized` drives the runner with the Eq. 15 waveform designed from the drive."""
    from passmd.model import optimized_waveform
    from passmd.protocols import eq15
    from passmd.solver import simulation

    data = run_json("run", "--waveform", "optimized", "--actuator", "rigid", "--periods", "3")
    drive = Drive(actuator_model="rigid")
    amplitude = drive.actuator.full_stroke_amplitude
    design = eq15.optimized_design(amplitude, drive)
    wave = optimized_waveform.optimized(amplitude, 100.0, drive, periods=3, design=design)
    result = simulation.simulate(drive, wave)
    assert data["waveform"] == "optimized"
    assert data["final_position_m"] == result.final_position  # same code path, bit for bit


def test_run_default_is_paper_drive_at_full_stroke():
    data = run_json("run", "--periods", "2", "--flyback", "fixed", "--springs", "40")
    drive = Drive()
    assert data["amplitude_m"] == drive.actuator.full_stroke_amplitude
    assert data["frequency_Hz"] == 100.0
    assert_summary_matches(data, simulate_summary(drive, drive.actuator.full_stroke_amplitude, 100.0, 2,
                                                  flyback="fixed", springs=40))


def test_run_writes_csv_and_png(tmp_path):
    csv, png = tmp_path / "series.csv", tmp_path / "plot.png"
    status, text = run_cli("run", "--contacts", "1", "--actuator", "rigid", "--amplitude", "80nm",
                           "--periods", "2", "--max-points", "500", "--csv", str(csv), "--plot", str(png))
    assert status == 0
    assert "final position" in text and " nm" in text
    header = csv.read_text().splitlines()[0].split(",")
    assert header[:3] == ["time_s", "piezo_position_m", "runner_position_m"]
    assert len(csv.read_text().splitlines()) > 100
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_force_json_is_the_stall_protocol():
    """`force` reports the force-generation chapter's generated_force, convergence flag included."""
    from passmd.protocols import stall

    data = run_json("force", "--contacts", "1", "--actuator", "rigid", "--load-cell-stiffness", "5e4",
                    "--amplitude", "120nm")
    drive = Drive(contacts=1, actuator_model="rigid", load_cell=True, load_cell_stiffness=5e4)
    expected = stall.generated_force(drive, 120e-9, PROTOCOL.drive_frequency)
    for key in ("generated_force_N", "converged", "periods", "periods_simulated", "remaining_force_N"):
        assert data[key] == expected[key], key
    assert data["converged"] is True and data["generated_force_N"] > 0
    assert data["drive"]["load_cell"] is True


def test_force_flags_a_run_that_did_not_stall():
    data = run_json("force", "--contacts", "1", "--actuator", "rigid", "--amplitude", "120nm",
                    "--periods", "17", "--max-periods", "17")
    assert data["converged"] is False and data["periods"] == 17
    status, text = run_cli("force", "--contacts", "1", "--actuator", "rigid", "--amplitude", "120nm",
                           "--periods", "17", "--max-periods", "17")
    assert status == 0 and "NOT stalled after 17 periods" in text


# --------------------------------------------------------------------------------------
# critical amplitude
# --------------------------------------------------------------------------------------


def test_critical_amplitude_analytic_only():
    data = run_json("critical-amplitude", "--analytic-only", "--contacts", "6", "--actuator", "rigid")
    theory = drive_theory(Drive(actuator_model="rigid"))
    assert data["analytic_critical_amplitude_m"] == theory["critical_amplitude_rigid_m"]
    assert "critical_amplitude_m" not in data


def test_critical_amplitude_is_the_books_search():
    """`critical-amplitude` reports what passmd.experiments.critical_amplitude_one.figures finds, bracket
    included."""
    from passmd.experiments.critical_amplitude_one import figures

    data = run_json("critical-amplitude", "--contacts", "1", "--actuator", "rigid", "--tolerance", "2nm")
    drive = Drive(contacts=1, actuator_model="rigid")
    found = figures.critical_amplitude(drive, tolerance=2e-9)
    assert data["critical_amplitude_m"] == found["critical_amplitude_m"]
    assert data["bracket_m"] == [found["bracket_low_m"], found["bracket_high_m"]]
    assert 0 < data["bracket_m"][1] - data["bracket_m"][0] <= 2e-9
    assert data["simulations"] == found["runs"] and data["protocol"] == "steady"
    assert data["analytic_critical_amplitude_m"] == drive_theory(drive)["critical_amplitude_rigid_m"]


def test_critical_amplitude_defaults_are_the_books():
    from passmd.protocols import critical_amplitude

    # the CLI's defaults are the protocol record's; the book's search must use the same values
    assert PROTOCOL.steady_periods == critical_amplitude.STEADY_PERIODS
    assert PROTOCOL.step_threshold == critical_amplitude.STEP_THRESHOLD
    data = run_json("critical-amplitude", "--contacts", "1", "--actuator", "rigid", "--tolerance", "5nm")
    assert data["threshold_m"] == critical_amplitude.STEP_THRESHOLD
    assert data["frequency_Hz"] == PROTOCOL.drive_frequency
    tolerance = inspect.signature(critical_amplitude.critical_amplitude).parameters["tolerance"].default
    assert tolerance == PROTOCOL.search_tolerance


def test_force_defaults_are_the_stall_protocols():
    from passmd.protocols import stall

    assert (PROTOCOL.stall_periods, PROTOCOL.stall_max_periods) == (stall.INITIAL_PERIODS, stall.MAX_PERIODS)
    help_text = option_help(run_cli("force", "--help")[1])
    assert f"(default: {stall.INITIAL_PERIODS})" in help_text["--periods"]
    assert f"(default: {stall.MAX_PERIODS})" in help_text["--max-periods"]


def test_critical_amplitude_first_flyback_protocol():
    """First fly-back, one rigid contact: full sliding starts at u_x,max (Eq. 7) within the bracket."""
    data = run_json("critical-amplitude", "--contacts", "1", "--actuator", "rigid", "--protocol", "first",
                    "--tolerance", "1nm")
    lo, hi = data["bracket_m"]
    u_max = drive_theory(Drive(contacts=1, actuator_model="rigid"))["presliding_m"][0]
    assert lo - 0.5e-9 <= u_max <= hi + 0.5e-9  # 0.5 nm: the runner's start-up vibration at 100 Hz


def test_critical_amplitude_none_up_to_full_stroke():
    """One rigid contact needs ~40 nm (Eq. 7): an actuator with a 20 nm stroke never steps."""
    args = ["critical-amplitude", "--contacts", "1", "--actuator", "rigid", "--full-stroke-amplitude", "20nm"]
    data = run_json(*args)
    assert data["critical_amplitude_m"] is None
    assert data["simulations"] == 1
    status, text = run_cli(*args)
    assert status == 0 and "none up to the full stroke 20 nm" in text


# --------------------------------------------------------------------------------------
# errors: one line on stderr, exit 2 for usage, 1 for a failed run
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["theory", "--radius", "3N"], "--radius = '3N' has the wrong unit: N is a force, expected a length"),
        (["theory", "--preload", "1 furlong"], "--preload = '1 furlong' has the wrong unit"),
        (["theory", "--preload", "abc"], "--preload = 'abc' is not a quantity"),
        (["theory", "--preload", "-0.4"], "--preload = -0.4 N is out of range: must be > 0 N"),
        (["theory", "--mu", "0"], "--mu = 0 is out of range"),
        (["theory", "--runner-poisson", "0.5"], "--runner-poisson = 0.5 is out of range"),
        (["theory", "--actuator-viscosity", "-1"], "--actuator-viscosity = -1.0 is out of range"),
        (["theory", "--contacts", "3"], "argument --contacts: invalid choice: 3"),
        (["theory", "--actuator", "soft"], "argument --actuator: invalid choice: 'soft'"),
        (["theory", "--bogus", "1"], "unrecognized arguments: --bogus 1"),
        (["frobnicate"], "invalid choice: 'frobnicate'"),
        (["contact"], "--path is required"),
        (["contact", "--path", "0nm,3N"], "--path = '3N' has the wrong unit"),
        (["contact", "--path", "0nm,,3nm"], "not a comma-separated list"),
        (["contact", "--path", "0nm,3nm", "--springs", "1"], "--springs = 1 is out of range"),
        (["run", "--amplitude", "300nm"], "--amplitude = 300 nm is out of range: must be <= 202 nm"),
        (["run", "--amplitude=-5nm"], "--amplitude = -5.0 is out of range"),
        (["run", "--frequency", "300kHz"], "--frequency = 300kHz is out of range: must be < 250 kHz"),
        (["run", "--periods", "0"], "--periods = 0 is out of range"),
        (["run", "--waveform", "optimized", "--amplitude", "5nm"],
         "the Eq. 15 acceleration amplitude Δ_a = V_a t_a derived from --amplitude 5nm is "),
        (["critical-amplitude", "--periods", "1"], "a step needs >= 2 periods"),
        (["force", "--waveform", "optimized"], "--waveform optimized is not supported by force"),
        (["force", "--springs", "100"], "--springs is not supported by force"),
        (["force", "--max-periods", "20"], "--max-periods = 20 is out of range"),
        (["figure", "fig0x"], "figure 'fig0x' is not available yet"),
        (["figure", "fig5a", "--profile", "slow"], "argument --profile: invalid choice: 'slow'"),
    ],
)
def test_usage_errors_exit_2_with_one_line(argv, message, capsys):
    status, out = run_cli(*argv)
    err = capsys.readouterr().err
    assert status == 2
    assert out == ""
    assert err.count("\n") == 1 and err.startswith("passmd"), err
    assert "error: " in err and message in err, err


def fake_figure_data(name, config):
    """A stand-in figure: a real sweep run at the configuration the CLI passes, plus what it saw."""
    frame = sweep.run(drive_theory_point, sweep.grid(preload=[0.1, 0.2]), progress=False, config=config)
    frame["profile"] = config.profile
    frame["executor_seen"] = config.executor
    return frame[["preload", "analytic_critical_amplitude_m", "profile", "executor_seen"]]


def fake_figure_plot(name, data):
    from matplotlib.figure import Figure

    fig = Figure()
    fig.add_subplot().plot(data["preload"], data["analytic_critical_amplitude_m"] * 1e9)
    return fig


@pytest.fixture
def fake_figure(monkeypatch):
    """The figure table holds one stand-in panel, fig99z (computed at a RunConfig)."""
    from types import SimpleNamespace

    from passmd.experiments import figure_table

    spec = SimpleNamespace(name="fig99z", title="a stand-in panel")
    monkeypatch.setattr(figure_table, "figure_names", lambda: ["fig99z"])
    monkeypatch.setattr(figure_table, "figure_spec", lambda name: spec)
    monkeypatch.setattr(figure_table, "figure_data", fake_figure_data)
    monkeypatch.setattr(figure_table, "figure_plot", fake_figure_plot)
    monkeypatch.delenv("PASSMD_EXECUTOR", raising=False)
    return spec


def test_figure_writes_csv_and_png_through_the_registry(fake_figure, tmp_path):
    cache_dir = tmp_path / "cache"
    data = run_json("figure", "fig99z", "--profile", "quick", "--out", str(tmp_path / "out"),
                    "--executor", "serial", "--cache-dir", str(cache_dir))
    assert data["rows"] == 2 and data["profile"] == "quick"
    csv = Path(data["csv"]).read_text().splitlines()
    assert csv[:3] == [f"# passmd_version: {passmd.__version__}",  # provenance header
                       f"# git_commit: {provenance.git_commit()}", "# profile: quick"]
    assert csv[3] == "preload,analytic_critical_amplitude_m,profile,executor_seen"
    assert csv[4].endswith(",quick,serial")  # the sweep saw --executor ...
    assert len(Cache(cache_dir).entries()) == 2  # ... and --cache-dir
    assert Path(data["png"]).read_bytes()[:4] == b"\x89PNG"
    from PIL import Image

    with Image.open(data["png"]) as png:  # the image names version, commit and profile too
        assert png.text["Description"] == provenance.summary("quick")
    assert "PASSMD_EXECUTOR" not in os.environ  # the command writes no environment variable
    status, text = run_cli("figure", "list")
    assert status == 0 and "fig99z  a stand-in panel" in text


def test_figure_reads_the_environment_once_and_its_options_win(fake_figure, tmp_path, monkeypatch):
    """PASSMD_EXECUTOR / PASSMD_CACHE_DIR reach the figure through the RunConfig; options replace them."""
    monkeypatch.setenv("PASSMD_EXECUTOR", "serial")
    monkeypatch.setenv("PASSMD_CACHE_DIR", str(tmp_path / "env-cache"))
    monkeypatch.setenv("PASSMD_SWEEP_LOG", str(tmp_path / "sweeps.jsonl"))
    monkeypatch.setenv("PASSMD_PROFILE", "slow")  # not read: --profile gives the profile
    monkeypatch.setenv("PASSMD_WORKERS", "two")  # not read: --workers gives the workers
    data = run_json("figure", "fig99z", "--profile", "quick", "--workers", "1", "--out", str(tmp_path / "a"))
    assert Path(data["csv"]).read_text().splitlines()[4].endswith(",quick,serial")
    assert len(Cache(tmp_path / "env-cache").entries()) == 2
    assert json.loads((tmp_path / "sweeps.jsonl").read_text())["computed"] == 2
    data = run_json("figure", "fig99z", "--profile", "quick", "--out", str(tmp_path / "b"),
                    "--executor", "process", "--workers", "2", "--cache-dir", str(tmp_path / "option-cache"))
    assert Path(data["csv"]).read_text().splitlines()[4].endswith(",quick,process")
    assert len(Cache(tmp_path / "option-cache").entries()) == 2


@pytest.mark.parametrize("how", ["a file", "read-only"])
def test_figure_with_an_unwritable_cache_keeps_its_result(fake_figure, tmp_path, monkeypatch, capsys, how):
    """The cache cannot be written: one warning line, the figure is still computed and written."""
    from passmd.runtime.cache import store

    monkeypatch.setattr(store, "_REPORTED_UNWRITABLE", set())
    cache_dir = tmp_path / "cache"
    if how == "a file":
        cache_dir.write_text("not a directory")
    else:
        if os.geteuid() == 0:
            pytest.skip("root writes into read-only directories")
        cache_dir.mkdir()
        cache_dir.chmod(0o500)
    try:
        status, text = run_cli("figure", "fig99z", "--profile", "quick", "--out", str(tmp_path / "out"),
                               "--executor", "serial", "--cache-dir", str(cache_dir), "--json")
    finally:
        if cache_dir.is_dir():
            cache_dir.chmod(0o700)
    err = capsys.readouterr().err
    assert status == 0, err
    assert err.count("\n") == 1 and re.search("warning: cannot (read|write) the cache", err), err
    lines = (tmp_path / "out" / "fig99z.csv").read_text().splitlines()
    assert len([line for line in lines if not line.startswith("#")]) == 3  # header + 2 rows after provenance


def test_cache_command_info_prune_clear(tmp_path):
    cache_dir = tmp_path / "cache"
    sweep.run(drive_theory_point, sweep.grid(preload=[0.1, 0.2]), executor="serial", cache=Cache(cache_dir),
              progress=False)
    old = Cache(cache_dir, fingerprint="f" * 64)
    old.put(old.key(drive_theory_point, {"preload": 0.3}), {"x": 1.0})
    info = run_json("cache", "info", "--cache-dir", str(cache_dir))
    assert (info["entries"], info["current_code"], info["other_code"]) == (3, 2, 1)
    assert info["functions"] == {"sweep_points:drive_theory_point": 2, "?": 1}
    assert run_json("cache", "prune", "--cache-dir", str(cache_dir))["removed"] == 1
    status, text = run_cli("cache", "info", "--cache-dir", str(cache_dir))
    assert status == 0 and "2 (2 of the current code, 0 of other code versions" in text
    assert run_json("cache", "clear", "--cache-dir", str(cache_dir))["removed"] == 2
    assert Cache(cache_dir).entries() == []


def test_failed_simulation_exits_1(monkeypatch, capsys):
    from passmd.solver import simulation
    from passmd.solver.results import SimulationError

    def diverge(*args, **kwargs):
        raise SimulationError("simulation diverged at integrator step 12")

    monkeypatch.setattr(simulation, "simulate", diverge)
    status, out = run_cli("run", "--periods", "1")
    err = capsys.readouterr().err
    assert status == 1 and out == ""
    assert err == "passmd run: error: run failed: simulation diverged at integrator step 12\n"


# --------------------------------------------------------------------------------------
# garbage collection paused while a command starts (passmd.cli.startup)
# --------------------------------------------------------------------------------------


def test_run_pauses_the_collector_until_its_simulation_has_run(monkeypatch, tmp_path):
    """Imports and kernel loading run without automatic collection; the outputs (pandas,
    matplotlib) and whatever follows the command run with it."""
    from passmd.cli.commands import run
    from passmd.solver import simulation

    enabled = {}
    simulate, write_outputs = simulation.simulate, run.write_outputs

    def spy_simulate(*args, **kwargs):
        enabled["simulation"] = gc.isenabled()
        return simulate(*args, **kwargs)

    def spy_write_outputs(*args, **kwargs):
        enabled["outputs"] = gc.isenabled()
        return write_outputs(*args, **kwargs)

    monkeypatch.setattr(simulation, "simulate", spy_simulate)
    monkeypatch.setattr(run, "write_outputs", spy_write_outputs)
    assert gc.isenabled()
    # (an in-process Ctrl-C test earlier in the session may have frozen objects: count from here)
    frozen = gc.get_freeze_count()
    status, _ = run_cli("run", "--contacts", "1", "--actuator", "rigid", "--periods", "1",
                        "--csv", str(tmp_path / "series.csv"))
    assert status == 0
    assert enabled == {"simulation": False, "outputs": True}
    assert gc.isenabled() and gc.get_freeze_count() == frozen  # nothing left frozen for the caller


def test_other_commands_run_with_the_collector_and_a_disabled_one_stays_off(monkeypatch):
    from passmd.model import theory

    enabled = []
    drive_theory = theory.drive_theory

    def spy(*args, **kwargs):
        enabled.append(gc.isenabled())
        return drive_theory(*args, **kwargs)

    monkeypatch.setattr(theory, "drive_theory", spy)
    assert run_cli("theory")[0] == 0
    assert run_cli("run", "--periods", "0")[0] == 2  # a usage error: the collector is on again
    assert enabled == [True] and gc.isenabled()
    gc.disable()
    try:
        assert run_cli("theory")[0] == 0
        assert enabled == [True, False] and not gc.isenabled()  # the caller's choice is kept
    finally:
        gc.enable()


_EXIT_PROBE = """
import atexit, contextlib, gc, io, sys
# registered before the command: atexit runs it after the command's own exit callbacks
atexit.register(lambda: sys.stderr.write(f"frozen at exit: {gc.get_freeze_count() > 0}\\n"))
from passmd import cli
with contextlib.redirect_stdout(io.StringIO()):
    status = cli.main(["theory"])
sys.stderr.write(f"frozen after main: {gc.get_freeze_count() > 0}\\n")
sys.exit(status)
"""


def test_the_exit_collection_is_skipped():
    """The interpreter's last collection, through all the command loaded, is skipped (the objects
    are frozen at exit, not before: a caller that goes on keeps collecting them)."""
    done = subprocess.run([sys.executable, "-c", _EXIT_PROBE], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stderr.splitlines() == ["frozen after main: False", "frozen at exit: True"]


_BLAS_PROBE = """
import sys
import numpy as np
from passmd.cli import startup
startup.load_numba_without_blas_probe()
hidden = "scipy.linalg" not in sys.modules and "scipy.linalg.cython_blas" not in sys.modules
from passmd.model.contact import contact_arrays, contact_force
params, state = contact_arrays("exact", 0.4, 1e-3, 1e11, 5e10, 0.2)
force = contact_force(params, state, 1e-9)  # a compiled kernel runs without BLAS
import scipy.linalg.cython_blas  # and scipy's BLAS module is importable afterwards
print(hidden, force > 0)
"""


def test_numba_registry_loads_without_scipy_and_scipy_stays_importable():
    """The run command loads numba's array-math registry with scipy's BLAS module hidden from its
    probe (0.1-0.15 s of start-up); passmd's kernels still run, and scipy imports normally later."""
    done = subprocess.run([sys.executable, "-c", _BLAS_PROBE], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["True", "True"]


def test_an_output_into_a_missing_folder_is_bad_input(tmp_path, capsys):
    """Found before the run: exit 2, as every input refused before any work."""
    target = tmp_path / "missing-dir" / "series.csv"
    status, _ = run_cli("run", "--contacts", "1", "--actuator", "rigid", "--periods", "1",
                        "--csv", str(target))
    err = capsys.readouterr().err
    assert status == 2 and "cannot write --csv" in err and err.count("\n") == 1


# --------------------------------------------------------------------------------------
# the installed console script and python -m passmd
# --------------------------------------------------------------------------------------


def test_console_script_json_and_errors(tmp_path):
    done = console("theory", "--radius", "0.25mm", "--contacts", "1", "--json")
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)
    assert data["drive"]["hemisphere_radius_m"] == 0.25e-3
    assert data["analytic_critical_amplitude_m"] == drive_theory(
        Drive(hemisphere_radius=0.25e-3, contacts=1))["analytic_critical_amplitude_m"]

    bad = console("theory", "--radius", "3N")
    assert bad.returncode == 2 and bad.stdout == ""
    assert bad.stderr.count("\n") == 1 and "Traceback" not in bad.stderr
    assert "--radius = '3N' has the wrong unit" in bad.stderr

    unknown = console("run", "--no-such-option")
    assert unknown.returncode == 2 and "Traceback" not in unknown.stderr
    assert unknown.stderr.strip() == "passmd: error: unrecognized arguments: --no-such-option"


def test_python_dash_m():
    done = console("contact", "--path", "0nm,30nm,-10nm,45nm", "--json", module=True)
    assert done.returncode == 0, done.stderr
    assert len(json.loads(done.stdout)["force_N"]) == 4
    assert console("--version", module=True).stdout.startswith("passmd ")
    assert console(module=True).returncode == 2  # a subcommand is required


def test_run_optimized_reports_its_eq15_design():
    """`run --waveform optimized` gives the design it ran (t_s, t_a, Δ_a, V_a, f_s, V_r, u_x,max),
    the one passmd.protocols.eq15 derives for this drive; a saw-tooth run has none."""
    from passmd.model.optimized_waveform import highest_fitting_frequency
    from passmd.model.parameters import Drive
    from passmd.protocols import eq15

    data = run_json("run", "--waveform", "optimized", "--frequency", "5kHz", "--periods", "3")
    drive = Drive()
    amplitude = drive.actuator.full_stroke_amplitude
    design = eq15.optimized_design(amplitude, drive)
    assert data["design"] == pytest.approx(design.as_dict(), rel=1e-12)  # the same computation, run again
    assert data["design"]["response_frequency_Hz"] == 100.0  # the paper's 100 Hz response (Section 5.2)
    f_max = highest_fitting_frequency(design, amplitude, drive)
    assert data["eq15_highest_frequency_Hz"] == pytest.approx(f_max, rel=1e-12)
    assert 5e3 < f_max < 10e3  # so Eq. 15 fits at 5 kHz and not at 10 kHz
    _, text = run_cli("run", "--waveform", "optimized", "--frequency", "5kHz", "--periods", "3")
    row = next(line for line in text.splitlines() if line.strip().startswith("Eq. 15 design"))
    symbols = ("t_s =", "t_a =", "Δ_a =", "V_a =", "f_s =", "V_r =", "u_x,max =", "100 Hz saw-tooth response")
    assert all(symbol in row for symbol in symbols), row
    from passmd.cli.notes import hz

    shown = hz(f_max, down=True)  # an upper limit is shown rounded down: typed back, it fits
    assert float(shown.split()[0]) * 1e3 <= f_max
    assert re.search(rf"Eq. 15 fits +up to {shown}", text), text
    # above it the run is refused in one line naming the highest frequency at which Eq. 15 fits
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        status, _ = run_cli("run", "--waveform", "optimized", "--frequency", "10kHz", "--periods", "3")
    text = err.getvalue()
    assert status == 2 and text.count("\n") <= 1, text
    assert f"--frequency = 10kHz is out of range for --waveform optimized: must be <= {shown}" in text
    data = run_json("run", "--waveform", "optimized", "--frequency", "2kHz", "--periods", "3",
                    "--design-response", "driving")
    assert data["design"]["response_frequency_Hz"] == 2e3
    assert "design" not in run_json("run", "--periods", "2")
