"""A controller's memory (its `snapshot()`) as bytes and back, exactly.

The arena's controllers keep their memory in plain Python values and numpy
arrays (a DFT robot's fields, an animat's map).  A resumed run must give them
back bit for bit, so arrays travel as their raw bytes with dtype and shape,
floats as float64, and map keys keep their type (an int key stays an int).
Decoding never raises: a broken blob is a `Rejected` reason, and the agent
runtime counts it (the controller then goes on with what it has).

Why pieces: a DFT robot's memory is MBs of fields, sent at every save tick
from a process that must stay under 80 MB.  `pieces` gives the
msgpack form as a list of small headers and the arrays' own bytes (views, no
copy), so the action message that carries it is written once, by one
`b"".join`, straight from the fields.  The form is msgpack's own, byte for
byte (tested against `msgpack.packb`), and msgpack decodes it.
"""

from __future__ import annotations

import math
import struct
from typing import Any

import msgpack
import numpy as np

from swarm.core import msgpack_views
from swarm.core.wire import HEADERS, Rejected, bin_header

_ARRAY = 1  # msgpack extension code: [dtype, shape, bytes]
MAX_MEMORY_BYTES = 256 * 1024 * 1024  # one controller's memory; a DFT robot on large-maze takes ~3.2 MB
_FIXEXT = {1: 0xD4, 2: 0xD5, 4: 0xD6, 8: 0xD7, 16: 0xD8}


def _plain(value: Any) -> Any:
    """msgpack's `default`: what a value without a wire form of its own travels as (arrays aside)."""
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    if isinstance(value, set | frozenset):
        return list(value)
    raise TypeError(f"a controller's memory holds a {type(value).__name__}, which has no wire form")


def _pack(value: Any) -> bytes:
    return msgpack.packb(value, default=_plain, use_bin_type=True, strict_types=False)


def _ext_header(code: int, size: int) -> bytes:
    if size in _FIXEXT:
        return struct.pack(">Bb", _FIXEXT[size], code)
    if size < 1 << 8:
        return struct.pack(">BBb", 0xC7, size, code)
    return struct.pack(">BHb", 0xC8, size, code) if size < 1 << 16 else struct.pack(">BIb", 0xC9, size, code)


def _array_pieces(value: np.ndarray, out: list) -> None:
    a = np.ascontiguousarray(value)
    if a.dtype.hasobject:
        _walk(a.tolist(), out)
        return
    raw = memoryview(a.reshape(-1).view(np.uint8))  # the array's bytes where they are: no copy (fields are MBs)
    head = HEADERS.pack_array_header(3) + _pack(a.dtype.str) + _pack(list(a.shape)) + bin_header(raw.nbytes)
    out += [_ext_header(_ARRAY, len(head) + raw.nbytes), head, raw]


def _walk(value: Any, out: list) -> None:
    if isinstance(value, np.ndarray):
        _array_pieces(value, out)
    elif isinstance(value, dict):
        out.append(HEADERS.pack_map_header(len(value)))
        for key, item in value.items():
            _walk(key, out)
            _walk(item, out)
    elif isinstance(value, list | tuple | set | frozenset):
        out.append(HEADERS.pack_array_header(len(value)))
        for item in value:
            _walk(item, out)
    else:
        out.append(_pack(value))


def pieces(memory: Any) -> list:
    """The msgpack form of `memory` as pieces (bytes, and memoryviews of its arrays) to be joined.
    The views read the arrays when joined: join them before the controller steps again."""
    out: list = []
    _walk(memory, out)
    return out


def encode(memory: Any) -> bytes:
    return b"".join(pieces(memory))


def _array(code: int, data: bytes | memoryview) -> np.ndarray:
    """An array from its extension, [dtype, shape, bin]: a read-only view of `data`, checked."""
    if code != _ARRAY:
        raise ValueError(f"unknown extension {code}")
    parts = msgpack_views.unpack(data)
    if not (isinstance(parts, list) and len(parts) == 3 and isinstance(parts[0], str)
            and isinstance(parts[1], list) and isinstance(parts[2], memoryview)):  # fmt: skip
        raise ValueError("an array is [dtype, shape, bytes]")
    dtype, shape, raw = np.dtype(parts[0]), parts[1], parts[2]
    if dtype.hasobject:
        raise ValueError("object arrays are not memory")
    if not all(type(n) is int and n >= 0 for n in shape) or raw.nbytes != dtype.itemsize * math.prod(shape):
        raise ValueError("an array's bytes do not match its dtype and shape")
    return np.frombuffer(raw, dtype=dtype).reshape(shape)


def _ext(code: int, data: bytes) -> np.ndarray:
    """msgpack's ext hook: the array copied once out of the extension's bytes (they are msgpack's copy)."""
    return _array(code, data).copy()


def decode(blob: bytes | memoryview, views: bool = False) -> Any:
    """The memory in `blob`, or a `Rejected` reason.  With `views`, its arrays (and any bins) are read-only
    views of `blob`, not copies: for a controller whose restore() copies what it is given (`restore_copies`,
    agents/controllers/arena.py), so a DFT robot's fields are never held twice while they are handed back."""
    if not isinstance(blob, bytes | bytearray | memoryview) or len(blob) > MAX_MEMORY_BYTES:
        return Rejected("memory: expected at most 256 MB of bytes")
    try:
        if views:
            return msgpack_views.unpack(blob, _array)
        return msgpack.unpackb(blob, raw=False, strict_map_key=False, ext_hook=_ext)
    except Exception as err:  # a broken blob is a reason, never a traceback
        return Rejected(f"memory: {type(err).__name__}")
