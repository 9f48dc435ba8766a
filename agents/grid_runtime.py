"""The grid family's agent process: one compiled call checks and steps a whole batch."""

from __future__ import annotations

from contextlib import contextmanager
from functools import partial

import numpy as np

from agents.controllers import CONTROLLERS
from agents.runtime import AgentRuntime
from swarm.core import kernels, wire
from swarm.core.errors import RunError
from world_server.grid.face import wire as proto
from world_server.grid.face.layout import CONTROLLERS as BUNDLED
from world_server.grid.face.layout import controller_kind, new_memory
from world_server.grid.face.own import GridController, compile_line


def load_step():
    """(`envelope.answer_message`, `dispatch.answer_rows`): the ahead-of-time build's
    when it exists (no numba in this process), else the JIT's (compiled or loaded
    from the cache now)."""
    built = kernels.load("answer_message"), kernels.load("answer_rows")
    if None not in built:
        return built
    from agents.controllers.grid.dispatch import answer_rows
    from agents.controllers.grid.envelope import answer_message, warm_up

    warm_up()
    return answer_message, answer_rows


def load_own_step(name: str, own: GridController):
    """The same two calls compiled around a user's step (its `kind`), by the JIT now: a user's
    step is no part of the ahead-of-time build.  A step that does not compile is one line."""
    from agents.controllers.grid.dispatch import own_step, rows_with
    from agents.controllers.grid.envelope import message_with, warm_up

    try:
        warm_up(own.step)
    except Exception as exc:  # numba's typing and lowering errors: many lines, the cause in one of them
        raise RunError(compile_line(name, exc)) from None
    return partial(message_with, own_step), partial(rows_with, own_step)


class GridAgentRuntime(AgentRuntime):
    """Grid controllers: one compiled call checks and steps the whole batch
    (`dispatch.answer_rows`); memory per agent."""

    family = wire.FAMILY_GRID

    def _prepare(self, count: int) -> None:
        own = CONTROLLERS[self.controller].make() if self.controller not in BUNDLED else None
        if own is not None and not isinstance(own, GridController):
            raise RunError(f"controller {self.controller!r} is not a grid controller")
        # the bundled step (its kind code), or a user's step passed to the same compiled loops as their "kind"
        self.kind = controller_kind(self.controller) if own is None else own.step
        self.answer_message, self.answer_rows = load_step() if own is None else load_own_step(self.controller, own)
        self.mem = new_memory(count)
        self.rows = np.zeros((count, proto.ACT_ROW), dtype=np.int64)  # the action rows, reused
        # The action message's bytes and the call's info (rows, any mark write, tick): the compiled call
        # writes them through numpy views, the short way reads them without numpy (a slice, a memoryview).
        self.out_bytes = bytearray(proto.ENVELOPE + count * proto.ACT_ROW * 8)
        self.out = np.frombuffer(self.out_bytes, dtype=np.uint8)
        info = bytearray(3 * 8)
        self.info, self.rows_written = np.frombuffer(info, dtype=np.int64), memoryview(info).cast("q")
        self.slot_table = np.full(0, -1, dtype=np.int64)  # agent id -> its slot (memory row), -1: not ours
        self.seed = 0
        self.params = np.zeros(1)

    def _welcomed(self, slot: int, agent: int, msg: dict) -> None:
        self.seed = int(msg["seed"])  # a Python int: no numpy scalar to convert at every call
        self.params = np.array(msg["params"], dtype=np.float64)
        # the slot's memory: fresh, or where a resumed run's agent was saved (this one takes it over)
        self.mem[slot] = msg.get("memory", new_memory(1)[0])
        self.slot_table[self.slot_table == slot] = -1
        if agent >= len(self.slot_table):
            self.slot_table = np.concatenate([self.slot_table, np.full(agent + 1 - len(self.slot_table), -1)])
        self.slot_table[agent] = slot

    def _parse(self, data: bytes):
        return proto.obs_blocks(data)

    def _answer_raw(self, raw: bytes) -> int | None:
        """Step every agent of ours in the observation and send the action
        message, envelope and all from one compiled call (`envelope`); mark
        writes ride the action rows."""
        with self._told():
            size = self.answer_message(self.kind, raw, self.mem, self.slot_table, self.rows,
                                       self.params, self.seed, self.null, self.out, self.info)  # fmt: skip
        if size == proto.NOT_PLAIN:
            return None
        if size < 0:
            self.rejected["obs: malformed"] += 1
            return 0  # not answered (the world counts the miss)
        self.act_publisher.put(self.out_bytes[:size])
        return self.rows_written[0]

    @contextmanager
    def _told(self):
        """A user's step that raises, or answers an action the world refuses (dispatch.own_step), ends
        the process in one line naming the controller, as it ends an in-process run."""
        try:
            yield
        except Exception as exc:
            if isinstance(self.kind, int):  # a bundled step's error is ours: its traceback tells where
                raise
            raise RunError(compile_line(self.controller, exc)) from None

    def _restore(self, memory: proto.Memory) -> None:
        for agent, *words in memory.rows.tolist():
            if (slot := self.slot_of.get(agent)) is not None:
                self.mem[slot] = words

    def _answer(self, obs: proto.ObsBlocks) -> int:
        """An observation in another layout than our world's (its keys in another
        order, say): the same step through the parsed blocks."""
        with self._told():
            n = self.answer_rows(self.kind, np.frombuffer(obs.ints, "<i8"), np.frombuffer(obs.pf, "<f8"), self.mem,
                                 self.slot_table, self.rows, self.params, self.seed, obs.tick, self.null)  # fmt: skip
        if n < 0:
            self.rejected["obs: malformed"] += 1
            return 0  # not answered (the world counts the miss)
        self.act_publisher.put(proto.pack_actions(obs.tick, self.rows[:n]))
        return n
