"""Sessions: ``tests`` (pytest), ``book`` (executed Jupyter Book), ``book_check``
(rendered pages in headless Chromium), ``lint`` (ruff), ``benchmarks``.

Every session installs the package and its dependencies itself; a machine with
Python and nox needs nothing else. uv is used to create the environments when it is
installed (``pip install nox uv``), plain virtualenv otherwise.
"""

from __future__ import annotations

import os

import nox

nox.options.default_venv_backend = "uv|virtualenv"
nox.options.sessions = ["lint", "tests"]
nox.options.reuse_existing_virtualenvs = True

PYTHON = None  # the interpreter nox runs with


@nox.session(python=PYTHON)
def tests(session: nox.Session) -> None:
    """Run the test suite (unit, physics, regression, CLI and ledger tests)."""
    session.install("-e", ".[test]")
    session.run("pytest", *session.posargs, env={"MPLBACKEND": "Agg"})


@nox.session(python=PYTHON)
def lint(session: nox.Session) -> None:
    """ruff over the package, tests, book helpers, benchmarks and this file."""
    session.install("ruff>=0.6")
    session.run("ruff", "check", ".")


@nox.session(python=PYTHON)
def book(session: nox.Session) -> None:
    """Build the executed Jupyter Book to book/_build/html (all pages, warnings are errors)."""
    session.install("-e", ".[book]")
    env = {"MPLBACKEND": "Agg", "PASSMD_PROFILE": os.environ.get("PASSMD_PROFILE", "paper")}
    args = list(session.posargs)
    if "--profile" in args:
        i = args.index("--profile")
        env["PASSMD_PROFILE"] = args[i + 1]
        del args[i : i + 2]
    session.run("jupyter-book", "build", "book", "--all", "-W", "-n", "--keep-going", *args, env=env)
