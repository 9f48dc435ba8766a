"""pymunk's cached contacts (its arbiters) as arrays, and back into a space.

Chipmunk warm-starts each contact from the impulses it solved last step and
calls `begin` only for a contact it has not cached.  A physics space rebuilt
from positions and velocities alone would forget both: every touching pair
would start cold and count as a new collision.  These arrays carry what the
rebuilt space needs, with each shape named by a stable key (DiffDrive's:
walls, then robots, then scheduled obstacles) instead of a pointer.

pymunk's own pickling does the same through `_arbiter_to_dict` and
`_arbiter_from_dict`; they are private, so the pinned pymunk version
(pyproject.toml) is what this module is tested against.
"""

from __future__ import annotations

import numpy as np
from pymunk._chipmunk_cffi import lib
from pymunk.arbiter import _arbiter_from_dict, _arbiter_to_dict

MAX_POINTS = 2  # Chipmunk's CP_MAX_CONTACTS_PER_ARBITER
_POINT = ("r1", "r2", "nMass", "tMass", "bounce", "jnAcc", "jtAcc", "jBias", "bias")  # r1, r2 are pairs
_POINT_WIDTH = 11
_HEAD = 6  # e, u, surface_vr (2), n (2)
FLOATS = _HEAD + MAX_POINTS * _POINT_WIDTH
INTS = 6  # a, b (shape keys), count, swapped, stamp, state


def save(space, key_of) -> dict[str, np.ndarray]:
    """Every cached arbiter of `space`; `key_of(shape)` names its shapes."""
    rows = [_arbiter_to_dict(arb, space) for arb in space._get_arbiters()]
    f = np.zeros((len(rows), FLOATS))
    i = np.zeros((len(rows), INTS), np.int64)
    h = np.zeros((len(rows), MAX_POINTS), np.uint64)
    for k, d in enumerate(rows):
        f[k, :_HEAD] = (d["e"], d["u"], *d["surface_vr"], *d["n"])
        for p, c in enumerate(d["contacts"]):
            at = _HEAD + p * _POINT_WIDTH
            f[k, at : at + _POINT_WIDTH] = (*c["r1"], *c["r2"], *(c[name] for name in _POINT[2:]))
            h[k, p] = c["hash"]
        i[k] = (key_of(d["a"]), key_of(d["b"]), d["count"], d["swapped"], d["stamp"], d["state"])
    clock = np.array([lib.cpSpaceGetTimestamp(space._space), lib.cpSpaceGetCurrentTimeStep(space._space)])
    return {"contacts_f": f, "contacts_i": i, "contacts_h": h, "space_clock": clock}


def load(space, state: dict[str, np.ndarray], shape_of) -> None:
    """Put saved arbiters into a rebuilt `space`; `shape_of(key)` finds its shapes."""
    stamp, dt = state["space_clock"]
    lib.cpSpaceSetTimestamp(space._space, int(stamp))
    lib.cpSpaceSetCurrentTimeStep(space._space, float(dt))
    for f, i, h in zip(state["contacts_f"], state["contacts_i"], state["contacts_h"], strict=True):
        count = int(i[2])
        contacts = []
        for p in range(count):
            v = f[_HEAD + p * _POINT_WIDTH : _HEAD + (p + 1) * _POINT_WIDTH].tolist()
            contacts.append({"r1": (v[0], v[1]), "r2": (v[2], v[3]), **dict(zip(_POINT[2:], v[4:], strict=True)),
                             "hash": int(h[p])})  # fmt: skip
        e, u, vx, vy, nx, ny = f[:_HEAD].tolist()
        a, b, _, swapped, stamp, state_ = i.tolist()
        d = {"e": e, "u": u, "surface_vr": (vx, vy), "n": (nx, ny), "a": shape_of(a), "b": shape_of(b),
             "count": count, "contacts": contacts, "swapped": swapped, "stamp": stamp, "state": state_}  # fmt: skip
        lib.cpSpaceAddCachedArbiter(space._space, _arbiter_from_dict(d, space))
