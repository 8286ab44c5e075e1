"""The chapter contract of CONTRIBUTING.md ("Add a figure", "Add a claim", "Add a chapter"): every
registration the recipes name is found where the recipes put it."""

from __future__ import annotations

import re
from pathlib import Path

from passmd.experiments import figure_table
from passmd.ledger.claims import load_claims
from passmd.report import evaluation

ROOT = Path(__file__).resolve().parents[1]
EXPERIMENTS = ROOT / "passmd" / "experiments"
#: The modules every chapter package has, and ``claims.py`` where the chapter judges claims: no others.
REQUIRED = {"__init__.py", "figures.py", "facts.py"}
MODULE = re.compile(r"__init__\.py|(figures|facts|claims)\.py")


def _toc_chapters() -> list[str]:
    """The file stems of book/_toc.yml, in reading order."""
    return re.findall(r"^\s*- file: (\w+)\s*$", (ROOT / "book" / "_toc.yml").read_text(), flags=re.M)


def _folders() -> list[Path]:
    return sorted(p for p in EXPERIMENTS.iterdir() if p.is_dir() and not p.name.startswith(("_", ".")))


def test_every_chapter_folder_is_in_the_chapter_order_and_the_book():
    assert sorted(p.name for p in _folders()) == sorted(figure_table.CHAPTERS)
    toc = _toc_chapters()
    assert set(figure_table.CHAPTERS) <= set(toc), set(figure_table.CHAPTERS) - set(toc)
    assert list(figure_table.CHAPTERS) == [stem for stem in toc if stem in figure_table.CHAPTERS]


def test_every_chapter_folder_has_the_same_modules():
    for folder in _folders():
        names = {p.name for p in folder.glob("*.py")}
        assert REQUIRED <= names, (folder.name, REQUIRED - names)
        assert all(MODULE.fullmatch(name) for name in names), (folder.name, sorted(names))
        docstring = (folder / "__init__.py").read_text().strip()
        assert docstring.startswith('"""') and docstring.count("\n") == 0, folder.name


def test_every_figure_row_belongs_to_its_chapters_folder_and_page():
    for module in figure_table.chapter_modules("figures"):
        chapter = module.__name__.split(".")[2]
        for spec in getattr(module, "FIGURES", ()):
            assert spec.chapter == chapter, (spec.name, spec.chapter, chapter)
            assert (ROOT / "book" / f"{spec.chapter}.md").is_file(), spec.name
            assert callable(spec.compute), spec.name
            assert callable(spec.plot_function()), spec.plot
    for spec in figure_table.READING_TABLES.values():
        assert set(spec.figures) <= set(figure_table.figure_names()), spec.key


def test_every_claim_extractor_reads_registered_results_of_its_chapter():
    claims = load_claims().set_index("id")
    chapter_of = {spec.name: spec.chapter for spec in figure_table.FIGURES}
    for key, spec in figure_table.READING_TABLES.items():
        chapter_of[key] = chapter_of[spec.figures[0]]
    for claim_id, function in evaluation.extractors().items():
        assert claim_id in claims.index, claim_id
        required = claims.loc[claim_id, "requires"].split(";")
        unknown = [key for key in required if key not in chapter_of and key != "closed_forms"]
        assert not unknown, (claim_id, unknown)
        if function.__module__.startswith("passmd.experiments."):
            chapter = function.__module__.split(".")[2]
            assert function.__module__.split(".")[3] == "claims", function.__module__
            assert chapter in {chapter_of.get(key) for key in required}, (claim_id, chapter, required)


def test_claim_modules_are_every_chapters_claims_modules():
    found = {module.__name__ for module in figure_table.CLAIM_MODULES}
    on_disk = {f"passmd.experiments.{p.parent.name}.{p.stem}" for folder in _folders()
               for p in folder.glob("claims*.py")}
    assert found == on_disk


def test_profile_grids_are_figures_whose_quick_grid_is_part_of_the_papers():
    """GRIDS name figures of the table; the quick profile computes only points the paper profile also
    computes, so "missing" counts the paper's points a quick build lacks (the partial-grid note)."""
    from passmd.experiments.figure_table import GRIDS, figure_names, figures_read, grid_shortfall

    assert set(GRIDS) <= set(figure_names())
    short = grid_shortfall(list(GRIDS), "quick").set_index("figure")
    assert (short["missing"] == short["reference_points"] - short["points"]).all()  # quick ⊂ paper
    assert (short["missing"] > 0).all()  # a grid that does not differ has no entry
    assert grid_shortfall(list(GRIDS), "paper")["missing"].eq(0).all()
    assert figures_read(["fig5b_readings", "closed_forms", "fig9a"]) == ["fig5b", "fig9a"]
