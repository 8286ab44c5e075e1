"""passmd.report.publish: the helpers the book's chapters use (profile, CSV links, captions, units)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import passmd
from passmd.model.parameters import paper_drive
from passmd.report import publish
from passmd.runtime import provenance


@pytest.fixture
def book(tmp_path):
    """A folder that looks like a book's source root, with a chapter subfolder."""
    (tmp_path / "_config.yml").write_text("title: t\n")
    (tmp_path / "_toc.yml").write_text("root: intro\n")
    (tmp_path / "part").mkdir()
    return tmp_path


# ----------------------------------------------------------------------------- profile


def test_profile_defaults_to_paper(monkeypatch):
    monkeypatch.delenv(publish.PROFILE_ENV, raising=False)
    assert publish.current_profile() == "paper"
    monkeypatch.setenv(publish.PROFILE_ENV, "  ")
    assert publish.current_profile() == "paper"


@pytest.mark.parametrize("profile", ["quick", "paper"])
def test_profile_from_environment(monkeypatch, profile):
    monkeypatch.setenv(publish.PROFILE_ENV, profile)
    assert publish.current_profile() == profile


def test_bad_profile_is_rejected_by_name(monkeypatch):
    monkeypatch.setenv(publish.PROFILE_ENV, "fast")
    with pytest.raises(ValueError, match=r"PASSMD_PROFILE = 'fast'.*'quick', 'paper'"):
        publish.current_profile()


# ----------------------------------------------------------------------------- data links


def test_book_root_found_from_a_chapter_folder(book, monkeypatch):
    monkeypatch.chdir(book / "part")
    assert publish.book_root() == book.resolve()
    assert publish.book_root(book / "part") == book.resolve()


def test_book_root_falls_back_to_start(tmp_path):
    assert publish.book_root(tmp_path) == tmp_path.resolve()


def test_data_link_writes_csv_and_returns_download_role(book, monkeypatch):
    monkeypatch.chdir(book / "part")
    monkeypatch.setenv(publish.PROFILE_ENV, "quick")
    df = pd.DataFrame({"amplitude_nm": [10.0, 20.5], "step_nm": [0.0, 3.25]})
    link = publish.data_link(df, "fig5a")
    target = book / "_generated" / "data" / "fig5a.csv"
    pd.testing.assert_frame_equal(pd.read_csv(target, comment="#"), df)
    # the header names version, commit and profile, as the caption does
    header = target.read_text(encoding="utf-8").splitlines()[:3]
    assert header == [f"# passmd_version: {passmd.__version__}",
                      f"# git_commit: {provenance.git_commit()}", "# profile: quick"]
    assert link == "{download}`fig5a.csv </_generated/data/fig5a.csv>`"
    assert link._repr_markdown_() == str(link)
    assert [p.name for p in target.parent.iterdir()] == ["fig5a.csv"]  # no temporary file left
    assert publish.data_link(df, "fig5a", label="data", root=book).startswith("{download}`data <")


@pytest.mark.parametrize("name", ["", "../up", "a/b", "fig.csv", "with space", 5])
def test_data_link_rejects_bad_names(book, name):
    with pytest.raises(ValueError, match="name = "):
        publish.data_link(pd.DataFrame({"x": [1]}), name, root=book)


def test_data_link_rejects_non_frames(book):
    with pytest.raises(ValueError, match="df = list"):
        publish.data_link([1, 2], "x", root=book)


# ----------------------------------------------------------------------------- units


@pytest.mark.parametrize(
    ("value", "unit", "expected"),
    [
        (202e-9, "nm", 202.0),
        (1e-6, "µm", 1.0),
        (3e-3, "g", 3.0),  # kg -> g
        (0.115, "mN", 115.0),
        (110e3, "kHz", 110.0),
        (0.019, "mm/s", 19.0),
        (1e-3, "mm", 1.0),
        (150e6, "V/µs", 150.0),
    ],
)
def test_to_unit_scales(value, unit, expected):
    # Only a power-of-ten scale is applied: agreement to round-off (1e-12 relative).
    assert publish.to_unit(value, unit) == pytest.approx(expected, rel=1e-12)


def test_to_unit_arrays():
    out = publish.to_unit([1e-9, 2e-9], "nm")
    np.testing.assert_allclose(out, [1.0, 2.0], rtol=1e-12)  # round-off only


def test_unknown_unit_is_rejected():
    with pytest.raises(ValueError, match="unit = 'furlongs/fortnight-ish'"):
        publish.to_unit(1.0, "furlongs/fortnight-ish")


