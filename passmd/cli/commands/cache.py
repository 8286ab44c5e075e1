"""``passmd cache``: the on-disk simulation cache: summary, empty it, or prune old entries."""

from __future__ import annotations

import os
import textwrap

from passmd.cli.errors import UsageError
from passmd.cli.options import CACHE_DIR_HELP, DirectoryPath
from passmd.cli.output import JSON_HELP, emit_json, emit_rows
from passmd.runtime.cache import MARKER_NAME, describe_default_cache_dir
from passmd.runtime.config import ENVIRONMENT, RunConfig

__all__ = ["add_parser", "run_cache"]

_EPILOG = textwrap.dedent(f"""\
    info: entries (of the current code and of older code versions), size, entries per
    function. clear: remove every entry. prune: remove entries of other code versions
    (their code fingerprint differs, so they can never be served), unreadable entries
    and stale temporary files. Entries are checksummed data (JSON header + raw array
    bytes), never code; see passmd.runtime.cache for the format. Directory:
    ${ENVIRONMENT['cache_dir']}, else {describe_default_cache_dir()}.

    Only a cache's own files are ever removed: a cache directory carries the marker
    {MARKER_NAME}, written when passmd creates the directory (or first caches into an
    empty one, or into one holding only passmd cache entries: a cache from before
    markers). A directory without it is refused with nothing read or removed; inside a
    cache, only entries (files <key[:2]>/<key>.pmc that start with the PASSMD-CACHE line,
    or links and special files in their place) and the cache's temporary files are
    removed, and other files are counted as foreign and left alone.

    --json keys: command, action, directory, and entries, bytes, current_code,
    other_code, unreadable, leftovers, foreign, functions (info) or removed (clear,
    prune: the number of files removed)""")


def add_parser(command) -> None:
    p = command("cache", "the on-disk simulation cache: summary, empty it, or prune old entries", _EPILOG)
    p.add_argument("action", choices=("info", "clear", "prune"), help="what to do (default: none, required)")
    p.add_argument("--cache-dir", metavar="DIR", action=DirectoryPath, help=CACHE_DIR_HELP)
    p.add_argument("--json", action="store_true", help=JSON_HELP)
    p.set_defaults(handler=run_cache)


def _named(args) -> str:
    """The cache directory as the user named it: option, environment variable or default."""
    variable = ENVIRONMENT["cache_dir"]
    if args.cache_dir:
        return f"--cache-dir = {args.cache_dir!r}"
    if (os.environ.get(variable) or "").strip():
        return f"{variable} = {os.environ[variable].strip()!r}"
    return "the default cache directory"


def run_cache(args, out) -> int:
    from passmd.runtime.cache import Cache, NotACache

    store = Cache(RunConfig.from_environment(cache_dir=args.cache_dir or None).cache_dir)
    try:
        if args.action == "info":
            record = store.info()
        elif args.action == "clear":
            record = {"directory": str(store.directory), "removed": store.clear()}
        else:
            record = {"directory": str(store.directory), "removed": store.prune()}
    except NotACache as exc:
        untouched = "nothing was read" if args.action == "info" else "nothing was removed"
        raise UsageError(f"{_named(args)} ({exc.directory}) {exc.reason}; {untouched}") from exc
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
            ("unreadable / leftovers", f"{record['unreadable']} / {record['leftovers']}"),
            ("foreign (left alone)", str(record["foreign"]))]
    rows += [(f"  {name}", str(n)) for name, n in sorted(record["functions"].items())]
    emit_rows("passmd cache", rows, out)
    return 0
