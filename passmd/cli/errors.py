"""The command line's errors and the exit status each one gives."""

from __future__ import annotations

__all__ = ["OPTIONAL_EXTRAS", "MissingDependencyError", "NotAvailableError", "OutputError", "UsageError"]

#: Optional dependencies: importable module -> the passmd extra that installs it.
OPTIONAL_EXTRAS = {"distributed": "dask", "dask": "dask"}


class UsageError(ValueError):
    """A user error found after argument parsing (exit status 2)."""


class NotAvailableError(UsageError):
    """A name (figure panel) the package does not provide (exit status 2)."""


class MissingDependencyError(RuntimeError):
    """An optional dependency is not installed (exit status 1)."""


class OutputError(RuntimeError):
    """An output file could not be written (exit status 1)."""
