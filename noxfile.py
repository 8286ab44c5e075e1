"""Sessions: ``tests`` (pytest), ``benchmarks_smoke`` (every benchmark's ``--smoke``), ``wheel``
(the built wheel installed and run outside the repository), ``citation`` (CITATION.cff against
its schema), ``book`` (executed Jupyter Book), ``book_check`` (rendered pages in headless
Chromium), ``lint`` (ruff).

Every session installs the package and its dependencies itself; a machine with
Python and nox needs nothing else. uv is used to create the environments when it is
installed (``pip install nox uv``), plain virtualenv otherwise.
"""

from __future__ import annotations

import glob
import json
import os
import shutil
import subprocess
import tempfile
import time
import zipfile

import nox

nox.options.default_venv_backend = "uv|virtualenv"
nox.options.sessions = ["lint", "tests"]
nox.options.reuse_existing_virtualenvs = True

PYTHON = None  # the interpreter nox runs with
#: One simulation cache for tests and book (keys include a source fingerprint, so a code
#: change never serves stale results); CI's book build reuses what the tests computed.
CACHE_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), ".passmd-cache")


def _bytecode_cache(folder: str) -> dict:
    """Environment of Pythons that keep their bytecode in ``folder`` (absolute, so a subprocess in
    another working folder finds it): of many Pythons importing the same modules only the first
    compiles them, also where the environment turned the cache off (PYTHONDONTWRITEBYTECODE), and
    no folder but ``folder`` is written."""
    return {"PYTHONDONTWRITEBYTECODE": "", "PYTHONPYCACHEPREFIX": os.path.abspath(folder)}


@nox.session(python=PYTHON)
def tests(session: nox.Session) -> None:
    """Run the test suite (unit, physics, regression, CLI and ledger tests)."""
    session.install("-e", ".[test]")
    # the command-line tests start hundreds of Pythons
    env = {"MPLBACKEND": "Agg", "PASSMD_CACHE_DIR": CACHE_DIR,
           **_bytecode_cache(os.path.join(session.create_tmp(), "pycache"))}
    session.run("pytest", *session.posargs, env=env)


@nox.session(python=PYTHON)
def benchmarks_smoke(session: nox.Session) -> None:
    """Run every script of ``benchmarks/`` with ``--smoke``: its real code once on its smallest
    input, seconds each, written to a temporary file; a broken default fails the session.

    Run it after ``tests``: ``bench_ledger.py --smoke`` reads the quick ledger from the
    simulation cache the tests filled. The times it prints are no measurements.
    """
    # the tests session's install; nox for bench_book.py, which lists the book session
    session.install("-e", ".[test]", "nox>=2024.10")
    # the scripts' temporary outputs land in the session's folder, not the system's
    env = {"MPLBACKEND": "Agg", "PASSMD_CACHE_DIR": CACHE_DIR, "TMPDIR": session.create_tmp()}
    for script in sorted(glob.glob(os.path.join("benchmarks", "*.py"))):
        start = time.monotonic()
        session.run("python", script, "--smoke", env=env, silent=True)
        session.log(f"{script} --smoke: {time.monotonic() - start:.1f} s")


@nox.session(python=PYTHON)
def lint(session: nox.Session) -> None:
    """ruff over the package, tests, book helpers, benchmarks and this file; the layer contracts.

    ``lint-imports`` checks the import-linter contracts of ``pyproject.toml`` (the package's
    layers and no import cycle) on the source tree; it imports nothing of the package.
    """
    session.install("ruff>=0.6", "import-linter>=2.16")
    session.run("ruff", "check", ".")
    session.run("lint-imports", "--no-cache")


