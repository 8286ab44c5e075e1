"""passmd.runtime.provenance: version, git commit and profile of a result, found robustly."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

import passmd
from passmd.runtime import provenance

GIT = shutil.which("git")
needs_git = pytest.mark.skipif(GIT is None, reason="git is not installed")


def _git(cwd: Path, *args: str) -> str:
    return subprocess.run([GIT, *args], cwd=cwd, check=True, capture_output=True, text=True).stdout.strip()


@pytest.fixture
def checkout(tmp_path):
    """A git work tree whose top holds a ``passmd/`` folder, committed."""
    (tmp_path / "passmd").mkdir()
    (tmp_path / "passmd" / "__init__.py").write_text("__version__ = '0'\n")
    _git(tmp_path, "init", "-q")
    _git(tmp_path, "add", ".")
    _git(tmp_path, "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-q", "-m", "x")
    return tmp_path


@needs_git
def test_clean_checkout_gives_its_commit(checkout):
    commit = provenance.git_commit(str(checkout / "passmd"))
    assert commit == _git(checkout, "rev-parse", "HEAD") and len(commit) == 40


@needs_git
@pytest.mark.parametrize("change", ["edit", "new file"])
def test_changed_tree_says_uncommitted_changes(checkout, change):
    if change == "edit":
        (checkout / "passmd" / "__init__.py").write_text("__version__ = '1'\n")
    else:
        (checkout / "passmd" / "extra.py").write_text("")
    head = _git(checkout, "rev-parse", "HEAD")
    assert provenance.git_commit(str(checkout / "passmd")) == f"{head} (uncommitted changes)"


@needs_git
def test_package_inside_another_repository_is_unknown(checkout):
    # e.g. a wheel installed into a virtualenv that lies inside some git work tree
    site = checkout / "venv" / "lib" / "site-packages" / "passmd"
    site.mkdir(parents=True)
    assert provenance.git_commit(str(site)) == provenance.UNKNOWN


def test_no_git_checkout_is_unknown(tmp_path):
    (tmp_path / "passmd").mkdir()
    assert provenance.git_commit(str(tmp_path / "passmd")) == provenance.UNKNOWN


def test_missing_git_executable_is_unknown(checkout, monkeypatch):
    monkeypatch.setenv("PATH", str(checkout / "no-such-bin"))
    assert provenance.git_commit(str(checkout / "passmd")) == provenance.UNKNOWN


def test_commit_is_looked_up_once_per_process():
    provenance.git_commit()
    hits = provenance.git_commit.cache_info().hits
    provenance.git_commit()
    assert provenance.git_commit.cache_info().hits == hits + 1


def test_stamp_summary_and_csv_header():
    stamp = provenance.stamp("quick")
    assert stamp == {"passmd_version": passmd.__version__, "git_commit": provenance.git_commit(),
                     "profile": "quick"}
    assert provenance.summary("paper") == (
        f"passmd {passmd.__version__}, commit {provenance.git_commit()}, profile paper")
    assert provenance.csv_header("quick").splitlines() == [
        f"# passmd_version: {passmd.__version__}", f"# git_commit: {provenance.git_commit()}",
        "# profile: quick"]
    with pytest.raises(ValueError, match="profile = 'fast'"):
        provenance.stamp("fast")


def test_an_installed_package_names_its_version_for_the_commit(monkeypatch):
    """A wheel has no git checkout: its results say which release made them."""
    monkeypatch.setattr(provenance, "git_commit", lambda: provenance.UNKNOWN)
    expected = f"none: installed package, version {passmd.__version__}"
    assert provenance.commit_or_version() == expected
    assert provenance.stamp("quick")["git_commit"] == expected
    assert f"commit {expected}" in provenance.summary("quick")