def test_format_quantity():
    assert publish.format_quantity(202e-9, "nm") == "202 nm"
    assert publish.format_quantity(0.0123456, "N", digits=2) == "0.012 N"
    with pytest.raises(ValueError, match="must be a scalar"):
        publish.format_quantity([1.0, 2.0], "nm")


# ----------------------------------------------------------------------------- captions


def test_drive_parameters_name_the_run():
    params = publish.drive_parameters(paper_drive(1e-3, 0.4))
    assert params["R"] == "1 mm"
    assert params["F_p"] == "0.4 N"
    assert params["μ"] == "0.2"
    assert params["m_r"] == "3 g"
    assert params["actuators"] == "flexible" and "k_p" in params
    rigid = publish.drive_parameters(paper_drive(0.25e-3, 0.2, actuator_model="rigid", load_cell=True))
    assert rigid["R"] == "0.25 mm" and "k_p" not in rigid and rigid["k"] == "2.5e+04 N/m"


def test_caption_lists_parameters_profile_and_data(book, monkeypatch):
    monkeypatch.chdir(book)
    monkeypatch.setenv(publish.PROFILE_ENV, "quick")
    df = pd.DataFrame({"preload_N": [0.1, 0.2], "critical_amplitude_nm": [30.0, 45.0]})
    text = publish.caption("Critical amplitude (Fig. 5b).", drive=paper_drive(), data=df, name="fig5b",
                           frequency="100 Hz")
    assert text.startswith("**Figure.** Critical amplitude (Fig. 5b).")
    for part in ("R = 1 mm", "F_p = 0.4 N", "frequency = 100 Hz",
                 f"Made by passmd {passmd.__version__}, commit {provenance.git_commit()}, profile quick.",
                 "{download}`fig5b.csv </_generated/data/fig5b.csv>`"):
        assert part in text
    assert (book / "_generated" / "data" / "fig5b.csv").is_file()


def test_caption_needs_data_and_name_together(book):
    with pytest.raises(ValueError, match="data and name"):
        publish.caption("x", data=pd.DataFrame({"a": [1]}))
    with pytest.raises(ValueError, match="data and name"):
        publish.caption("x", name="a")


# ----------------------------------------------------------------------------- tables


def test_parameter_frame_side_by_side_in_display_units():
    big, small = paper_drive(1e-3), paper_drive(0.25e-3)
    df = publish.parameter_frame(big, small, labels=["1 mm", "0.25 mm"])
    assert list(df.columns) == ["parameter", "symbol", "1 mm", "0.25 mm", "unit", "source"]
    row = df.set_index("parameter")
    assert row.loc["hemisphere_radius", "unit"] == "mm"
    assert (row.loc["hemisphere_radius", "1 mm"], row.loc["hemisphere_radius", "0.25 mm"]) == ("1", "0.25")
    assert row.loc["runner_mass", "1 mm"] == "3" and row.loc["runner_mass", "unit"] == "g"
    assert row.loc["actuator.stiffness", "0.25 mm"] == "4e+06"  # Table 2, R = 0.25 mm
    assert row.loc["runner_material.youngs_modulus", "1 mm"] == "210"  # GPa, Table 1
    assert row.loc["actuator_model", "1 mm"] == "flexible"


def test_parameter_frame_rejects_bad_input():
    with pytest.raises(ValueError, match="records is empty"):
        publish.parameter_frame()
    with pytest.raises(ValueError, match="labels"):
        publish.parameter_frame(paper_drive(), labels=["a", "b"])
    with pytest.raises(ValueError, match="same type"):
        publish.parameter_frame(paper_drive(), paper_drive().amplifier)


def test_assumptions_frame_holds_every_assumption_in_the_tables_order():
    from passmd.report.assumptions import all_assumptions

    df = publish.assumptions_frame()
    assert list(df.columns) == ["key", "symbol", "value", "unit", "rationale", "sensitivity"]
    assert list(df["key"]) == list(all_assumptions())
    assert {"actuator_viscosity", "preload_grids"} <= set(df["key"])


@pytest.mark.parametrize(("symbol", "value", "unit", "shown"), [
    ("δ", "0.5", "nm", "δ = 0.5 nm"),
    ("μ", "0.2", "–", "μ = 0.2"),
    # a description: the unit belongs to the symbol, not to the description's last word
    ("c_p", "2·ζ·√(k_p m_a) with ζ = 0.05", "kg/s", "c_p [kg/s] = 2·ζ·√(k_p m_a) with ζ = 0.05"),
    ("–", "1024 reversal points", "–", "1024 reversal points"),
])
def test_assumption_value_shows_the_unit_once_and_on_the_symbol(symbol, value, unit, shown):
    assert publish.assumption_value(symbol, value, unit) == shown