@nox.session(python=PYTHON)
def wheel(session: nox.Session) -> None:
    """Build the wheel and sdist, install the wheel into a fresh environment and run it.

    The wheel must hold every tracked file of ``passmd/`` (modules and package data) and the
    LICENSE; installed into a new virtual environment (dependencies from PyPI only), it must
    run ``tools/check_installed_wheel.py`` from a temporary folder outside the repository:
    ``passmd --version``, ``passmd theory --json``, the ledger's and reference curves'
    loaders, ``passmd ledger --profile quick --json`` (reading the simulation cache the tests
    filled, ``CACHE_DIR``) and ``passmd figure fig9a --profile quick``. Nothing is installed
    editable.
    """
    repo = os.path.dirname(os.path.abspath(__file__))
    session.install("build>=1.2", "virtualenv>=20.26")
    # outside the repository (not in .nox/): nothing of the checkout can be picked up by accident
    work = tempfile.mkdtemp(prefix="passmd-wheel-")
    try:
        _build_and_check_wheel(session, repo, work)
    finally:
        shutil.rmtree(work, ignore_errors=True)


def _build_and_check_wheel(session: nox.Session, repo: str, work: str) -> None:
    dist = os.path.join(work, "dist")
    uv = shutil.which("uv")
    installer = ["--installer", "uv"] if uv else []
    # No --sdist/--wheel: build makes the sdist, then the wheel from the unpacked sdist, so a
    # file missing from the sdist is missing from the wheel too and fails below.
    session.run("python", "-m", "build", "--outdir", dist, *installer, repo)
    (wheel_file,) = glob.glob(os.path.join(dist, "passmd-*.whl"))
    (sdist_file,) = glob.glob(os.path.join(dist, "passmd-*.tar.gz"))
    session.log(f"built {os.path.basename(wheel_file)} and {os.path.basename(sdist_file)}")
    tracked = subprocess.run(
        ["git", "ls-files", "passmd"], cwd=repo, capture_output=True, text=True, check=True
    ).stdout.split()
    with zipfile.ZipFile(wheel_file) as archive:
        names = set(archive.namelist())
    missing = [path for path in tracked if path not in names]
    if missing:
        session.error(f"the wheel lacks {len(missing)} package file(s): {', '.join(missing)}")
    if not any(name.endswith(".dist-info/licenses/LICENSE") for name in names):
        session.error("the wheel lacks the LICENSE file")
    # A fresh environment outside nox's: only the wheel and its dependencies from PyPI.
    venv = os.path.join(work, "venv")
    if uv:
        session.run(uv, "venv", "--quiet", "--python", os.path.join(session.bin, "python"),
                    venv, external=True)
        python = os.path.join(venv, "bin", "python")
        session.run(uv, "pip", "install", "--quiet", "--python", python, wheel_file, external=True)
    else:
        session.run("python", "-m", "virtualenv", "--quiet", venv)
        python = os.path.join(venv, "bin", "python")
        session.run(python, "-m", "pip", "install", "--quiet", wheel_file, external=True)
    outside = os.path.join(work, "outside")
    os.makedirs(outside)
    checker = os.path.join(repo, "tools", "check_installed_wheel.py")
    with session.chdir(outside):
        session.run(python, "-I", checker, "--repo", repo, "--ledger-cache", CACHE_DIR, external=True,
                    env={"MPLBACKEND": "Agg", "PASSMD_CACHE_DIR": os.path.join(outside, ".passmd-cache"),
                         "PYTHONPATH": ""})


@nox.session(python=PYTHON)
def citation(session: nox.Session) -> None:
    """Validate CITATION.cff against the Citation File Format schema (cffconvert --validate)."""
    session.install("cffconvert>=2.0,<3")
    session.run("cffconvert", "--validate", "--infile", "CITATION.cff")
    session.run("cffconvert", "--format", "bibtex", "--infile", "CITATION.cff")


BOOK_HTML = "book/_build/html"
SCREENSHOTS = "artifacts/screenshots"


