"""The ledger's joint reading as a drive file (``passmd ledger --write-drive``) and the shipped
``passmd/data/drives/joint_reading.toml``: the paper profile's joint reading, as its baseline
records it, written as the command writes it and read back as ``--drive`` reads it."""

from __future__ import annotations

import contextlib
import io
from dataclasses import replace
from pathlib import Path

import pytest

from passmd import cli
from passmd.ledger import readings
from passmd.ledger.joint_drive import joint_drive, joint_drive_file, reading_from_baseline, section_reading
from passmd.model.drive_file import JOINT_READING_FILE, load_drive

BASELINES = Path(__file__).parent


def test_the_shipped_file_is_the_paper_baselines_joint_reading():
    """Regenerate with
    ``passmd ledger --profile paper --overwrite --write-drive passmd/data/drives/joint_reading.toml``."""
    reading = reading_from_baseline(BASELINES / "ledger_baseline_paper.csv")
    assert JOINT_READING_FILE.read_text(encoding="utf-8") == joint_drive_file(reading, "paper")


def test_the_shipped_file_reads_back_to_the_reading_with_its_protocol_options():
    point = reading_from_baseline(BASELINES / "ledger_baseline_paper.csv")
    s41, s42, s5 = (section_reading(point, s) for s in ("4.1", "4.2", "5"))
    drive = load_drive(JOINT_READING_FILE)
    assert drive == joint_drive(point)
    assert drive.amplifier.flyback == s41["flyback"]
    assert drive.friction_coefficient == s41["friction_coefficient"]
    assert drive.actuator.damping_ratio == pytest.approx(s41["damping_ratio"], rel=1e-12)
    header = JOINT_READING_FILE.read_text(encoding="utf-8").splitlines()[:7]
    assert any(f"--protocol {s41['ac_protocol']} --frequency {s41['drive_frequency_s4']:g}Hz" in line
               for line in header)
    force = f"passmd force --drive FILE --frequency {s42['force_frequency']:g}Hz"
    assert any(force in line for line in header)
    assert s42["friction_coefficient"] == 0.2  # what Section 4.2 states
    assert any("Section 5: passmd run --waveform optimized --drive FILE" in line for line in header)
    assert s5["friction_coefficient"] in (0.2, 0.3)


def test_drive_template_prints_the_shipped_file():
    out = io.StringIO()
    assert cli.main(["drive", "template", "--joint-reading"], out=out) == 0
    assert out.getvalue() == JOINT_READING_FILE.read_text(encoding="utf-8")


def test_a_drive_axis_left_at_its_default_is_the_papers_drive():
    """The defaults are the paper's drive: every drive axis at its default changes nothing; a point of the
    space sets the file's keys from Section 4.1's reading only, and each section's command gets the
    options where its reading differs (Section 4.2 its stated μ = 0.2)."""
    default = joint_drive(readings.default_reading())
    assert default == joint_drive({})
    assert joint_drive({"friction_coefficient": 0.3}) == replace(default, friction_coefficient=0.3)
    assert joint_drive({"flyback": "fixed"}).amplifier.flyback == "fixed"
    point = {**readings.default_point(readings.declared_free_axes()), ("friction_coefficient", "5"): 0.3,
             ("friction_coefficient", "4.1"): 0.3, ("flyback", "4.2"): "fixed"}
    assert joint_drive(point) == replace(default, friction_coefficient=0.3)
    text = joint_drive_file(point, "paper")
    assert "Section 4.2: passmd force --drive FILE --frequency 100Hz --flyback fixed --mu 0.2" in text
    assert "Section 5: passmd run --waveform optimized --drive FILE (no option" in text
    assert "--mu" not in text.split("Section 5:")[1].splitlines()[0]  # Section 5's μ = the file's 0.3


#: Claims of claims.csv whose sections and axes the synthetic baselines borrow.
CLAIMS = ("fig6a-rigid-ac-matches-eq11", "fig5b-flexible-above-rigid", "fig9a-standard-position-552nm")


def _baseline(tmp_path, joints):
    text = "claim,status,readings,states,joint\n" + "".join(
        f"{claim},reproduced,defaults,h,{joint}\n" for claim, joint in zip(CLAIMS, joints, strict=False))
    path = tmp_path / "baseline.csv"
    path.write_text(text, encoding="utf-8")
    return path


def test_reading_from_baseline_is_the_union_of_the_claims_projections(tmp_path):
    """Each claim's projection sets the free axes of its own section: μ = 0.3 of a Section 5 claim is
    Section 5's μ, never Section 4.1's."""
    path = _baseline(tmp_path, ["fly-back rule = fixed", "defaults", "μ = 0.3"])
    point = reading_from_baseline(path)
    assert point == {**readings.default_point(readings.declared_free_axes()), ("flyback", "4.1"): "fixed",
                     ("friction_coefficient", "5"): 0.3}


@pytest.mark.parametrize("joints, message", [
    (["fly-back rule = fixed", "fly-back rule = slew"], "disagree on fly-back rule \\(Section 4.1\\)"),
    (["fly-back rule = sometimes"], "is no value of an axis it depends on"),
], ids=["disagreeing", "undeclared"])
def test_reading_from_baseline_refuses_what_is_no_joint_reading(tmp_path, joints, message):
    with pytest.raises(ValueError, match=message):
        reading_from_baseline(_baseline(tmp_path, joints))


def test_a_baseline_without_states_has_no_joint_reading(tmp_path):
    path = tmp_path / "old.csv"
    path.write_text("claim,status\nc0,reproduced\n", encoding="utf-8")
    with pytest.raises(ValueError, match="records no joint reading"):
        reading_from_baseline(path)


@pytest.mark.slow
def test_the_command_writes_the_joint_reading_of_its_ledger(tmp_path):
    """``passmd ledger --profile quick --write-drive`` writes the quick ledger's joint reading (the one
    its baseline records; the quick ledger test keeps the baseline current)."""
    target = tmp_path / "joint.toml"
    with contextlib.redirect_stderr(io.StringIO()):
        status = cli.main(["ledger", "--profile", "quick", "--write-drive", str(target)], out=io.StringIO())
    assert status == 0
    reading = reading_from_baseline(BASELINES / "ledger_baseline_quick.csv")
    assert target.read_text(encoding="utf-8") == joint_drive_file(reading, "quick")
