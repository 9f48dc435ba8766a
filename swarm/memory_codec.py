"""A controller's memory (its `snapshot()`) as bytes and back, exactly.

The arena's controllers keep their memory in plain Python values and numpy
arrays (a DFT robot's fields, an animat's map).  A resumed run must give them
back bit for bit, so arrays travel as their raw bytes with dtype and shape,
floats as float64, and map keys keep their type (an int key stays an int).
Decoding never raises: a broken blob is a `Rejected` reason, and the agent
runtime counts it (the controller then goes on with what it has).
"""

from __future__ import annotations

from typing import Any

import msgpack
import numpy as np

from swarm.protocol import Rejected

_ARRAY = 1  # msgpack extension code: [dtype, shape, bytes]
MAX_MEMORY_BYTES = 256 * 1024 * 1024  # one controller's memory; a DFT robot on large-maze takes ~30 MB


def _default(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        a = np.ascontiguousarray(value)
        if a.dtype.hasobject:
            return a.tolist()
        raw = memoryview(a.reshape(-1).view(np.uint8))  # the array's bytes where they are: no copy (fields are MBs)
        return msgpack.ExtType(_ARRAY, msgpack.packb([a.dtype.str, list(a.shape), raw], use_bin_type=True))
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    if isinstance(value, tuple | set | frozenset):
        return list(value)
    raise TypeError(f"a controller's memory holds a {type(value).__name__}, which has no wire form")


def _ext(code: int, data: bytes) -> Any:
    if code != _ARRAY:
        raise ValueError(f"unknown extension {code}")
    kind, shape, raw = msgpack.unpackb(data, raw=False)
    dtype = np.dtype(kind)
    if dtype.hasobject:
        raise ValueError("object arrays are not memory")
    return np.frombuffer(raw, dtype=dtype).reshape(shape).copy()


def encode(memory: Any) -> bytes:
    return msgpack.packb(memory, default=_default, use_bin_type=True, strict_types=False)


def decode(blob: bytes) -> Any:
    if not isinstance(blob, bytes | bytearray) or len(blob) > MAX_MEMORY_BYTES:
        return Rejected("memory: expected at most 256 MB of bytes")
    try:
        return msgpack.unpackb(blob, raw=False, strict_map_key=False, ext_hook=_ext)
    except Exception as err:  # a broken blob is a reason, never a traceback
        return Rejected(f"memory: {type(err).__name__}")
