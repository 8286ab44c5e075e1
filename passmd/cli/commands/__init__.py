"""The ``passmd`` subcommands, one module per command group.

Each module has ``add_parser(command)``, which adds its subcommand(s) through the factory
``command(name, help, epilog)`` of :func:`passmd.cli.parser.make_parser` and sets the
``handler(args, out) -> exit status``. Heavy modules (the simulator, pandas, matplotlib)
are imported inside the handlers, so ``passmd --help`` starts quickly.
"""
