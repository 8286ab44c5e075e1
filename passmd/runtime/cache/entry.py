"""The bytes of one cache entry (format and rules in :mod:`passmd.runtime.cache`):
:func:`~passmd.runtime.cache.entry.encode_entry` writes a checksummed JSON header and the raw bytes
of its arrays, :func:`~passmd.runtime.cache.entry.decode_entry` checks every part and raises
:class:`~passmd.runtime.cache.entry.CorruptEntry` otherwise.
"""

from __future__ import annotations

import hashlib
import json
import time

import numpy as np

from passmd.runtime.inputs import LIMITS

__all__ = ["FORMAT", "MAGIC", "MAX_DEPTH", "MAX_ENTRY_BYTES", "MAX_HEADER_BYTES", "CorruptEntry",
           "decode_entry", "encode_entry"]

#: Format name and version: the first line of every entry and the marker's format line.
FORMAT = "PASSMD-CACHE 1"
#: First line of every entry.
MAGIC = FORMAT.encode() + b"\n"
#: Largest entry file read or written, in bytes (results are KiB to MiB; arrays live here):
#: the cache entry's limit of :data:`passmd.runtime.inputs.LIMITS`.
MAX_ENTRY_BYTES = LIMITS["cache entry"]
#: Largest JSON header read or written, in bytes (the value tree without its array bytes).
MAX_HEADER_BYTES = 16 * 2**20
#: Deepest nesting of a stored value (a dict in a list in a dict ... counts one per level).
MAX_DEPTH = 64


class CorruptEntry(ValueError):
    """An entry's bytes do not decode to a checked value (see :func:`decode_entry`)."""


class _TooLarge(ValueError):
    """An encoded entry above :data:`MAX_ENTRY_BYTES` or :data:`MAX_HEADER_BYTES`."""


def _encode_node(value, chunks: list[bytes], offset: list[int], where: str, depth: int = 1):
    """JSON node of one value; array bytes are appended to ``chunks``."""
    if depth > MAX_DEPTH:
        raise TypeError(f"cannot cache {where}: the value nests deeper than {MAX_DEPTH} levels")
    if value is None:
        return {"t": "none"}
    if isinstance(value, bool):
        return {"t": "bool", "v": value}
    if isinstance(value, (np.ndarray, np.generic)):
        arr = np.asarray(value)
        if arr.dtype.hasobject or arr.dtype.fields is not None or arr.dtype.kind not in "biufc":
            raise TypeError(f"cannot cache {where}: a NumPy {arr.dtype} value (numeric dtypes only)")
        data = np.ascontiguousarray(arr).tobytes()
        node = {"t": "array", "dtype": arr.dtype.str, "shape": list(arr.shape),
                "offset": offset[0], "nbytes": len(data), "scalar": isinstance(value, np.generic)}
        chunks.append(data)
        offset[0] += len(data)
        return node
    if isinstance(value, int):
        return {"t": "int", "v": int(value)}
    if isinstance(value, float):
        return {"t": "float", "v": float.hex(value)}
    if isinstance(value, str):
        return {"t": "str", "v": value}
    if isinstance(value, (list, tuple)):
        items = [_encode_node(x, chunks, offset, f"{where}[{i}]", depth + 1) for i, x in enumerate(value)]
        return {"t": type(value).__name__, "v": items}
    if isinstance(value, dict):
        if not all(isinstance(k, str) for k in value):
            raise TypeError(f"cannot cache {where}: a dict with non-string keys")
        return {"t": "dict", "v": [[k, _encode_node(v, chunks, offset, f"{where}[{k!r}]", depth + 1)]
                                   for k, v in value.items()]}
    raise TypeError(
        f"cannot cache {where}: a {type(value).__name__} (the cache stores None, bool, int, float, "
        "str, lists, tuples, dicts and numeric NumPy arrays; convert it where it is produced)"
    )


