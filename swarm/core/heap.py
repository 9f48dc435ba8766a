"""Give freed memory back to the operating system after a burst of large allocations.

An agent process answers the ticks before a save with its controllers'
memory: a DFT robot on `large-maze` packs ~3.4 MB of fields several times over
(the copy, the blob, the action message) and zenoh copies it once more.  glibc
keeps such freed blocks in its heaps (after the first large free it raises its
own mmap threshold), so each save would leave the process ~10 MB larger than
it needs to be, against the 80 MB budget of an agent process.  `malloc_trim`
returns those pages; elsewhere (no glibc) this does nothing.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools


@functools.cache
def _trim():
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        trim = libc.malloc_trim
    except (OSError, AttributeError):  # not glibc: nothing to give back this way
        return None
    trim.argtypes, trim.restype = [ctypes.c_size_t], ctypes.c_int
    return trim


def give_back() -> bool:
    """Return the heaps' free pages to the system; whether anything was returned."""
    trim = _trim()
    return bool(trim(0)) if trim is not None else False
