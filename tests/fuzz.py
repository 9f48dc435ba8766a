"""What the fuzz tests share: their hypothesis settings, msgpack-aware mutations of valid messages, and the
check every decoded input must pass (a result or a `Rejected` the code names, counted by reason).

The default settings keep the suite fast and reproducible (200 examples a property, derandomized);
`SWARM_FUZZ=long` runs thousands per property, randomly (`--hypothesis-seed=N` repeats one run), and
`-s` prints the rejections counted by reason (docs/testing.md)."""

from __future__ import annotations

import ast
import math
import os
import re
import signal
import tracemalloc
from collections import Counter
from collections.abc import Callable, Iterator
from contextlib import contextmanager, suppress
from pathlib import Path
from typing import Any

import msgpack
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st

from swarm.core.wire import Rejected

ROOT = Path(__file__).resolve().parents[1]
settings.register_profile("fuzz-default", max_examples=200, deadline=None, derandomize=True, database=None,
                          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])  # fmt: skip
settings.register_profile("fuzz-long", max_examples=5000, deadline=None, database=None,
                          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])  # fmt: skip
LONG = os.environ.get("SWARM_FUZZ") == "long"
FUZZ = settings.get_profile("fuzz-long" if LONG else "fuzz-default")  # a decorator: `@FUZZ` on each property
HANG_SECONDS = 10.0  # one input decoded (or one scenario parsed) longer than this is a hang
ALLOCATION_SLACK = 4 * 1024 * 1024  # bytes a decoder may allocate beyond a few copies of its input

TALLY: Counter = Counter()  # (decoder, reason) -> rejections seen in this process
ACCEPTED: Counter = Counter()  # decoder -> inputs it decoded

# ----------------------------------------------------------------- reasons


