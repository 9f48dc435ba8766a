"""Compiled reading and writing of the grid's msgpack messages where their
bytes lie: both ends' one-call envelopes (the agent's answer,
`agents/controllers/grid/envelope.py`, and the world's acceptance of actions,
`world_server/grid/accept.py`) read and write the same fixed layout that
`world_server.grid.face.wire` packs.  Every read is bounds-checked: a short or lying
buffer gives -1, never a read past its end.
"""

import numpy as np
from numba import njit

from swarm.core.wire import FAMILY_GRID, VERSION

# The fixed bytes of both messages (msgpack: fixmap of 5, fixstr keys, in the order face.wire packs them).
OBS_HEAD = np.frombuffer(b"\x85\xa1v" + bytes([VERSION]) + b"\xa4type\xa3obs\xa4tick", np.uint8).copy()
ACT_HEAD = np.frombuffer(b"\x85\xa1v" + bytes([VERSION]) + b"\xa4type\xa3act\xa6family\xa4" + FAMILY_GRID.encode()
                          + b"\xa4tick", np.uint8).copy()  # fmt: skip
INTS_KEY = np.frombuffer(b"ints", np.uint8).copy()
PF_KEY = np.frombuffer(b"pf", np.uint8).copy()
ROWS_KEY = np.frombuffer(b"rows", np.uint8).copy()


@njit(cache=True)
def tagged(buf, at, first_tag, widths):
    """(value, next offset) of a tag byte in first_tag .. first_tag + widths - 1 at `at`,
    followed by a big-endian unsigned value of 1, 2, 4 or 8 bytes (msgpack's uint and
    bin headers), or (-1, -1) when the tag is another or the bytes run out."""
    n = len(buf)
    if at >= n or not first_tag <= buf[at] < first_tag + widths:
        return -1, -1
    size = 1 << (buf[at] - first_tag)
    if at + 1 + size > n:
        return -1, -1
    v = np.uint64(0)
    for k in range(size):
        v = (v << np.uint64(8)) | np.uint64(buf[at + 1 + k])
    if v > np.uint64(2**62):
        return -1, -1
    return np.int64(v), at + 1 + size


@njit(cache=True)
def read_int(buf, at):
    """(value, next offset) of a non-negative msgpack integer at `at`, or (-1, -1)."""
    if at < len(buf) and buf[at] <= 0x7F:
        return np.int64(buf[at]), at + 1
    return tagged(buf, at, 0xCC, 4)  # uint 8, 16, 32, 64


@njit(cache=True)
def read_bin(buf, at):
    """(start, length) of a msgpack bin at `at`, or (-1, -1)."""
    length, start = tagged(buf, at, 0xC4, 3)  # bin 8, 16, 32
    if start < 0 or start + length > len(buf):
        return -1, -1
    return start, length


@njit(cache=True)
def words(buf, at, count):
    """`count` little-endian 64-bit words from `at`, at any alignment."""
    out = np.empty(count, np.uint64)
    for j in range(count):
        v = np.uint64(0)
        for k in range(8):
            v |= np.uint64(buf[at + 8 * j + k]) << np.uint64(8 * k)
        out[j] = v
    return out


@njit(cache=True)
def key(buf, at, key):
    """The offset after fixstr `key` at `at`, or -1."""
    m = len(key)
    if at + 1 + m > len(buf) or buf[at] != 0xA0 | m:
        return -1
    for k in range(m):
        if buf[at + 1 + k] != key[k]:
            return -1
    return at + 1 + m


@njit(cache=True)
def read_head(buf, header):
    """(tick, next offset) of a message that begins with `header` (the fixed
    bytes up to its tick key) and a tick, or (-1, -1)."""
    if len(buf) < len(header):
        return -1, -1
    for k in range(len(header)):
        if buf[k] != header[k]:
            return -1, -1
    return read_int(buf, len(header))


@njit(cache=True)
def write_key(out, at, name):
    """`name` as a fixstr map key; returns the next offset."""
    out[at] = 0xA0 | len(name)
    return write_raw(out, at + 1, name)


@njit(cache=True)
def write_tagged(out, at, v, first_tag, widths):
    """`v` after the tag of its narrowest width (1, 2, 4, then 8 bytes, big-endian); returns the next offset."""
    w = 0
    while w < widths - 1 and v >= 1 << (8 << w):
        w += 1
    size = 1 << w
    out[at] = first_tag + w
    for k in range(size):
        out[at + size - k] = (v >> (8 * k)) & 0xFF
    return at + 1 + size


@njit(cache=True)
def write_uint(out, at, v):
    """A non-negative integer as msgpack packs it (a positive fixint, else uint 8, 16, 32 or 64)."""
    if v <= 0x7F:
        out[at] = v
        return at + 1
    return write_tagged(out, at, v, 0xCC, 4)


@njit(cache=True)
def write_raw(out, at, raw):
    """The bytes of `raw` (uint8) at `at`; returns the next offset."""
    for k in range(len(raw)):
        out[at + k] = raw[k]
    return at + len(raw)


@njit(cache=True)
def write_words(out, at, bits, first, count):
    """`count` 64-bit words of `bits` (uint64) from `first`, little-endian; returns the next offset."""
    for j in range(first, first + count):
        v = bits[j]
        for k in range(8):
            out[at] = (v >> np.uint64(8 * k)) & np.uint64(0xFF)
            at += 1
    return at
