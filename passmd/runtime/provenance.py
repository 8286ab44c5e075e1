"""Provenance of a result: which ``passmd`` version, git commit and profile made it.

Every figure caption (:func:`passmd.report.publish.caption`), every CSV file the book or
``passmd figure`` writes, and the book's footer carry the same three facts, so a figure
or a data file found on its own says what produced it:

* the version, :data:`passmd.__version__` (its one source);
* the git commit of the source tree the package was imported from, ``"<hash> (uncommitted
  changes)"`` when tracked or new files differ from that commit, and, when the package is not
  imported from a git checkout (an installed wheel) or git is unavailable, ``"none: installed
  package, version X"`` (:func:`commit_or_version`), so a result found on its own still says
  which release made it;
* the build profile (``quick`` or ``paper``).

The commit is looked up once per process (:func:`git_commit` is cached): a running
process does not change its own source.
"""

from __future__ import annotations

import subprocess
from functools import cache
from pathlib import Path

import passmd
from passmd.runtime.config import PROFILES
from passmd.runtime.validation import check_choice

__all__ = ["UNKNOWN", "UNCOMMITTED", "commit_or_version", "csv_header", "git_commit", "stamp", "summary"]

#: The commit when it cannot be known (no git, or not imported from a git checkout).
UNKNOWN = "unknown"
#: Appended to the commit when the working tree differs from it.
UNCOMMITTED = "uncommitted changes"

_PACKAGE_DIR = Path(passmd.__file__).resolve().parent


def _git(args: list[str], cwd: Path) -> str | None:
    try:
        result = subprocess.run(
            ["git", *args], cwd=cwd, capture_output=True, text=True, timeout=20, check=False
        )
    except (OSError, subprocess.SubprocessError):  # git missing, not executable, hung
        return None
    return result.stdout.strip() if result.returncode == 0 else None


@cache
def git_commit(package_dir: str | None = None) -> str:
    """The git commit of the source tree ``passmd`` was imported from.

    Parameters
    ----------
    package_dir : str, optional
        The package folder to describe; default the imported package's own folder.

    Returns
    -------
    str
        The full commit hash; ``"<hash> (uncommitted changes)"`` when ``git status`` lists
        changed or new (not ignored) files; :data:`UNKNOWN` when the folder is not the
        ``passmd/`` folder at the top of a git work tree (e.g. an installed wheel inside
        ``site-packages``, even if that lies inside some other repository) or git fails.
    """
    folder = Path(package_dir).resolve() if package_dir is not None else _PACKAGE_DIR
    top = _git(["rev-parse", "--show-toplevel"], folder)
    if top is None or Path(top).resolve() != folder.parent:
        return UNKNOWN
    commit = _git(["rev-parse", "HEAD"], folder.parent)
    if not commit:
        return UNKNOWN
    status = _git(["status", "--porcelain"], folder.parent)
    if status is None:
        return UNKNOWN
    return f"{commit} ({UNCOMMITTED})" if status else commit


def commit_or_version() -> str:
    """:func:`git_commit`, or ``"none: installed package, version X"`` where it is unknown."""
    commit = git_commit()
    return commit if commit != UNKNOWN else f"none: installed package, version {passmd.__version__}"


def stamp(profile: str) -> dict[str, str]:
    """``{"passmd_version", "git_commit", "profile"}`` of a result made on ``profile``."""
    return {
        "passmd_version": passmd.__version__,
        "git_commit": commit_or_version(),
        "profile": check_choice("profile", profile, PROFILES),
    }


def summary(profile: str) -> str:
    """One line for captions and the footer, e.g. ``passmd 0.1.0, commit 1a2b…, profile quick``."""
    facts = stamp(profile)
    return f"passmd {facts['passmd_version']}, commit {facts['git_commit']}, profile {facts['profile']}"


def csv_header(profile: str) -> str:
    """``#`` comment lines written above a CSV table (read it with ``pandas.read_csv(comment="#")``)."""
    return "".join(f"# {key}: {value}\n" for key, value in stamp(profile).items())
