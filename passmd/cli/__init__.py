"""The ``passmd`` command line.

Subcommands::

    passmd theory               closed forms of a configuration (Eqs. 1, 7–14)
    passmd critical-amplitude   simulated and analytic critical amplitude A_c
    passmd run                  one simulation of a driving waveform
    passmd force                generated force against the load cell
    passmd contact              tangential force of one MDR contact along a path
    passmd figure               one paper figure's data and image
    passmd ledger               the replication ledger: every claim's computed category
    passmd cache                the on-disk simulation cache: info, clear, prune

Quantities accept units (``0.4N``, ``1mm``, ``0.25 mm``, ``202nm``, ``100kHz``,
``310GPa``); a bare number is SI, refused where ``--help`` shows another unit. Human output uses nm,
N, mm and kHz; ``--json`` prints one JSON object in SI units whose keys carry the unit.

Exit status: 0 success, 2 usage error (unknown option, wrong unit, out-of-range value,
contradicting options), 1 failed run (the simulation diverged, a result failed its
finiteness/plausibility check, an output could not be written, an optional dependency
is missing, not enough memory), 130 interrupted (Ctrl-C), 143 terminated (SIGTERM, handled
as Ctrl-C: no partial or temporary file is left), 141 standard output closed (a pipe reader
such as ``head`` went away, or the command was started with it closed; nothing is printed,
as Unix tools do).
Errors print one line to stderr, never a traceback. Parameter ranges come from
:data:`passmd.model.parameters.PLAUSIBLE_RANGES`; ``--allow-extrapolation`` lifts their soft
limits. On a console that cannot encode the output's symbols (μ, ×, –, →), ASCII
stand-ins are printed.

``figure`` and ``ledger`` run with one :class:`~passmd.runtime.config.RunConfig`: the environment
(``PASSMD_*``, read once here) replaced by the options given, passed down to the sweeps and
the cache.

Modules: ``passmd.cli.parser`` (the parser), ``passmd.cli.app`` (dispatch and exit
status), ``passmd.cli.options`` and ``passmd.cli.drive`` (quantity options, the
drive they describe), ``passmd.cli.output`` (human and JSON output),
``passmd.cli.streams`` (standard streams), ``passmd.cli.startup`` (garbage collection
paused while a command starts), ``passmd.cli.configuration`` (the RunConfig of ``figure``
and ``ledger``), ``passmd.cli.commands`` (one module per command).
"""

from __future__ import annotations

from passmd.cli.app import main
from passmd.cli.drive import build_drive
from passmd.cli.errors import UsageError
from passmd.cli.parser import make_parser

__all__ = ["UsageError", "build_drive", "main", "make_parser"]
