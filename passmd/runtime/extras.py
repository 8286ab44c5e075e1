"""How to install an optional dependency, said so that it works however passmd was installed.

``pip install 'passmd[dask]'`` asks a package index for passmd, which fails for a wheel or a source
checkout; the extra's own requirements install into any environment. They are read from the
installed package's metadata (``pyproject.toml``'s ``[project.optional-dependencies]``), so the
hint never drifts from what the extra declares.
"""

from __future__ import annotations

from importlib import metadata

__all__ = ["install_hint"]

#: The extra's requirements when the metadata cannot be read (a source tree on ``sys.path``).
_FALLBACK = {"dask": ("dask[distributed]",)}


def _requirements(extra: str) -> tuple[str, ...]:
    try:
        declared = metadata.requires("passmd") or []
    except metadata.PackageNotFoundError:
        return _FALLBACK.get(extra, ())
    found = []
    for line in declared:
        requirement, _, marker = line.partition(";")
        if marker.replace(" ", "").replace("'", '"') == f'extra=="{extra}"':
            found.append(requirement.strip())
    return tuple(found) or _FALLBACK.get(extra, ())


def install_hint(extra: str) -> str:
    """``pip install 'dask[distributed]>=2024.1'`` for the extra ``dask`` (its requirements, quoted)."""
    requirements = _requirements(extra)
    if not requirements:
        return f"pip install 'passmd[{extra}]'"
    return "pip install " + " ".join(f"'{r}'" for r in requirements) + f" (the passmd[{extra}] extra)"
