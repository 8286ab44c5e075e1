"""The book's build wrapper (tools/build_book.py) and extension (book/_ext/passmd_book.py).

``nox -s book`` runs ``jupyter-book build`` through ``tools/build_book.py --jobs N`` so that
Sphinx reads (executes) several chapters at once. These tests build a generated tiny book
with the book's own Sphinx extension: it must be read in parallel, a chapter that writes
to stderr in a forked reader must still fail the ``-W`` build, and an executed chapter that
ran a sweep ends with the generated Run time section. The extension's ``passmd-expect`` tag
follows the figure table and the ledger's claims. They need jupyter-book and are skipped
without it, except under ``nox -s book_check`` (PASSMD_REQUIRE_BROWSER=1).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = 7  # Sphinx reads in parallel only with more than five documents to read

pytestmark = pytest.mark.slow


def _require_jupyter_book() -> None:
    if (Path(sys.executable).parent / "jupyter-book").exists():
        return
    message = "the book build wrapper needs jupyter-book (run: nox -s book_check)"
    if os.environ.get("PASSMD_REQUIRE_BROWSER") == "1":
        pytest.fail(message)
    pytest.skip(message)


def _tiny_book(folder: Path, *, stderr_cell: bool) -> Path:
    folder.mkdir()
    ext = (ROOT / "book" / "_ext").as_posix()
    (folder / "_config.yml").write_text(
        "title: tiny\n"
        "execute:\n  execute_notebooks: force\n  stderr_output: warn\n"
        "sphinx:\n"
        "  extra_extensions: [sphinx-mathjax-offline, sphinx.ext.autodoc]\n"
        f"  local_extensions:\n    passmd_book: {ext}\n",
        encoding="utf-8",
    )
    toc = "format: jb-book\nroot: index\nchapters:\n" + "".join(f"- file: page{i}\n" for i in range(PAGES))
    (folder / "_toc.yml").write_text(toc, encoding="utf-8")
    (folder / "index.md").write_text("# Tiny\n", encoding="utf-8")
    header = ("---\njupytext:\n  text_representation:\n    extension: .md\n    format_name: myst\n"
              "kernelspec:\n  name: python3\n  display_name: Python 3\n---\n")
    for i in range(PAGES):
        body = f"# Page {i}\n\ntext\n"
        if i == PAGES - 1:
            code = "import sys; print('oops', file=sys.stderr)" if stderr_cell else SWEEP_CELL
            body = header + body + "\n```{code-cell} ipython3\n" + code + "\n```\n"
        (folder / f"page{i}.md").write_text(body, encoding="utf-8")
    return folder


#: A chapter's cell that runs a sweep of three points, logged where the book's extension points
#: the page's sweep log.
SWEEP_CELL = """from passmd.report.publish import book_config
from passmd.runtime.sweep import run
run(lambda x: {"y": x * x}, [{"x": 1}, {"x": 2}, {"x": 3}], executor="serial", cache=False,
    config=book_config())"""


def _build(book: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, str(ROOT / "tools" / "build_book.py"), "--jobs", "2",
         str(book), "--all", "-W", "-n", "--keep-going"],
        capture_output=True, text=True, timeout=600,
        env={**os.environ, "MPLBACKEND": "module://matplotlib_inline.backend_inline"},
    )


def test_chapters_are_read_in_parallel(tmp_path):
    _require_jupyter_book()
    book = _tiny_book(tmp_path / "good", stderr_cell=False)
    result = _build(book)
    log = result.stdout + result.stderr
    assert result.returncode == 0, log[-3000:]
    assert "doing serial read" not in log
    # Sphinx names each parallel chunk by its first and last document, e.g. "index .. page2".
    assert " .. page" in log, log[-3000:]
    # the executed page that ran a sweep ends with its Run time section; the others have none
    html = {i: (book / "_build" / "html" / f"page{i}.html").read_text(encoding="utf-8") for i in range(PAGES)}
    assert "Run time" in html[PAGES - 1]
    sweeps = "Its 1 simulation sweep(s) needed 3 points: 3 computed, 0 taken from the simulation cache"
    assert sweeps in html[PAGES - 1]
    assert not any("Run time" in html[i] for i in range(PAGES - 1))
    # no page of the tiny book is in the figure table: it expects no figure and no ledger
    assert all('<meta name="passmd-expect" content="figures=0 ledger=0 partial=0"' in page
               for page in html.values())


def _extension():
    _require_jupyter_book()
    sys.path.insert(0, str(ROOT / "book" / "_ext"))
    import passmd_book

    return passmd_book


def _expect(page: str) -> dict[str, int]:
    items = dict(item.partition("=")[::2] for item in _extension().expectation(page).split())
    return {key: int(items[key]) for key in ("figures", "ledger")}


def test_verdict_pages_of_a_quick_build_carry_the_partial_grid_note(monkeypatch):
    ext = _extension()

    def note(page):
        for cached in (ext.partial_grid_note, ext.expectation):
            cached.cache_clear()
        found = ext.partial_grid_note(page, "intro")
        return None if found is None else " ".join([found[1], *found[2]])

    try:
        monkeypatch.setenv("PASSMD_PROFILE", "quick")
        text = note("critical_amplitude_one")
        # computed from the figures' grids: fig5a's amplitudes, fig5b's preloads and frequencies
        pattern = r"fig5a: \d+ of the paper profile's \d+ points \(amplitudes\), \d+ missing"
        assert re.search(pattern, text), text
        assert "fig5b" in text and "nox -s book" in text
        assert note("intro") is not None and note(ext.LEDGER_PAGE) is not None  # headline, whole ledger
        assert note("api") is None and note("model") is None  # no verdicts there
        assert "partial=1" in ext.expectation("waveform_velocity", "intro")
        monkeypatch.setenv("PASSMD_PROFILE", "paper")
        assert note("critical_amplitude_one") is None
        assert "partial=0" in ext.expectation("waveform_velocity", "intro")
    finally:
        for cached in (ext.partial_grid_note, ext.expectation):
            cached.cache_clear()


def test_a_page_expects_its_rows_of_the_figure_table():
    from passmd.experiments.figure_table import FIGURES

    for chapter in {spec.chapter for spec in FIGURES}:
        assert _expect(chapter)["figures"] == sum(spec.chapter == chapter for spec in FIGURES)
    assert _expect("api") == {"figures": 0, "ledger": 0}  # a page without figures
    assert _expect(_extension().LEDGER_PAGE)["ledger"] == 1  # the whole ledger


def test_a_page_expects_a_ledger_where_the_ledger_judges_claims_of_its_figures():
    from passmd.experiments.figure_table import FIGURES, READING_TABLES
    from passmd.ledger.claims import load_claims

    chapter_of = {spec.name: spec.chapter for spec in FIGURES}
    judged = set()
    for requires in load_claims()["requires"]:
        for key in filter(None, requires.split(";")):
            for figure in READING_TABLES[key].figures if key in READING_TABLES else (key,):
                judged.add(chapter_of.get(figure))
    judged.discard(None)
    assert judged  # the ledger judges some chapter's figures
    for chapter in set(chapter_of.values()):
        assert _expect(chapter)["ledger"] == (chapter in judged), chapter


def test_a_warning_in_a_parallel_reader_fails_the_build(tmp_path):
    _require_jupyter_book()
    result = _build(_tiny_book(tmp_path / "bad", stderr_cell=True))
    log = result.stdout + result.stderr
    assert result.returncode != 0
    assert "stderr was found in the cell outputs" in log, log[-3000:]


def test_jobs_must_be_positive():
    _require_jupyter_book()
    result = subprocess.run([sys.executable, str(ROOT / "tools" / "build_book.py"), "--jobs", "0", "book"],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 2
    assert "--jobs = 0 is out of range" in result.stderr


def _lock_is_held(lock_path: Path) -> bool:
    """Whether some open file holds the exclusive lock on ``lock_path`` (flock locks belong to
    an open file, so a second open of the file in the same process contends for it too)."""
    import fcntl

    with open(lock_path, "a") as probe:
        try:
            fcntl.flock(probe, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            return True
        fcntl.flock(probe, fcntl.LOCK_UN)
        return False


def test_kernel_start_holds_the_lock_from_the_choice_of_ports_until_the_answer(tmp_path, monkeypatch):
    """The build wrapper's lock (what keeps two forked readers from picking the same
    picked-but-unbound port) is held while a kernel picks its ports and while its client starts,
    is released once the client has answered, and is released too when the start fails."""
    _require_jupyter_book()
    import asyncio
    import importlib.util

    import nbformat
    from nbclient import NotebookClient

    spec = importlib.util.spec_from_file_location("build_book", ROOT / "tools" / "build_book.py")
    build_book = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(build_book)
    lock_path = tmp_path / "start.lock"
    seen = []

    async def start_kernel(self, **kwargs):  # stands for picking the ports and launching
        seen.append(("kernel", _lock_is_held(lock_path)))
        if kwargs.get("fail"):
            raise RuntimeError("kernel died")

    async def start_client(self):  # stands for binding the ports and answering kernel_info
        seen.append(("client", _lock_is_held(lock_path)))

    monkeypatch.setattr(NotebookClient, "async_start_new_kernel", start_kernel)
    monkeypatch.setattr(NotebookClient, "async_start_new_kernel_client", start_client)
    build_book.serialize_kernel_starts(str(lock_path))

    async def start(fail=False):
        client = NotebookClient(nbformat.v4.new_notebook())
        await client.async_start_new_kernel(fail=fail)
        await client.async_start_new_kernel_client()

    asyncio.run(start())
    assert seen == [("kernel", True), ("client", True)]
    assert not _lock_is_held(lock_path)
    with pytest.raises(RuntimeError, match="kernel died"):
        asyncio.run(start(fail=True))
    assert seen[-1] == ("kernel", True)
    assert not _lock_is_held(lock_path)
