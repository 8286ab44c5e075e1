"""Every passmd name is imported under its own name (guide: "modules imported under their own names").

A reader who meets ``simulation.simulate`` in one file and ``dynamics.simulate`` in another
has to translate; so no ``import … as`` renames anything of passmd, in the package, the
tests, the benchmarks, the tools or the book's code cells. The one exception is the explicit
re-export idiom ``from .x import Y as Y`` of the ``__init__`` files, which keeps the name.
"""

from __future__ import annotations

import ast
import re
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FENCE = re.compile(r"^(`{3,})\s*(\{code-cell\}[^\n]*|python|py)\s*\n(.*?)^\1\s*$", re.S | re.M)


def _is_passmd(module: str | None, level: int, path: Path) -> bool:
    """Whether an import names passmd (absolute, or relative from inside the package)."""
    if level:
        return path.is_relative_to(ROOT / "passmd")
    return module is not None and (module == "passmd" or module.startswith("passmd."))


def _embedded(node: ast.AST) -> str | None:
    """A string constant that is itself Python importing passmd (code run in a subprocess)."""
    if not (isinstance(node, ast.Constant) and isinstance(node.value, str) and "passmd" in node.value
            and "import" in node.value):
        return None
    try:
        ast.parse(textwrap.dedent(node.value))
    except SyntaxError:
        return None
    return textwrap.dedent(node.value)


def renames(source: str, path: Path) -> list[str]:
    """The ``import … as`` renames of passmd names in ``source`` (and in the Python it holds as
    strings), one line each."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if (code := _embedded(node)) is not None:
            found += [f"string at line {node.lineno}, {item}" for item in renames(code, path)]
        if isinstance(node, ast.Import):
            pairs = [(alias, _is_passmd(alias.name, 0, path)) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            pairs = [(alias, _is_passmd(node.module, node.level, path)) for alias in node.names]
        else:
            continue
        for alias, ours in pairs:
            if ours and alias.asname and alias.asname != alias.name.rpartition(".")[2]:
                found.append(f"line {node.lineno}: {alias.name} as {alias.asname}")
    return found


def _cells(text: str) -> list[tuple[int, str]]:
    """Python code blocks of a Markdown page: (first line number, code without cell options)."""
    cells = []
    for match in FENCE.finditer(text):
        body = match.group(3)
        lines = body.splitlines()
        if lines and lines[0].strip() == "---":  # YAML cell options
            end = lines.index("---", 1) if "---" in lines[1:] else 0
            lines = [""] * (end + 1) + lines[end + 1:]
        code = "\n".join("" if line.startswith((":", "%", "!")) else line for line in lines)
        cells.append((text.count("\n", 0, match.start(3)) + 1, code))
    return cells


def _sources() -> list[Path]:
    python = [path for folder in ("passmd", "tests", "benchmarks", "tools")
              for path in (ROOT / folder).rglob("*.py")]
    markdown = sorted((ROOT / "book").glob("*.md")) + [ROOT / "README.md", ROOT / "CONTRIBUTING.md"]
    python = [path for path in python if path != Path(__file__).resolve()]  # its counter-examples
    return sorted(python) + [ROOT / "noxfile.py", ROOT / "book" / "_ext" / "passmd_book.py"] + markdown


def _findings(path: Path) -> list[str]:
    text = path.read_text(encoding="utf-8")
    if path.suffix == ".py":
        return renames(text, path)
    found = []
    for first_line, code in _cells(text):
        found += [f"cell at line {first_line}, {item}" for item in renames(code, path)]
    return found


def test_no_passmd_name_is_imported_under_another_name():
    found = {str(path.relative_to(ROOT)): items for path in _sources() if (items := _findings(path))}
    assert not found, "imports under another name:\n" + "\n".join(
        f"  {name}: {item}" for name, items in found.items() for item in items)


@pytest.mark.parametrize("line", [
    "from passmd.solver import simulation as dynamics",
    "import passmd.solver.simulation as sim",
    "from passmd.protocols.fit.profiles import FINE_SPACING as FINE",
])
def test_a_rename_is_found(line):
    assert renames(line, ROOT / "tests" / "x.py")


def test_a_rename_in_code_run_from_a_string_is_found():
    runner = 'RUNNER = """\nimport sys\nfrom passmd.solver import kernels as kern\nkern.integrate\n"""\n'
    assert renames(runner, ROOT / "tests" / "x.py") == ["string at line 1, line 3: kernels as kern"]


def test_a_relative_rename_inside_the_package_is_found():
    assert renames("from ..solver import simulation as dynamics", ROOT / "passmd" / "cli" / "x.py")


@pytest.mark.parametrize("line", [
    "from passmd.solver import simulation",
    "from .simulation import simulate as simulate",
    "import passmd.solver.simulation as simulation",
    "import numpy as np",
])
def test_own_names_and_other_packages_pass(line):
    assert not renames(line, ROOT / "passmd" / "x.py")


def test_book_cells_are_read():
    page = ("text\n\n```{code-cell} ipython3\n:tags: [hide-input]\n"
            "from passmd.experiments import figure_table as figures\n```\n")
    assert _cells(page) and renames(_cells(page)[0][1], ROOT / "book" / "x.md")
