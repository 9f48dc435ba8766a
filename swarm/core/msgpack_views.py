"""msgpack decoded with its bins as views into the message, not copies.

msgpack-python copies every bin and extension out of the bytes it decodes.
A resumed world hands a DFT robot its 3.2 MB memory in one message, so the
agent held the message, the memory's blob copied out of it and the fields
copied out of that at once: three copies of MBs in a process that must stay
under 80 MB.  This reader returns each bin as a read-only
memoryview of the message and gives each extension's bytes to a hook as a
view too; everything else decodes to what `msgpack.unpackb(raw=False,
strict_map_key=False)` gives (tested against it).  It walks values in
Python, one at a time: for messages of a few large bins (memories handed
back), not for the per-tick observations, which msgpack's C reader keeps.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from typing import Any

import msgpack

ExtHook = Callable[[int, memoryview], Any]
TIMESTAMP = -1  # the extension type msgpack reserves for its Timestamp
MAX_DEPTH = 64  # nested arrays and maps; a deeper message is refused, not a RecursionError

_FIXED = {  # type byte: (struct format, size) of a fixed-size scalar
    0xCA: (">f", 4), 0xCB: (">d", 8),
    0xCC: (">B", 1), 0xCD: (">H", 2), 0xCE: (">I", 4), 0xCF: (">Q", 8),
    0xD0: (">b", 1), 0xD1: (">h", 2), 0xD2: (">i", 4), 0xD3: (">q", 8),
}  # fmt: skip
_SIZED = {0xC4: ("bin", 1), 0xC5: ("bin", 2), 0xC6: ("bin", 4), 0xC7: ("ext", 1), 0xC8: ("ext", 2),
          0xC9: ("ext", 4), 0xD9: ("str", 1), 0xDA: ("str", 2), 0xDB: ("str", 4), 0xDC: ("array", 2),
          0xDD: ("array", 4), 0xDE: ("map", 2), 0xDF: ("map", 4)}  # fmt: skip
_FIXEXT = {0xD4: 1, 0xD5: 2, 0xD6: 4, 0xD7: 8, 0xD8: 16}
_CONSTANTS = {0xC0: None, 0xC2: False, 0xC3: True}


def _no_ext(code: int, data: memoryview) -> Any:
    raise ValueError(f"extension {code} where none is expected")


def unpack(data: bytes | memoryview, ext_hook: ExtHook = _no_ext) -> Any:
    """The one value `data` holds; raises ValueError on a malformed, truncated or overlong message.
    Bins in the result are views of `data`: it stays alive as long as they do."""
    view = memoryview(data).cast("B")  # bytes, whatever the buffer's item format
    reader = _Reader(view, ext_hook)
    try:
        value = reader.value(0)
    except (TypeError, struct.error) as err:  # a key that cannot be a key (a list), a short number
        raise ValueError(str(err)) from None
    if reader.at != len(view):
        raise ValueError(f"{len(view) - reader.at} bytes after the message")
    return value


class _Reader:
    def __init__(self, view: memoryview, ext_hook: ExtHook) -> None:
        self.view, self.ext_hook, self.at = view, ext_hook, 0

    def take(self, size: int) -> memoryview:
        if size > len(self.view) - self.at:
            raise ValueError("truncated message")
        self.at += size
        return self.view[self.at - size : self.at]

    def number(self, fmt: str, size: int) -> Any:
        return struct.unpack(fmt, self.take(size))[0]

    def value(self, depth: int, key: bool = False) -> Any:
        code = self.take(1)[0]
        if code <= 0x7F:
            return code
        if code >= 0xE0:
            return code - 0x100
        if code in _CONSTANTS:
            return _CONSTANTS[code]
        if code in _FIXED:
            return self.number(*_FIXED[code])
        if 0xA0 <= code <= 0xBF:
            return str(self.take(code & 0x1F), "utf-8")
        if 0x90 <= code <= 0x9F:
            return self.array(code & 0x0F, depth)
        if 0x80 <= code <= 0x8F:
            return self.map(code & 0x0F, depth)
        if code in _FIXEXT:
            return self.ext(_FIXEXT[code])
        if code not in _SIZED:
            raise ValueError(f"0x{code:02x} is not a msgpack type")
        kind, width = _SIZED[code]
        size = int.from_bytes(self.take(width), "big")
        if kind == "bin":
            raw = self.take(size)
            return bytes(raw) if key else raw  # a key must hash: msgpack's bytes
        if kind == "str":
            return str(self.take(size), "utf-8")
        if kind == "ext":
            return self.ext(size)
        return self.array(size, depth) if kind == "array" else self.map(size, depth)

    def ext(self, size: int) -> Any:
        code = self.number(">b", 1)
        if code == TIMESTAMP:  # msgpack's own type, decoded (and refused when malformed) as msgpack does
            return msgpack.Timestamp.from_bytes(bytes(self.take(size)))
        return self.ext_hook(code, self.take(size))

    def array(self, size: int, depth: int) -> list:
        if depth >= MAX_DEPTH:
            raise ValueError("nested too deep")
        if size > len(self.view) - self.at:  # each item takes a byte at least: a header cannot claim more
            raise ValueError("truncated message")
        return [self.value(depth + 1) for _ in range(size)]

    def map(self, size: int, depth: int) -> dict:
        if depth >= MAX_DEPTH:
            raise ValueError("nested too deep")
        if 2 * size > len(self.view) - self.at:
            raise ValueError("truncated message")
        out = {}
        for _ in range(size):
            key = self.value(depth + 1, key=True)
            out[key] = self.value(depth + 1)
        return out
