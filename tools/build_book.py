"""``jupyter-book build`` with Sphinx's parallel reading: ``python tools/build_book.py --jobs N ARGS``.

Jupyter Book 1.x builds through Sphinx but its command line has no ``-j``: its
``build_sphinx`` takes ``jobs`` and the command always passes the default (1). Reading a
page of this book means executing its chapter (myst-nb), and each chapter spends seconds
starting a kernel and importing numpy, pandas, matplotlib and numba before its first result;
with ``--jobs 2`` Sphinx reads (executes) two chapters at once in forked processes. Every
other argument goes to ``jupyter-book build`` unchanged.
"""

from __future__ import annotations

import argparse
import functools
import sys

import jupyter_book.sphinx
from jupyter_book.cli import main as jupyter_book_cli


def main(argv: list[str]) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0], add_help=False)
    parser.add_argument("--jobs", type=int, default=1)
    options, rest = parser.parse_known_args(argv)
    if options.jobs < 1:
        parser.error(f"--jobs = {options.jobs} is out of range: must be an integer >= 1")
    # The build command imports build_sphinx from jupyter_book.sphinx when it runs.
    jupyter_book.sphinx.build_sphinx = functools.partial(jupyter_book.sphinx.build_sphinx, jobs=options.jobs)
    jupyter_book_cli.main(["build", *rest], prog_name="jupyter-book")


if __name__ == "__main__":
    main(sys.argv[1:])
