"""A grid agent process's answer to one observation, envelope included, in one
compiled call.

The world packs every observation the same way (`swarm.protocol.observations`:
a msgpack map of v, type, tick, ints, pf, in that order), so the agent reads
those bytes where they stand instead of unpacking a dict, steps its agents
(`dispatch.answer_rows`), and writes the action message's msgpack bytes as
`swarm.protocol.pack_actions` would (tests hold the two byte for byte).  Any
other message - a stop, a resumed run's memory, a wake, anything malformed -
is left to the Python parser, which says what it is or why it is refused.
Every read is bounds-checked: a short or lying buffer is NOT_PLAIN, never a
read past its end.
"""

import numpy as np
from numba import njit

from agents.controllers.dispatch import answer_rows
from swarm.protocol import ACT_ROW, ENVELOPE, FAMILY_GRID, NOT_PLAIN, R_MARKED, VERSION

# The fixed bytes of both messages (msgpack: fixmap of 5, fixstr keys, in the order swarm.protocol packs them).
_OBS_HEAD = np.frombuffer(b"\x85\xa1v" + bytes([VERSION]) + b"\xa4type\xa3obs\xa4tick", np.uint8).copy()
_ACT_HEAD = np.frombuffer(b"\x85\xa1v" + bytes([VERSION]) + b"\xa4type\xa3act\xa6family\xa4" + FAMILY_GRID.encode()
                          + b"\xa4tick", np.uint8).copy()  # fmt: skip
_INTS_KEY = np.frombuffer(b"ints", np.uint8).copy()
_PF_KEY = np.frombuffer(b"pf", np.uint8).copy()
_ROWS_KEY = np.frombuffer(b"\xa4rows", np.uint8).copy()


@njit(cache=True)
def _tagged(buf, at, first_tag, widths):
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
def _read_int(buf, at):
    """(value, next offset) of a non-negative msgpack integer at `at`, or (-1, -1)."""
    if at < len(buf) and buf[at] <= 0x7F:
        return np.int64(buf[at]), at + 1
    return _tagged(buf, at, 0xCC, 4)  # uint 8, 16, 32, 64


@njit(cache=True)
def _read_bin(buf, at):
    """(start, length) of a msgpack bin at `at`, or (-1, -1)."""
    length, start = _tagged(buf, at, 0xC4, 3)  # bin 8, 16, 32
    if start < 0 or start + length > len(buf):
        return -1, -1
    return start, length


@njit(cache=True)
def _words(buf, at, count):
    """`count` little-endian 64-bit words from `at`, at any alignment."""
    out = np.empty(count, np.uint64)
    for j in range(count):
        v = np.uint64(0)
        for k in range(8):
            v |= np.uint64(buf[at + 8 * j + k]) << np.uint64(8 * k)
        out[j] = v
    return out


@njit(cache=True)
def _key(buf, at, key):
    """The offset after fixstr `key` at `at`, or -1."""
    m = len(key)
    if at + 1 + m > len(buf) or buf[at] != 0xA0 | m:
        return -1
    for k in range(m):
        if buf[at + 1 + k] != key[k]:
            return -1
    return at + 1 + m


@njit(cache=True)
def _write_tagged(out, at, v, first_tag, widths):
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
def answer_message(kind, buf, mems, slot_of, rows, params, seed, null, out, info):
    """Answer the observation in `buf` into `out` (the action message's bytes);
    returns their length, -1 for an observation whose blocks are malformed (not
    answered, as `answer_rows` says), or NOT_PLAIN.  `info`: rows written,
    whether any row put a mark write, the tick."""
    header, act_header, rows_key = _OBS_HEAD, _ACT_HEAD, _ROWS_KEY
    n = len(buf)
    if n < len(header):
        return NOT_PLAIN
    for k in range(len(header)):
        if buf[k] != header[k]:
            return NOT_PLAIN
    tick, at = _read_int(buf, len(header))
    if at < 0:
        return NOT_PLAIN
    at = _key(buf, at, _INTS_KEY)
    if at < 0:
        return NOT_PLAIN
    ints_at, ints_len = _read_bin(buf, at)
    if ints_at < 0:
        return NOT_PLAIN
    at = _key(buf, ints_at + ints_len, _PF_KEY)
    if at < 0:
        return NOT_PLAIN
    pf_at, pf_len = _read_bin(buf, at)
    if pf_at < 0 or pf_at + pf_len != n:
        return NOT_PLAIN
    if ints_len % 8 or pf_len % 8:
        return -1
    ints = _words(buf, ints_at, ints_len // 8).view(np.int64)
    pf = _words(buf, pf_at, pf_len // 8).view(np.float64)
    got = answer_rows(kind, ints, pf, mems, slot_of, rows, params, seed, tick, null)
    if got < 0:
        return -1
    marked = 0
    for i in range(got):
        marked |= rows[i, R_MARKED]
    info[0], info[1], info[2] = got, marked, tick
    size = got * ACT_ROW * 8
    if len(out) < ENVELOPE + size:
        return -1
    at = 0
    for k in range(len(act_header)):
        out[at] = act_header[k]
        at += 1
    if tick <= 0x7F:  # positive fixint
        out[at] = tick
        at += 1
    else:
        at = _write_tagged(out, at, tick, 0xCC, 4)  # uint 8, 16, 32, 64
    for k in range(len(rows_key)):
        out[at] = rows_key[k]
        at += 1
    at = _write_tagged(out, at, size, 0xC4, 3)  # bin 8, 16, 32
    for i in range(got):
        for c in range(ACT_ROW):
            v = np.uint64(rows[i, c])
            for k in range(8):
                out[at] = (v >> np.uint64(8 * k)) & np.uint64(0xFF)
                at += 1
    return at