def reason_patterns(*modules: str) -> list[re.Pattern]:
    """Every reason the decoders' source names: each `Rejected("...")` or `Rejected(f"...")` in `modules`
    (paths from the repository root) as a pattern, a formatted field matching any text."""
    patterns = []
    for module in modules:
        for node in ast.walk(ast.parse((ROOT / module).read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "Rejected" and node.args:
                arg = node.args[0]
                parts = arg.values if isinstance(arg, ast.JoinedStr) else [arg]
                text = "".join(re.escape(p.value) if isinstance(p, ast.Constant) else ".+" for p in parts)
                patterns.append(re.compile(text, re.DOTALL))
    return patterns


def check(decoder: str, result: Any, accepted: type | tuple, reasons: list[re.Pattern]) -> Any:
    """`result` is a decoded message of the `accepted` types, or a `Rejected` whose reason is one line the
    decoders name; each rejection is tallied under `decoder`."""
    if isinstance(result, Rejected):
        reason = result.reason
        assert isinstance(reason, str) and reason and "\n" not in reason and len(reason) <= 200, repr(reason)
        assert any(p.fullmatch(reason) for p in reasons), f"{decoder}: a reason no decoder names: {reason!r}"
        TALLY[decoder, reason] += 1
    else:
        assert isinstance(result, accepted), f"{decoder} gave a {type(result).__name__}"
        ACCEPTED[decoder] += 1
    return result


def tally_table() -> str:
    """The inputs decoded and the rejections counted so far, by decoder and reason (most frequent first)."""
    width = max((len(d) for d, _ in TALLY), default=0)
    rows = [(count, d, "(decoded)") for d, count in ACCEPTED.most_common()]
    rows += [(count, d, reason) for (d, reason), count in TALLY.most_common()]
    return "\n".join(f"{count:8d}  {d:<{width}}  {reason}" for count, d, reason in rows)


# ------------------------------------------------------------ the guard


@contextmanager
def guarded(data_size: int | None = None) -> Iterator[None]:
    """Fail on a hang (SIGALRM after HANG_SECONDS) and, given the input's size, on an allocation far beyond
    it (a claimed length believed).  Main thread only, as pytest runs tests."""

    def hang(signum, frame):
        raise TimeoutError(f"no answer within {HANG_SECONDS} s")

    previous = signal.signal(signal.SIGALRM, hang)
    signal.setitimer(signal.ITIMER_REAL, HANG_SECONDS)
    tracing = data_size is not None and not tracemalloc.is_tracing()
    if tracing:
        tracemalloc.start()
    try:
        yield
        if tracing:
            peak = tracemalloc.get_traced_memory()[1]
            assert peak <= 4 * data_size + ALLOCATION_SLACK, f"{peak} bytes allocated for a {data_size}-byte input"
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
        if tracing:
            tracemalloc.stop()


def decode(decoder: str, fn: Callable, data: Any, accepted: type | tuple, reasons: list[re.Pattern], *args) -> Any:
    """`fn(data, *args)` under the guard, then `check`ed."""
    size = len(data) if isinstance(data, bytes | bytearray | memoryview) else 0
    with guarded(size):
        result = fn(data, *args)
    return check(decoder, result, accepted, reasons)


# ------------------------------------------------------------ mutations

HUGE_HEADERS = [b"\xc6\xff\xff\xff\xff", b"\xdd\xff\xff\xff\xff", b"\xdf\xff\xff\xff\xff", b"\xdb\xff\xff\xff\xff",
                b"\xc9\xff\xff\xff\xff\x01", b"\xc5\xff\xff", b"\xdc\xff\xff", b"\xde\xff\xff", b"\x9f", b"\x8f",
                b"\xc7\xff\x01", b"\xd7\x01", b"\xd8\xff"]  # fmt: skip
ODD_INTS = [0, -1, 1, 2**31, 2**32, 2**53 + 1, 2**63 - 1, 2**63, 2**64 - 1, -(2**63), -(2**31)]
ODD_FLOATS = [math.nan, math.inf, -math.inf, -0.0, 1e308, 5e-324]
DTYPE_NAMES = ["<f8", "<i8", "|u1", "|b1", ">f8", "<f4", "<i4", "|O", "O", "<U4", "|S0", "|V0", "|V8", "<M8[s]",
               "<c16", "(2,)<f8", "xyz", ""]  # fmt: skip


def scalars() -> st.SearchStrategy:
    """Values of every msgpack type, the awkward ones often."""
    return st.one_of(st.none(), st.booleans(), st.sampled_from(ODD_INTS), st.integers(-(2**63), 2**64 - 1),
                     st.sampled_from(ODD_FLOATS), st.floats(), st.text(max_size=12), st.sampled_from(DTYPE_NAMES),
                     st.binary(max_size=40))  # fmt: skip


def values() -> st.SearchStrategy:
    """Any msgpack value: scalars, and lists and maps of them."""
    return VALUES


VALUES = st.recursive(scalars(), lambda inner: st.lists(inner, max_size=4) |
                      st.dictionaries(st.text(max_size=6) | st.integers(-(2**63), 2**64 - 1), inner, max_size=4),
                      max_leaves=8)  # fmt: skip


class Ext(list):
    """An extension's content, decoded so that mutations reach it (a memory's array: [[dtype, shape, bytes]]);
    packed again as its items one after another (none, or two, are mutations too)."""

    code = 0


def _ext_hook(code: int, data: bytes) -> Any:
    try:
        inner = Ext([msgpack.unpackb(data, raw=False, strict_map_key=False, ext_hook=_ext_hook)])
    except Exception:
        return msgpack.ExtType(code, data)
    inner.code = code
    return inner


def _tree(data: bytes) -> Any:
    return msgpack.unpackb(data, raw=False, strict_map_key=False, ext_hook=_ext_hook)


def _packable(value: Any) -> Any:
    if isinstance(value, Ext):
        return msgpack.ExtType(value.code, b"".join(msgpack.packb(_packable(v), use_bin_type=True) for v in value))
    if isinstance(value, list):
        return [_packable(v) for v in value]
    if isinstance(value, dict):
        return {_packable(k): _packable(v) for k, v in value.items()}
    return value


def _pack(value: Any) -> bytes:
    return msgpack.packb(_packable(value), use_bin_type=True)


def _places(value: Any, out: list) -> list:
    """(container, key) of every value inside `value`, depth first."""
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, item in items:
        out.append((value, key))
        _places(item, out)
    return out


@st.composite
def _mutate_value(draw, old: Any) -> Any:
    """A new value for one place: of its own type but odd (a bin cut, grown or flipped; a dtype or shape
    changed; an integer at a boundary) or of another type."""
    if isinstance(old, bytes) and old and draw(st.booleans()):
        at = draw(st.integers(0, len(old) - 1))
        return draw(st.sampled_from([old[:at], old + old[:at] + b"\x00", old[:at] + bytes([old[at] ^ 0xFF]) +
                                     old[at + 1:], old * draw(st.integers(2, 5))]))  # fmt: skip
    if isinstance(old, str) and draw(st.booleans()):
        return draw(st.sampled_from(DTYPE_NAMES) | st.text(max_size=8))
    if isinstance(old, list) and draw(st.booleans()):
        mutated = list(old)
        how = draw(st.sampled_from(["drop", "repeat", "append", "negative"]))
        if how == "drop" and mutated:
            del mutated[draw(st.integers(0, len(mutated) - 1))]
        elif how == "repeat" and mutated:
            mutated += mutated[: draw(st.integers(1, len(mutated)))]
        elif how == "negative":
            mutated = [-1 if isinstance(v, int) else v for v in mutated] or [-1]
        else:
            mutated.append(draw(values()))
        return mutated
    if isinstance(old, int) and not isinstance(old, bool) and draw(st.booleans()):
        return draw(st.sampled_from([*ODD_INTS, old + 1, old - 1, old * 2**20]))
    return draw(values())


@st.composite
def mutate_tree(draw, tree: Any) -> Any:
    places = _places(tree, [])
    if not places:
        return draw(values())
    container, key = draw(st.sampled_from(places))
    how = draw(st.sampled_from(["replace", "replace", "replace", "drop", "add"]))
    if how == "drop":
        del container[key]
    elif how == "add" and isinstance(container, dict):
        container[draw(st.sampled_from(["v", "type", "family", "tick", "agents", "memory", "shared", "rab", "acts",
                                        "keep", "x", "", 1]))] = draw(values())  # fmt: skip
    elif how == "add":
        container.insert(key, draw(values()))
    else:
        container[key] = draw(_mutate_value(container[key]))
    return tree


@st.composite
def _mutate_bytes(draw, data: bytes) -> bytes:
    """Damage below msgpack's structure: cut, flipped or inserted bytes, a header that claims a huge length."""
    at = draw(st.integers(0, len(data)))
    how = draw(st.sampled_from(["cut", "flip", "insert", "claim", "overwrite-claim", "trail"]))
    if how == "cut":
        return data[:at]
    if how == "flip" and data:
        out = bytearray(data)
        for _ in range(draw(st.integers(1, 4))):
            out[draw(st.integers(0, len(out) - 1))] ^= draw(st.integers(1, 255))
        return bytes(out)
    if how in ("claim", "overwrite-claim"):
        header = draw(st.sampled_from(HUGE_HEADERS))
        return data[:at] + header + data[at + (len(header) if how == "overwrite-claim" else 0) :]
    if how == "trail":
        return data + draw(st.binary(min_size=1, max_size=16))
    return data[:at] + draw(st.binary(min_size=1, max_size=16)) + data[at:]


@st.composite
def mutated(draw, valid: bytes | st.SearchStrategy) -> bytes:
    """A valid message (or a strategy of them) after one to three msgpack-aware mutations, and sometimes
    byte-level damage after them; sometimes left whole, so that the decoders' acceptance is exercised too."""
    data = draw(valid) if isinstance(valid, st.SearchStrategy) else valid
    if draw(st.integers(0, 9)) == 0:
        return data
    if draw(st.integers(0, 3)):
        tree = _tree(data)
        for _ in range(draw(st.integers(1, 2))):
            tree = draw(mutate_tree(tree))
        with suppress(OverflowError, TypeError, ValueError):  # an int msgpack cannot hold: left as it was
            data = _pack(tree)
    if draw(st.integers(0, 3)) == 0:
        data = draw(_mutate_bytes(data))
    return data


def inputs(valid: bytes | st.SearchStrategy) -> st.SearchStrategy:
    """What a decoder is fed: random bytes, random msgpack values, or (mostly) mutated valid messages."""
    return st.one_of(st.binary(max_size=256), VALUES.map(_pack), *[mutated(valid)] * 4)


def pack_value(value: Any) -> bytes:
    """`value` as msgpack, extensions kept (for strategies that build odd messages directly)."""
    return _pack(value)
