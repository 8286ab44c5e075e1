"""The ``passmd`` argument parser: one-line errors, and every subcommand's options."""

from __future__ import annotations

import argparse
import re
import sys

from passmd import __version__
from passmd.cli.commands import (
    cache,
    contact,
    critical_amplitude,
    drive,
    figure,
    fit,
    force,
    ledger,
    run,
    sweep,
    theory,
)

__all__ = ["DESCRIPTION", "PROG", "make_parser"]

PROG = "passmd"

DESCRIPTION = """\
passmd: the piezo-actuated stick-slip micro-drive of Nguyen et al., Coatings 8, 62 (2018).

Quantities accept units (0.4N, 1mm, '0.25 mm', 202nm, 100kHz, 310GPa). A bare number is
read in SI units, and only where the option's help shows the SI unit (N, N/m, kg/s, V); an
option shown in mm, nm, kHz, g, GPa or V/us refuses a bare number and asks for the unit.
A drive file (--drive FILE, `passmd drive template`) reads bare numbers in SI.
Human output uses nm, N, mm and kHz; --json prints one JSON object in SI units whose
keys carry the unit (e.g. final_position_m)."""

#: The subcommands in the order ``passmd --help`` lists them.
COMMANDS = (theory, critical_amplitude, run, force, sweep, fit, contact, drive, figure, cache, ledger)


#: A command-line token that is a negative value, with or without a unit (``-1us``, ``-.5``, ``-2e-3N``).
_NEGATIVE_VALUE = re.compile(r"^-\.?\d")


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (no usage dump) and exit status 2."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # A value that starts with a minus and a digit (--flyback -1us, --mu -0.2) is the option's
        # value, refused by its range check with the option named; argparse reads only plain
        # negative numbers so, and would say "expected one argument".
        self._negative_number_matcher = _NEGATIVE_VALUE

    def error(self, message):  # noqa: D401 - argparse API
        self.exit(2, f"{self.prog}: error: {message}\n")

    def _print_message(self, message, file=None):  # argparse would swallow a failed write
        if message:
            (file or sys.stderr).write(message)


class _Formatter(argparse.RawDescriptionHelpFormatter):
    def __init__(self, prog):
        super().__init__(prog, max_help_position=34, width=100)


def make_parser() -> argparse.ArgumentParser:
    """The ``passmd`` argument parser (all subcommands)."""
    parser = _Parser(
        prog=PROG,
        formatter_class=_Formatter,
        description=DESCRIPTION,
        epilog="Exit status: 0 ok, 2 usage error, 1 failed run. 'passmd COMMAND --help' for options.",
    )
    parser.add_argument("--version", action="version", version=f"passmd {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    def command(name, help_text, epilog):
        return sub.add_parser(name, help=help_text, description=help_text, epilog=epilog,
                              formatter_class=_Formatter)

    for module in COMMANDS:
        module.add_parser(command)
    return parser
