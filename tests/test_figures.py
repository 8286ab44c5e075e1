"""The figure table: names, chapters, lookup errors, and the layers it joins."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from passmd.experiments import figure_table
from passmd.runtime.config import RunConfig

BOOK = Path(__file__).resolve().parents[1] / "book"


def test_names_are_unique_and_in_table_order():
    names = figure_table.figure_names()
    assert names == [spec.name for spec in figure_table.FIGURES]
    assert len(set(names)) == len(names)


def test_every_figure_a_chapter_draws_is_in_the_table():
    """A chapter draws figures only through figure_plot, with names that the table holds for it."""
    for spec in figure_table.FIGURES:
        assert (BOOK / f"{spec.chapter}.md").exists(), spec
    for chapter in BOOK.glob("*.md"):
        text = chapter.read_text()
        for name in re.findall(r"figure_plot\(\"(\w+)\"", text):
            assert figure_table.figure_spec(name).chapter == chapter.stem, (chapter.name, name)


def test_unknown_figure_names_the_known_ones():
    with pytest.raises(ValueError, match="figure = .fig99z. is not available: must be one of model_sawtooth"):
        figure_table.figure_spec("fig99z")


def test_figure_data_takes_a_run_configuration():
    with pytest.raises(ValueError, match="config = 'quick' is not a RunConfig"):
        figure_table.figure_data("fig5a", "quick")
    with pytest.raises(ValueError, match="profile = 'fast'"):
        figure_table.figure_data("fig5a", RunConfig(profile="fast"))


def test_claim_modules_are_the_experiment_modules_with_extractors():
    """Every experiment module that tags a claim extractor is found (by its name, claims*.py), and
    only those."""
    package = Path(figure_table.__file__).parent
    tagged = {"passmd." + ".".join(path.relative_to(package.parent).with_suffix("").parts)
              for path in package.rglob("*.py")
              if re.search(r"^@(register_)?extractor\(", path.read_text(), flags=re.M)}
    assert {module.__name__ for module in figure_table.CLAIM_MODULES} == tagged


@pytest.mark.parametrize("module", ["passmd.experiments.critical_amplitude_one.figures",
                                    "passmd.experiments.figure_table", "passmd.report.evaluation",
                                    "passmd.protocols.critical_amplitude"])
def test_computing_loads_no_plotting(module):
    """Figure data, the ledger and the protocols load no matplotlib: the figure table names each
    plot function and imports it only to draw."""
    code = (f"import sys, {module}; "
            "print(any(m.startswith(('matplotlib', 'passmd.plots')) for m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_plots_do_not_import_experiments():
    code = ("import sys, passmd.plots.critical_amplitude; "
            "print(any(m.startswith('passmd.experiments') for m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


@pytest.mark.parametrize("chapter", ["design_your_drive", "calibration"])
def test_a_page_drawing_the_tables_it_computed_draws_each_of_its_rows_once(chapter):
    """These pages compute their tables with the rows' own functions and draw each one through
    figure_plot by name, once, and nothing else: the page's generated figure count is what it shows."""
    text = (BOOK / f"{chapter}.md").read_text()
    drawn = re.findall(r"figure_plot\(\"(\w+)\"", text)
    assert sorted(drawn) == sorted(spec.name for spec in figure_table.FIGURES if spec.chapter == chapter)
    assert text.count("show_figure(") == len(drawn) == len(re.findall(r"show_figure\(figure_plot\(", text))
