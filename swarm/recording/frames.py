"""A recording cut short by a kill: the whole frames before the cut.

An .rrd file is a 12-byte stream header ("RRF2", version, options) and then
frames, each a 16-byte header (kind, payload length: little-endian u64) and its
payload.  rerun writes each batch the recorder hands it at once, so a world
killed mid-run leaves every batch but perhaps the last one's frames whole;
rerun's reader refuses the whole file over one cut frame, so the reader is
given the whole frames only.
"""

from __future__ import annotations

import contextlib
import struct
import tempfile
from collections.abc import Iterator
from pathlib import Path

MAGIC = b"RRF2"
STREAM_HEADER = 12
FRAME_HEADER = 16


def whole_length(data: bytes) -> int | None:
    """How many leading bytes of `data` are whole frames; None: not a rerun stream."""
    if not data.startswith(MAGIC) or len(data) < STREAM_HEADER:
        return None
    at = STREAM_HEADER
    while at + FRAME_HEADER <= len(data):
        _, length = struct.unpack_from("<QQ", data, at)
        if at + FRAME_HEADER + length > len(data):
            break
        at += FRAME_HEADER + length
    return at


@contextlib.contextmanager
def whole_frames(path: Path) -> Iterator[Path | None]:
    """A temporary copy of `path`'s whole frames; None when there is no cut frame to leave out
    (a whole file, or not a rerun stream: the reader says what is wrong)."""
    data = Path(path).read_bytes()
    whole = whole_length(data)
    if whole is None or whole in (STREAM_HEADER, len(data)):
        yield None
        return
    with tempfile.TemporaryDirectory(prefix="swarm-cut-") as folder:
        copy = Path(folder) / Path(path).name
        copy.write_bytes(data[:whole])
        yield copy