def _split_profile(args: list[str]) -> tuple[str, list[str]]:
    """Take ``--profile NAME`` (or ``--profile=NAME``) out of the session's arguments.

    Without it the profile is ``$PASSMD_PROFILE`` or ``paper``; the value is validated by
    ``passmd.report.publish.current_profile`` inside the session's environment.
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
    any warning fails the build. Simulation results are reused from passmd's on-disk cache,
    which ``passmd ledger`` fills first (every table a claim reads); the chapters then run one per core.
    ``-- --cold`` measures a cold build: empty simulation and numba caches (fresh temporary
    folders; your caches are left alone) and no previous build output. The bytecode of the
    installed modules belongs to the environment, as pip's does to site-packages (it is kept in
    the session's folder): a cold build measures passmd's work, not Python compiling numpy,
    scipy, pandas, matplotlib, numba and Sphinx, which only the first build after an install pays.
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
    # every chapter is a fresh kernel importing the same thousand modules; beside the environment,
    # not in book/_build, which --cold empties
    env.update(_bytecode_cache(os.path.join(session.create_tmp(), "pycache")))
    # Validate the profile with the package's own check, and build matplotlib's font cache
    # now: its first-use notice on a fresh machine would otherwise be a stderr warning
    # inside the first chapter and fail the -W build.
    session.run(
        "python", "-c",
        "import matplotlib.pyplot; from passmd.report.publish import current_profile; "
        "print('book profile:', current_profile())",
        env=env,
    )
    scratch = None
    if cold:
        # Absolute: the chapters run in book/, the prefetch in the repository root.
        scratch = os.path.abspath(tempfile.mkdtemp(prefix="cold-build-", dir=session.create_tmp()))
        env["PASSMD_CACHE_DIR"] = os.path.join(scratch, "passmd-cache")
        env["NUMBA_CACHE_DIR"] = os.path.join(scratch, "numba-cache")
        shutil.rmtree(os.path.join("book", "_build"), ignore_errors=True)
    start = time.monotonic()
    # Every figure's sweeps first, in one process whose sweeps keep every core busy
    # (`passmd ledger` evaluates every claim, hence computes every table a claim reads); the chapters
    # then take their results from the cache and are executed several at a time (Sphinx's
    # parallel reading, tools/build_book.py). The ledger's sweep counts are the first row
    # of the book's execution statistics.
    build_dir = os.path.join("book", "_build")
    os.makedirs(build_dir, exist_ok=True)
    prefetch_log = os.path.abspath(os.path.join(build_dir, "passmd-prefetch.jsonl"))
    prefetch_time = os.path.abspath(os.path.join(build_dir, "passmd-prefetch-time.json"))
    ledger_file = os.path.abspath(os.path.join(build_dir, "passmd-ledger.pmc"))
    for old in (prefetch_log, prefetch_time, ledger_file):
        if os.path.exists(old):
            os.remove(old)
    session.log(f"computing every table the claims read ({profile} profile) first (passmd ledger)")
    # The whole ledger, evaluated once, is written for every chapter (each shows its rows judged in it).
    session.run("python", "-m", "passmd", "ledger", "--profile", profile, "--json",
                "--write-evaluation", ledger_file, silent=True, env={**env, "PASSMD_SWEEP_LOG": prefetch_log})
    with open(prefetch_time, "w", encoding="utf-8") as fh:
        json.dump({"wall_seconds": time.monotonic() - start}, fh)
    env["PASSMD_BOOK_PREFETCH_LOG"] = prefetch_log
    env["PASSMD_BOOK_PREFETCH_TIME"] = prefetch_time
    env["PASSMD_BOOK_LEDGER"] = ledger_file
    session.run("python", "tools/build_book.py", "--jobs", str(os.cpu_count() or 1),
                "book", "--all", "-W", "-n", "--keep-going", *args, env=env)
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
        "pytest", "tests/test_book_check.py", "tests/test_build_book.py", "tests/test_replication_report.py",
        "-p", "no:cacheprovider",
        env={"PASSMD_REQUIRE_BROWSER": "1", "MPLBACKEND": "Agg"},
    )
