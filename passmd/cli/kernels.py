"""A one-line notice on stderr before the simulation kernels compile (numba's cache is cold).

The first simulation after installing (or after the kernels' source changed) compiles the
numba kernels once, which takes ≈ 15–20 s on a laptop core; without a word the command looks
hung. The check is cheap (a directory listing, no numba import): the kernels are warm when,
for each kernel module, an index file of numba's on-disk cache (``<module>.<function>-<line>
.py<XY>.nbi``) is present and not older than the module's source, in any of the places numba
keeps it (``__pycache__`` next to the source, ``$NUMBA_CACHE_DIR``, the user-wide cache).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

__all__ = ["KERNEL_MODULES", "kernels_cold", "notice_if_cold"]

#: The modules whose ``@njit(cache=True)`` functions every simulation compiles (the step loop
#: and the contact kernels it calls), relative to the package folder. Not
#: :mod:`passmd.model.mdr_contact`: its array kernels serve MDRContact's methods, which no
#: simulation calls, so a simulation never writes their index.
KERNEL_MODULES = ("solver/kernels", "model/contact_kernels")

NOTICE = "compiling the simulation kernels (≈ 20 s, once) …"


def _cache_dirs(source_dir: Path) -> list[Path]:
    dirs = [source_dir / "__pycache__"]
    relative = Path(*source_dir.resolve().parts[1:])  # numba mirrors the source path below its cache root
    if os.environ.get("NUMBA_CACHE_DIR"):
        dirs.append(Path(os.environ["NUMBA_CACHE_DIR"]) / relative)
    dirs.append(Path.home() / ".cache" / "numba" / relative)
    return dirs


def kernels_cold(package_dir: Path | None = None) -> bool:
    """Whether some kernel module has no index file in numba's cache as new as its source."""
    package_dir = package_dir or Path(__file__).resolve().parents[1]
    tag = f".py{sys.version_info.major}{sys.version_info.minor}.nbi"
    for module in KERNEL_MODULES:
        source = package_dir / f"{module}.py"
        try:
            stamp = source.stat().st_mtime
        except OSError:
            continue
        dirs = [d for d in _cache_dirs(source.parent) if d.is_dir()]
        names = {d: os.listdir(d) for d in dirs}
        stem = source.stem
        fresh = any(name.startswith(stem + ".") and name.endswith(tag)
                    and (d / name).stat().st_mtime >= stamp for d in dirs for name in names[d])
        if not fresh:
            return True
    return False


def notice_if_cold(stream=None) -> None:
    """Write :data:`NOTICE` to ``stream`` (stderr) when :func:`kernels_cold`; never to stdout."""
    try:
        cold = kernels_cold()
    except OSError:  # an unreadable cache directory: say nothing rather than fail the run
        return
    if cold:
        stream = stream or sys.stderr
        stream.write(f"passmd: {NOTICE}\n")
        stream.flush()
