"""The book's build wrapper (tools/build_book.py): chapters executed in parallel, failures kept.

``nox -s book`` runs ``jupyter-book build`` through ``tools/build_book.py --jobs N`` so that
Sphinx reads (executes) several chapters at once. These tests build a generated tiny book
with the book's own Sphinx extension: it must be read in parallel, and a chapter that writes
to stderr in a forked reader must still fail the ``-W`` build. They need jupyter-book and
are skipped without it, except under ``nox -s book_check`` (PASSMD_REQUIRE_BROWSER=1).
"""

from __future__ import annotations

import os
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
            code = "import sys; print('oops', file=sys.stderr)" if stderr_cell else "print(6 * 7)"
            body = header + body + "\n```{code-cell} ipython3\n" + code + "\n```\n"
        (folder / f"page{i}.md").write_text(body, encoding="utf-8")
    return folder


def _build(book: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, str(ROOT / "tools" / "build_book.py"), "--jobs", "2",
         str(book), "--all", "-W", "-n", "--keep-going"],
        capture_output=True, text=True, timeout=600,
        env={**os.environ, "MPLBACKEND": "module://matplotlib_inline.backend_inline"},
    )


def test_chapters_are_read_in_parallel(tmp_path):
    _require_jupyter_book()
    result = _build(_tiny_book(tmp_path / "good", stderr_cell=False))
    log = result.stdout + result.stderr
    assert result.returncode == 0, log[-3000:]
    assert "doing serial read" not in log
    # Sphinx names each parallel chunk by its first and last document, e.g. "index .. page2".
    assert " .. page" in log, log[-3000:]


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


_OVERLAP_PROBE = r"""
import asyncio, importlib.util, multiprocessing, sys, time
import nbformat
from nbclient import NotebookClient

spec = importlib.util.spec_from_file_location("build_book", sys.argv[1])
build_book = importlib.util.module_from_spec(spec)
spec.loader.exec_module(build_book)
lock_path, log_path, serialize = sys.argv[2], sys.argv[3], sys.argv[4] == "1"


async def fake_start_kernel(self, **kwargs):  # stands for picking the ports and launching
    self.started = time.monotonic()
    await asyncio.sleep(0.3)


async def fake_start_client(self):  # stands for binding the ports and answering kernel_info
    await asyncio.sleep(0.3)
    with open(log_path, "a") as log:
        log.write(f"{self.started} {time.monotonic()}\n")


NotebookClient.async_start_new_kernel = fake_start_kernel
NotebookClient.async_start_new_kernel_client = fake_start_client
if serialize:
    build_book.serialize_kernel_starts(lock_path)


async def start():
    client = NotebookClient(nbformat.v4.new_notebook())
    await client.async_start_new_kernel()
    await client.async_start_new_kernel_client()


def reader():
    asyncio.run(start())


if __name__ == "__main__":
    context = multiprocessing.get_context("fork")  # as Sphinx forks its parallel readers
    readers = [context.Process(target=reader) for _ in range(3)]
    for p in readers:
        p.start()
    for p in readers:
        p.join()
    sys.exit(max(p.exitcode for p in readers))
"""


def _kernel_start_intervals(tmp_path: Path, serialize: bool) -> list[tuple[float, float]]:
    probe = tmp_path / "probe.py"
    probe.write_text(_OVERLAP_PROBE, encoding="utf-8")
    log = tmp_path / f"starts-{serialize}.log"
    result = subprocess.run(
        [sys.executable, str(probe), str(ROOT / "tools" / "build_book.py"), str(tmp_path / "start.lock"),
         str(log), "1" if serialize else "0"],
        capture_output=True, text=True, timeout=60,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    intervals = sorted(tuple(map(float, line.split())) for line in log.read_text().splitlines())
    assert len(intervals) == 3
    return intervals


def test_kernel_starts_of_parallel_readers_do_not_overlap(tmp_path):
    """Three forked readers start a (stand-in) kernel at once: with the build wrapper's lock,
    each start runs from its choice of ports until its answer before the next begins, so two
    kernels never hold the same picked-but-unbound port; without the lock the starts overlap
    (the probe can tell)."""
    _require_jupyter_book()
    locked = _kernel_start_intervals(tmp_path, serialize=True)
    assert all(end <= next_start for (_, end), (next_start, _) in zip(locked, locked[1:], strict=False))
    free = _kernel_start_intervals(tmp_path, serialize=False)
    assert any(end > next_start for (_, end), (next_start, _) in zip(free, free[1:], strict=False))
