"""Packaging: one source for the version, license and citation files, package data declared.

The installed wheel itself is exercised by ``nox -s wheel``; CITATION.cff is validated
against the Citation File Format schema by ``nox -s citation`` (cffconvert --validate).
"""

from __future__ import annotations

from importlib import metadata
from pathlib import Path

import pytest
import yaml

import passmd

ROOT = Path(__file__).resolve().parents[1]
tomllib = pytest.importorskip("tomllib")  # Python >= 3.11


def test_installed_version_is_the_packages():
    """The installed metadata reports the version the package itself reports (one source)."""
    assert metadata.version("passmd") == passmd.__version__


def test_installed_metadata_carries_the_license():
    """The installed distribution declares the MIT license expression and ships its text."""
    declared = metadata.metadata("passmd")
    assert declared["License-Expression"] == "MIT"
    assert declared.get_all("License-File") == ["LICENSE"]
    assert (ROOT / "LICENSE").read_text(encoding="utf-8").startswith("MIT License")


def test_citation_and_changelog_name_this_version():
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    assert cff["version"] == passmd.__version__
    assert cff["type"] == "software" and cff["license"] == "MIT"
    (paper,) = cff["references"]
    assert paper["doi"] == "10.3390/coatings8020062"  # the replicated paper (passmd.PAPER_CITATION)
    assert paper["doi"] in passmd.PAPER_CITATION
    changelog = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    assert f"## [{passmd.__version__}]" in changelog and "## [Unreleased]" in changelog


def _environment_uses(path: Path) -> tuple[list[str], list[str]]:
    """(writes, reads) of the process environment in one source file, as ``file:line``."""
    import ast

    tree = ast.parse(path.read_text(encoding="utf-8"))
    writes, reads = [], []

    def is_environ(node) -> bool:
        return isinstance(node, ast.Attribute) and node.attr == "environ" \
            and isinstance(node.value, ast.Name) and node.value.id == "os"

    for node in ast.walk(tree):
        where = f"{path.relative_to(ROOT)}:{getattr(node, 'lineno', '?')}"
        if isinstance(node, (ast.Assign, ast.AugAssign, ast.Delete)):
            targets = node.targets if isinstance(node, (ast.Assign, ast.Delete)) else [node.target]
            if any(isinstance(t, ast.Subscript) and is_environ(t.value) for t in targets):
                writes.append(where)
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            if is_environ(node.func.value) and node.func.attr in ("update", "pop", "setdefault", "clear"):
                writes.append(where)
            elif isinstance(node.func.value, ast.Name) and node.func.value.id == "os" \
                    and node.func.attr in ("putenv", "unsetenv"):
                writes.append(where)
        if is_environ(node) or (isinstance(node, ast.Attribute) and node.attr == "getenv"):
            reads.append(where)
    return writes, reads


def test_the_package_never_writes_the_environment_and_the_engine_never_reads_it():
    """Entry points read the environment once into a RunConfig and pass it down (passmd.runtime.config)."""
    writes = []
    for path in sorted((ROOT / "passmd").rglob("*.py")):
        writes += _environment_uses(path)[0]
    assert writes == []
    engine = [ROOT / "passmd" / "runtime" / "sweep.py", *(ROOT / "passmd" / "runtime" / "cache").glob("*.py")]
    for path in engine:
        assert _environment_uses(path)[1] == [], path.name
