"""``jupyter-book build`` with Sphinx's parallel reading: ``python tools/build_book.py --jobs N ARGS``.

Jupyter Book 1.x builds through Sphinx but its command line has no ``-j``: its
``build_sphinx`` takes ``jobs`` and the command always passes the default (1). Reading a
page of this book means executing its chapter (myst-nb), and each chapter spends seconds
starting a kernel and importing numpy, pandas, matplotlib and numba before its first result;
with ``--jobs 2`` Sphinx reads (executes) two chapters at once in forked processes. Every
other argument goes to ``jupyter-book build`` unchanged.

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
from jupyter_book.cli import main as jupyter_book_cli
from nbclient import NotebookClient


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
    handle, lock_path = tempfile.mkstemp(prefix="passmd-kernel-start-", suffix=".lock")
    os.close(handle)
    serialize_kernel_starts(lock_path)
    try:
        jupyter_book_cli.main(["build", *rest], prog_name="jupyter-book")
    finally:
        os.unlink(lock_path)


if __name__ == "__main__":
    main(sys.argv[1:])
