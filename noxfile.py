"""Sessions: ``tests`` (pytest), ``book`` (executed Jupyter Book), ``book_check``
(rendered pages in headless Chromium), ``lint`` (ruff), ``benchmarks``.

Every session installs the package and its dependencies itself; a machine with
Python and nox needs nothing else. uv is used to create the environments when it is
installed (``pip install nox uv``), plain virtualenv otherwise.
"""

from __future__ import annotations

import os
import shutil
import tempfile
import time

import nox

nox.options.default_venv_backend = "uv|virtualenv"
nox.options.sessions = ["lint", "tests"]
nox.options.reuse_existing_virtualenvs = True

PYTHON = None  # the interpreter nox runs with
#: One simulation cache for tests and book (keys include a source fingerprint, so a code
#: change never serves stale results); CI's book build reuses what the tests computed.
CACHE_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), ".passmd-cache")


@nox.session(python=PYTHON)
def tests(session: nox.Session) -> None:
    """Run the test suite (unit, physics, regression, CLI and ledger tests)."""
    session.install("-e", ".[test]")
    session.run("pytest", *session.posargs, env={"MPLBACKEND": "Agg", "PASSMD_CACHE_DIR": CACHE_DIR})


@nox.session(python=PYTHON)
def lint(session: nox.Session) -> None:
    """ruff over the package, tests, book helpers, benchmarks and this file."""
    session.install("ruff>=0.6")
    session.run("ruff", "check", ".")


BOOK_HTML = "book/_build/html"
SCREENSHOTS = "artifacts/screenshots"


def _split_profile(args: list[str]) -> tuple[str, list[str]]:
    """Take ``--profile NAME`` (or ``--profile=NAME``) out of the session's arguments.

    Without it the profile is ``$PASSMD_PROFILE`` or ``paper``; the value is validated by
    ``passmd.publish.current_profile`` inside the session's environment.
    """
    profile = os.environ.get("PASSMD_PROFILE", "") or "paper"
    rest: list[str] = []
    it = iter(args)
    for arg in it:
        if arg == "--profile":
            profile = next(it, "")
        elif arg.startswith("--profile="):
            profile = arg.split("=", 1)[1]
        else:
            rest.append(arg)
    return profile, rest


@nox.session(python=PYTHON)
def book(session: nox.Session) -> None:
    """Build the executed Jupyter Book to book/_build/html (all pages, warnings are errors).

    ``nox -s book -- --profile quick`` builds on the quick profile (CI); default ``paper``.
    Every chapter is executed on every build (``execute_notebooks: force``); a cell error or
    any warning fails the build. Simulation results are reused from passmd's on-disk cache.
    ``-- --cold`` measures a cold build: empty simulation and numba caches (fresh temporary
    folders; your caches are left alone) and no previous build output.
    """
    session.install("-e", ".[book]")
    profile, args = _split_profile(list(session.posargs))
    cold = "--cold" in args
    args = [arg for arg in args if arg != "--cold"]
    # Chapter kernels must use Jupyter's inline backend (with e.g. MPLBACKEND=Agg inherited
    # from the shell, their figures would silently not be displayed).
    env = {"PASSMD_PROFILE": profile, "MPLBACKEND": "module://matplotlib_inline.backend_inline"}
    # Chapters run in book/; keep the simulation cache at the repository root, shared with
    # the CLI (`passmd figure` computes the same points), unless the user chose a place.
    env["PASSMD_CACHE_DIR"] = os.environ.get("PASSMD_CACHE_DIR") or os.path.abspath(".passmd-cache")
    # Validate the profile with the package's own check, and build matplotlib's font cache
    # now: its first-use notice on a fresh machine would otherwise be a stderr warning
    # inside the first chapter and fail the -W build.
    session.run(
        "python", "-c",
        "import matplotlib.pyplot; from passmd.publish import current_profile; "
        "print('book profile:', current_profile())",
        env=env,
    )
    scratch = None
    if cold:
        scratch = tempfile.mkdtemp(prefix="cold-build-", dir=session.create_tmp())
        env["PASSMD_CACHE_DIR"] = os.path.join(scratch, "passmd-cache")
        env["NUMBA_CACHE_DIR"] = os.path.join(scratch, "numba-cache")
        shutil.rmtree(os.path.join("book", "_build"), ignore_errors=True)
    start = time.monotonic()
    session.run("jupyter-book", "build", "book", "--all", "-W", "-n", "--keep-going", *args, env=env)
    elapsed = time.monotonic() - start
    session.log(f"book built in {elapsed:.0f} s wall time (profile {profile}{', cold' if cold else ''})")
    if scratch:
        shutil.rmtree(scratch, ignore_errors=True)


@nox.session(python=PYTHON)
def book_check(session: nox.Session) -> None:
    """Open the built book in headless Chromium and check every page (run ``book`` first).

    Checks each page of book/_toc.yml loads, shows its figures (decoded images), its ledger
    table, rendered math and no execution error; screenshots go to artifacts/screenshots/.
    Then shows on a deliberately broken tiny book that the check fails. Chromium and
    chromedriver come from the system packages (tools/install_chromium.sh installs them
    with apt when missing and run as root).
    """
    if not os.path.exists(os.path.join(BOOK_HTML, "index.html")):
        session.error(f"{BOOK_HTML}/index.html is missing: build the book first (nox -s book)")
    session.run("bash", "tools/install_chromium.sh", external=True)
    session.install("-e", ".[book,test]")
    session.run(
        "python", "tools/check_rendered_book.py", BOOK_HTML,
        "--toc", "book/_toc.yml", "--screenshots", SCREENSHOTS, *session.posargs,
    )
    session.run(
        "pytest", "tests/test_book_check.py", "-p", "no:cacheprovider",
        env={"PASSMD_REQUIRE_BROWSER": "1", "MPLBACKEND": "Agg"},
    )