def _decode_node(node, payload: memoryview, depth: int = 1):
    if depth > MAX_DEPTH:
        raise CorruptEntry(f"the value nests deeper than {MAX_DEPTH} levels")
    if not isinstance(node, dict):
        raise CorruptEntry("a value node that is not an object")
    kind = node["t"]
    if kind == "none":
        return None
    if kind == "bool":
        return bool(node["v"])
    if kind == "int":
        if not isinstance(node["v"], int):
            raise CorruptEntry("int node without an integer")
        return node["v"]
    if kind == "float":
        return float.fromhex(node["v"])
    if kind == "str":
        if not isinstance(node["v"], str):
            raise CorruptEntry("str node without a string")
        return node["v"]
    if kind in ("list", "tuple"):
        items = [_decode_node(x, payload, depth + 1) for x in node["v"]]
        return items if kind == "list" else tuple(items)
    if kind == "dict":
        return {str(k): _decode_node(v, payload, depth + 1) for k, v in node["v"]}
    if kind == "array":
        dtype = np.dtype(node["dtype"])
        if dtype.hasobject or dtype.kind not in "biufc":
            raise CorruptEntry(f"array of dtype {dtype}")
        shape = tuple(int(n) for n in node["shape"])
        start, nbytes = int(node["offset"]), int(node["nbytes"])
        count = int(np.prod(shape, dtype=np.int64))
        if start < 0 or start + nbytes > len(payload) or nbytes != count * dtype.itemsize:
            raise CorruptEntry("array outside the payload")
        arr = np.frombuffer(payload[start:start + nbytes], dtype=dtype, count=count).reshape(shape).copy()
        return arr[()] if node.get("scalar") else arr
    raise CorruptEntry(f"unknown node type {kind!r}")


def encode_entry(key: str, value, *, function: str = "", fingerprint: str = "") -> bytes:
    """The bytes of one entry (format in the module docstring).

    Raises
    ------
    TypeError
        If ``value`` holds a type the format does not store, or nests deeper than
        :data:`MAX_DEPTH` levels.
    ValueError
        If the entry would exceed :data:`MAX_ENTRY_BYTES` or its header
        :data:`MAX_HEADER_BYTES` (it could not be read back).
    """
    chunks: list[bytes] = []
    tree = _encode_node(value, chunks, [0], "the value")
    header = json.dumps(
        {"format": 1, "key": key, "function": function, "code": fingerprint,
         "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), "value": tree},
        separators=(",", ":"), allow_nan=False,
    ).encode()
    if len(header) > MAX_HEADER_BYTES:
        raise _TooLarge(f"its header of {len(header)} bytes is above the {MAX_HEADER_BYTES}-byte limit")
    payload = b"".join(chunks)
    digest = hashlib.sha256(header + payload).hexdigest()
    data = MAGIC + f"{digest} {len(header)}\n".encode() + header + payload
    if len(data) > MAX_ENTRY_BYTES:
        raise _TooLarge(f"its {len(data)} bytes are above the {MAX_ENTRY_BYTES}-byte limit")
    return data


def _split_entry(data: bytes) -> tuple[dict, memoryview]:
    """Header (checked against the checksum and the limits) and payload of an entry's bytes."""
    if not data.startswith(MAGIC):
        raise CorruptEntry("not a passmd cache entry (bad first line)")
    if len(data) > MAX_ENTRY_BYTES:
        raise CorruptEntry(f"{len(data)} bytes, above the {MAX_ENTRY_BYTES}-byte limit")
    end = data.find(b"\n", len(MAGIC), len(MAGIC) + 128)
    if end < 0:
        raise CorruptEntry("truncated (no checksum line)")
    try:
        digest, length = data[len(MAGIC):end].decode("ascii").split(" ")
        length = int(length)
    except (UnicodeDecodeError, ValueError) as exc:
        raise CorruptEntry("unreadable checksum line") from exc
    body = data[end + 1:]
    if length > MAX_HEADER_BYTES:
        raise CorruptEntry(f"a header of {length} bytes, above the {MAX_HEADER_BYTES}-byte limit")
    if length < 0 or length > len(body):
        raise CorruptEntry("truncated (header shorter than announced)")
    if hashlib.sha256(body).hexdigest() != digest:
        raise CorruptEntry("checksum mismatch (the bytes changed after they were written)")
    try:
        header = json.loads(body[:length].decode())
    except RecursionError as exc:
        raise CorruptEntry("a header nested too deeply to read") from exc
    except (UnicodeDecodeError, ValueError) as exc:
        raise CorruptEntry("unreadable header") from exc
    if not isinstance(header, dict) or header.get("format") != 1 or "value" not in header:
        raise CorruptEntry("foreign header")
    return header, memoryview(body)[length:]


def decode_entry(data: bytes, key: str | None = None):
    """``(header, value)`` of an entry's bytes; ``key`` given: it must be the entry's key.

    Raises
    ------
    CorruptEntry
        Bad magic line, checksum, header or node, a header or value above the limits
        (:data:`MAX_HEADER_BYTES`, :data:`MAX_DEPTH`), or another key than ``key``.
    """
    header, payload = _split_entry(data)
    if key is not None and header.get("key") != key:
        raise CorruptEntry(f"written for another key ({str(header.get('key'))[:12]}...)")
    try:
        value = _decode_node(header["value"], payload)
    except CorruptEntry:
        raise
    except (KeyError, TypeError, ValueError, OverflowError, IndexError, RecursionError) as exc:
        raise CorruptEntry(f"malformed value ({type(exc).__name__})") from exc
    return header, value
