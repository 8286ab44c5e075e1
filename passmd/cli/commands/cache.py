"""``passmd cache``: the on-disk simulation cache: summary, empty it, or prune old entries."""

from __future__ import annotations

import textwrap

from passmd.cache import DEFAULT_CACHE_DIR
from passmd.cli.errors import OutputError
from passmd.cli.options import CACHE_DIR_HELP, DirectoryPath
from passmd.cli.output import JSON_HELP, emit_json, emit_rows
from passmd.config import ENVIRONMENT, RunConfig

__all__ = ["add_parser", "run_cache"]

_EPILOG = textwrap.dedent(f"""\
    info: entries (of the current code and of older code versions), size, entries per
    function. clear: remove every entry. prune: remove entries of other code versions
    (their code fingerprint differs, so they can never be served), unreadable entries
    and leftovers. Entries are checksummed data (JSON header + raw array bytes), never
    code; see passmd.cache for the format. Directory: ${ENVIRONMENT['cache_dir']} or ./{DEFAULT_CACHE_DIR}.

    --json keys: action, directory, and entries, bytes, current_code, other_code,
    unreadable, leftovers, functions (info) or removed (clear, prune)""")


def add_parser(command) -> None:
    p = command("cache", "the on-disk simulation cache: summary, empty it, or prune old entries", _EPILOG)
    p.add_argument("action", choices=("info", "clear", "prune"), help="what to do (default: none, required)")
    p.add_argument("--cache-dir", metavar="DIR", action=DirectoryPath, help=CACHE_DIR_HELP)
    p.add_argument("--json", action="store_true", help=JSON_HELP)
    p.set_defaults(handler=run_cache)


def run_cache(args, out) -> int:
    from passmd.cache import Cache

    store = Cache(RunConfig.from_environment(cache_dir=args.cache_dir or None).cache_dir)
    if store.directory.exists() and not store.directory.is_dir():
        raise OutputError(f"the cache {store.directory} is not a directory")
    if args.action == "info":
        record = store.info()
    elif args.action == "clear":
        record = {"directory": str(store.directory), "removed": store.clear()}
    else:
        record = {"directory": str(store.directory), "removed": store.prune()}
    if args.json:
        emit_json({"command": "cache", "action": args.action, **record}, out)
        return 0
    if args.action != "info":
        out.write(f"{args.action}: removed {record['removed']} file(s) from {record['directory']}\n")
        return 0
    rows = [("directory", record["directory"]),
            ("entries", f"{record['entries']} ({record['current_code']} of the current code, "
                        f"{record['other_code']} of other code versions: 'passmd cache prune' removes them)"),
            ("size", f"{record['bytes'] / 2**20:.3g} MiB"),
            ("unreadable / leftovers", f"{record['unreadable']} / {record['leftovers']}")]
    rows += [(f"  {name}", str(n)) for name, n in sorted(record["functions"].items())]
    emit_rows("passmd cache", rows, out)
    return 0
