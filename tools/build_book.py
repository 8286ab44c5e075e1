"""``jupyter-book build`` with Sphinx's parallel reading: ``python tools/build_book.py --jobs N ARGS``.

Jupyter Book 1.x builds through Sphinx but its command line has no ``-j``: its
``build_sphinx`` takes ``jobs`` and the command always passes the default (1). Reading a
page of this book means executing its chapter (myst-nb), and each chapter spends seconds
starting a kernel and importing numpy, pandas, matplotlib and numba before its first result;
with ``--jobs 2`` Sphinx reads (executes) two chapters at once in forked processes. Every
other argument goes to ``jupyter-book build`` unchanged.

Sphinx cuts the sorted documents into one fixed run per reader, so one reader can get most of
the long chapters while the other idles. Each document is its own chunk here instead, taken by
whichever reader is free, the longest chapters first (:data:`LONGEST_FIRST`, list scheduling):
the readers finish within about one short chapter of each other.

Kernels start one at a time. A Jupyter client picks a kernel's five TCP ports by binding and
releasing them, and the kernel binds them again only once it has started; two readers that
start kernels at the same moment can pick the same port, and one kernel then dies with
"Address already in use" (a known race of the Jupyter protocol, e.g. nteract/papermill#511).
A file lock held from the choice of ports until the kernel has answered serialises the starts
across the forked readers; the chapters still execute in parallel.
"""

from __future__ import annotations

import argparse
import fcntl
import functools
import os
import sys
import tempfile

import jupyter_book.sphinx
import sphinx.builders
from jupyter_book.cli import main as jupyter_book_cli
from nbclient import NotebookClient
from sphinx.util.parallel import make_chunks

#: The chapters that take longest to execute (their run times on the book's execution statistics
#: page), longest first: read first when chapters are read in parallel. Only the order of reading
#: depends on it; a name that is no chapter is ignored.
LONGEST_FIRST = ("calibration", "model_numerics", "waveform_optimum", "design_your_drive", "force_generation",
                 "critical_amplitude_six")


def longest_first_chunks(docnames, nproc: int, maxbatch: int = 10) -> list[list[str]]:
    """Sphinx's ``make_chunks`` for reading: one document per chunk, :data:`LONGEST_FIRST` first, the
    others in Sphinx's order (``nproc`` and ``maxbatch`` do not apply)."""
    rank = {name: i for i, name in enumerate(LONGEST_FIRST)}
    return [[name] for name in sorted(docnames, key=lambda name: rank.get(name, len(rank)))]


def read_longest_first() -> None:
    """Make Sphinx's parallel reading take :func:`longest_first_chunks` (writing keeps Sphinx's chunks)."""
    read_parallel = sphinx.builders.Builder._read_parallel

    def _read_parallel(self, docnames, nproc):
        sphinx.builders.make_chunks = longest_first_chunks  # (the builder module's reference to it)
        try:
            return read_parallel(self, docnames, nproc)
        finally:
            sphinx.builders.make_chunks = make_chunks

    sphinx.builders.Builder._read_parallel = _read_parallel


def serialize_kernel_starts(lock_path: str) -> None:
    """Hold an exclusive lock on ``lock_path`` from a kernel's start until it has answered.

    Patches :class:`nbclient.NotebookClient` (which myst-nb executes chapters with) in this
    process and in the readers Sphinx forks from it.
    """
    start_kernel = NotebookClient.async_start_new_kernel
    start_client = NotebookClient.async_start_new_kernel_client

    def release(client) -> None:
        handle = client.__dict__.pop("_passmd_start_lock", None)
        if handle is not None:
            handle.close()  # (closing the file releases its lock)

    async def locked_start_kernel(self, **kwargs):
        handle = open(lock_path, "a")  # (held until the kernel client has started)
        fcntl.flock(handle, fcntl.LOCK_EX)
        self.__dict__["_passmd_start_lock"] = handle
        try:
            await start_kernel(self, **kwargs)
        except BaseException:
            release(self)
            raise

    async def locked_start_client(self):
        try:
            return await start_client(self)
        finally:
            release(self)

    NotebookClient.async_start_new_kernel = locked_start_kernel
    NotebookClient.async_start_new_kernel_client = locked_start_client


def main(argv: list[str]) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0], add_help=False)
    parser.add_argument("--jobs", type=int, default=1)
    options, rest = parser.parse_known_args(argv)
    if options.jobs < 1:
        parser.error(f"--jobs = {options.jobs} is out of range: must be an integer >= 1")
    # The build command imports build_sphinx from jupyter_book.sphinx when it runs.
    jupyter_book.sphinx.build_sphinx = functools.partial(jupyter_book.sphinx.build_sphinx, jobs=options.jobs)
    read_longest_first()
    handle, lock_path = tempfile.mkstemp(prefix="passmd-kernel-start-", suffix=".lock")
    os.close(handle)
    serialize_kernel_starts(lock_path)
    try:
        jupyter_book_cli.main(["build", *rest], prog_name="jupyter-book")
    finally:
        os.unlink(lock_path)


if __name__ == "__main__":
    main(sys.argv[1:])