def test_an_assumption_whose_value_ends_in_its_unit_is_refused():
    from passmd.model.tables import Assumption

    fields = {"key": "k", "symbol": "f", "rationale": "r", "sensitivity": "s"}
    for value, unit in (("1, 5, …, 130 kHz", "kHz"), ("R = 1 mm: 0.1–1.0 N; step 0.1 N", "N")):
        with pytest.raises(ValueError, match="ends in its unit"):
            Assumption(value=value, unit=unit, **fields)
    Assumption(value="over the last 16 periods", unit="s", **fields)  # "periods" does not end in " s"
    for row in publish.assumptions_frame().itertuples():  # and the registry renders no unit twice
        text = publish.assumption_value(row.symbol, row.value, row.unit)
        unit = re.escape(row.unit)
        assert row.unit in ("", "–") or not re.search(rf"(?<!\w){unit}\W+{unit}(?!\w)", text), text


def test_implementations_resolve_names_and_fail_on_stale_ones():
    df = publish.implementations({
        "Eq. (1)": "passmd.model.theory.normal_forces",
        "Eq. (6)": ["passmd.model.mdr_contact.MDRContact", "passmd.model.mdr_contact.MDRContact.path"],
    })
    assert list(df["implemented by"]) == [
        "passmd.model.theory.normal_forces", "passmd.model.mdr_contact.MDRContact",
        "passmd.model.mdr_contact.MDRContact.path"
    ]
    assert "Eq. 1" in df["summary"].iloc[0]
    with pytest.raises(ValueError, match="'no_such_function' not found"):
        publish.implementations({"Eq. (1)": "passmd.model.theory.no_such_function"})
    with pytest.raises(ValueError, match="no such module"):
        publish.implementations({"Eq. (1)": "nosuchpackage.f"})


#: Every chapter with code cells: they only call tested package functions and glue results.
GLUE_ONLY_CHAPTERS = tuple(sorted(
    path.stem for path in (Path(__file__).resolve().parents[1] / "book").glob("*.md")
    if "```{code-cell}" in path.read_text(encoding="utf-8")
))


@pytest.mark.parametrize("chapter", GLUE_ONLY_CHAPTERS)
def test_chapters_define_no_functions(chapter):
    """Analysis belongs in the package, where a test reaches it; a chapter only calls and glues."""
    import ast
    import re

    text = (Path(__file__).resolve().parents[1] / "book" / f"{chapter}.md").read_text()
    cells = re.findall(r"```\{code-cell\}[^\n]*\n(.*?)```", text, flags=re.S)
    assert cells, chapter
    for cell in cells:
        code = "\n".join(line for line in cell.splitlines() if not line.startswith(":tags:"))
        defined = [node for node in ast.walk(ast.parse(code))
                   if isinstance(node, (ast.FunctionDef, ast.Lambda, ast.ClassDef))]
        assert not defined, f"{chapter}: {[getattr(n, 'name', 'lambda') for n in defined]}"


def test_put_all_glues_numbers_and_text(monkeypatch):
    glued = {}
    monkeypatch.setattr(publish, "put", lambda name, value: glued.__setitem__(name, ("number", value)))
    monkeypatch.setattr(publish, "put_text", lambda name, text: glued.__setitem__(name, ("text", text)))
    publish.put_all({"a": 1.5, "b": "below"})
    assert glued == {"a": ("number", 1.5), "b": ("text", "below")}


def test_text_link_writes_the_text_as_is(book):
    text = "preload = 0.6\n# no provenance lines: passmd reads this file back\n"
    link = publish.text_link(text, "fitted-drive.toml", root=book)
    target = book / "_generated" / "data" / "fitted-drive.toml"
    assert target.read_text(encoding="utf-8") == text
    assert link == "{download}`fitted-drive.toml </_generated/data/fitted-drive.toml>`"
    assert [p.name for p in target.parent.iterdir()] == ["fitted-drive.toml"]  # no temporary file left
    for bad in ("../up.toml", "a/b.toml", ""):
        with pytest.raises(ValueError, match="filename = "):
            publish.text_link(text, bad, root=book)
    with pytest.raises(ValueError, match="text = bytes"):
        publish.text_link(b"x", "x.toml", root=book)


def test_figure_png_is_a_png_of_the_figure():
    from matplotlib.figure import Figure

    fig = Figure(figsize=(2, 1), dpi=100)
    fig.add_subplot().plot([0, 1], [1, 0])
    png = publish.figure_png(fig)
    assert png.startswith(b"\x89PNG\r\n\x1a\n")
    width, height = int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")
    assert 100 < width < 400 and 50 < height < 200  # 2 × 1 in at 100 dpi, box fitted to the content
    with pytest.raises(ValueError, match="fig = list"):
        publish.figure_png([1])
