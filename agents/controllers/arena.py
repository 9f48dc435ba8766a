"""The face every arena controller shows both engines.

An arena controller is an object (it carries maps, fields or neurons):
`reset(seed, agent, params)` once, then `step(perception) -> (left, right)`
wheel speeds in m/s each tick, or (left, right, act) for a robot with a
metabolism (world_server.arena.metabolism.ACTS).  It sees only its robot's sensors (the
perception dict) and what its paper gives the robot beforehand (`params`:
the map it is given, its goal or route, its body's limits).
`snapshot()` / `restore()` make a resumed run bit-equal (a snapshot may
share its arrays with the controller: encode or copy it before the next step); `record()` returns
what a reviewer should see.  The in-process engine holds N of them; an agent
process holds K.
"""

from __future__ import annotations

import sys
from typing import Any, Protocol

import numpy as np

from agents.controllers import CONTROLLERS
from swarm.core.errors import RunError, one_line

MAX_SHARE_BYTES = 4 * 1024 * 1024


class ArenaController(Protocol):
    def reset(self, seed: int, agent: int, params: dict[str, Any]) -> None: ...

    def step(self, perception: dict[str, np.ndarray]) -> np.ndarray: ...

    def snapshot(self) -> dict[str, Any]: ...

    def restore(self, state: dict[str, Any]) -> None: ...

    def record(self) -> dict[str, np.ndarray]: ...

    # Optional: atomic_restore = True when restore() checks the whole state before it writes any of it, so
    # that one raising has changed nothing (the agent then keeps no rollback copy of the old state).
    # Optional: restore_copies = True when restore() copies the arrays it is given into its own and keeps
    # none of them: it is then given read-only views of the message that carried its memory, not copies.
    # Optional: broadcast() -> bytes (or None: as before) its robot sends its range-and-bearing neighbours
    # this tick (world_server/arena/face/sensors/range_bearing.py); read after step(), in both runtimes.
    # Optional: route() -> the path (N x 2 metres) a controller follows, or None.  An agent process asks
    # for it every tick to send a new plan to the recording, so it must be cheap (record() need not be).


def as_action(step_result) -> np.ndarray:
    """A controller's answer as the world's action row: (left, right, act), the
    act 0 (none) when it gave only wheel speeds.  Anything else goes on as it is,
    for the world to judge and count."""
    a = np.asarray(step_result, np.float64).ravel()
    if len(a) == 2:
        return np.array([a[0], a[1], 0.0])
    return a if len(a) == 3 else np.full(3, np.nan)


ON_ERROR = ("idle", "stop")  # what a run does with a robot whose controller raised: hold it still, or end


class ControllerFailed(RunError):
    """A controller raised (or answered NaN or the wrong shape) and the run was told to stop on it."""


FAILED = "swarm_controller_failed"  # the only key of a saved memory whose controller had failed


class StepGuard:
    """Steps controllers as both runtimes must, so that a user's controller that raises, answers NaN
    or the wrong shape is one line naming it, not a traceback that ends every robot's run.

    A controller that raises in its step is out of the run: from that tick on its robot holds still (wheel
    speeds 0, a valid answer, so a lock-step world does not wait out its deadline for it) and its
    controller is not asked again (its state may be half-written).  A NaN or wrong-shaped answer
    goes to the world, which refuses and counts it; it is told once per robot.  With on_error
    "stop" either ends the run (ControllerFailed).  Both runtimes do the same, so lock-step runs
    stay equal to in-process ones."""

    def __init__(self, on_error: str = "idle"):
        if on_error not in ON_ERROR:
            raise ValueError(f"on_error {on_error!r}: expected one of {', '.join(ON_ERROR)}")
        self.on_error = on_error
        self.failed: dict[int, str] = {}  # agent -> what its controller raised
        self.told: set[int] = set()

    def reset(self, controller, seed: int, agent: int, params: dict, name: str) -> None:
        """`controller.reset(...)`.  One that raises cannot start (a table it refuses, a map it lacks):
        the run ends in one line whatever `on_error` says, since no robot of it has moved yet."""
        try:
            controller.reset(seed, agent, params)
        except Exception as exc:  # whatever a user's controller raises
            raise ControllerFailed(f"controller {name!r} of robot {agent} cannot start: {one_line(exc)}") from None

    def action(self, controller, perception, agent: int, name: str, tick: int) -> np.ndarray:
        if agent in self.failed:
            return np.zeros(3)
        try:
            answer = controller.step(perception)
        except Exception as exc:  # whatever a user's controller raises
            self._failed(agent, exc, f"controller {name!r} of robot {agent}", f"at tick {tick}")
            return np.zeros(3)
        try:
            action = as_action(answer)
        except (TypeError, ValueError):  # not numbers at all (a dict, a string): a wrong shape
            action = np.full(3, np.nan)
        if not np.isfinite(action).all() and agent not in self.told:
            self.told.add(agent)
            what = "NaN or infinite wheel speeds" if np.size(answer) in (2, 3) else f"shape {np.shape(answer)}"
            self._fault(f"controller {name!r} of robot {agent} answered {what} at tick {tick}",
                        "the world refuses such answers and counts them (rejected actions)")  # fmt: skip
        return action

    def memory(self, controller, agent: int):
        """What a save keeps of a robot's controller: its snapshot, or, once it has failed, why, so that a
        resumed run keeps it out as the uninterrupted run does."""
        return {FAILED: self.failed[agent]} if agent in self.failed else controller.snapshot()

    def resumed_failed(self, memory, agent: int, name: str) -> bool:
        """Whether a saved `memory` says the robot's controller had failed: then it stays out (told once)."""
        if not (isinstance(memory, dict) and set(memory) == {FAILED}):
            return False
        self.failed[agent] = str(memory[FAILED])
        print(f"swarm: controller {name!r} of robot {agent} had raised {self.failed[agent]} before the run was saved;"
              f" the robot holds still for the rest of the run", file=sys.stderr, flush=True)  # fmt: skip
        return True

    def working(self, pairs) -> tuple[list, list]:
        """The (controller, agent) pairs still in the run, as (controllers, agents): only they publish,
        receive, broadcast and save."""
        kept = [(c, a) for c, a in pairs if a not in self.failed]
        return [c for c, _ in kept], [a for _, a in kept]

    def _failed(self, agent: int, exc: Exception, who: str, when: str) -> None:
        self.failed[agent] = one_line(exc)
        self._fault(f"{who} raised {self.failed[agent]} {when}", "the robot holds still for the rest of the run")

    def _fault(self, what: str, then: str) -> None:
        if self.on_error == "stop":
            raise ControllerFailed(f"{what}; the run stops (--on-controller-error idle lets it go on)")
        print(f"swarm: {what}; {then} (--on-controller-error stop ends the run instead)", file=sys.stderr, flush=True)


def record_of(controller) -> tuple[dict, str | None]:
    """(its record(), None), or ({}, why it gives none: it raised, or gave no dict), so that the
    recorder and the agent processes leave a user's broken record() out the same way, in one line."""
    try:
        record = controller.record()
    except Exception as exc:  # whatever a user's controller raises
        return {}, f"it raised {one_line(exc)}"
    return (record, None) if isinstance(record, dict) else ({}, f"it gave {str(record)[:80]!r}, not a dict")


def make_controller(name: str) -> ArenaController:
    """A fresh controller of the registry's entry `name` (agents.controllers.CONTROLLERS)."""
    return CONTROLLERS[name].make()


def publications(controllers, agents) -> list[tuple[int, str, bytes]]:
    """(agent, share, msgpack payload) of every controller that has something to publish, in agent order."""
    from swarm.core.wire import pack

    out = []
    for a, c in zip(agents, controllers, strict=True):
        share = getattr(c, "shares", None)
        if share and (data := c.publish()) is not None:
            out.append((int(a), share, pack(data)))
    return out


def broadcasts(controllers, agents) -> list[tuple[int, bytes]]:
    """(agent, bytes) of every controller that broadcasts this tick (its optional `broadcast()`), in
    agent order: the world hands them to its range-and-bearing neighbours at the next tick."""
    out = []
    for a, c in zip(agents, controllers, strict=True):
        send = getattr(c, "broadcast", None)
        if send is not None and (data := send()) is not None:
            out.append((int(a), bytes(data)))
    return out


def deliver(controllers, agents, shared: list[tuple[int, str, bytes]]) -> int:
    """Hand every controller what the others of its share published (not its own), in agent order.
    Returns the payloads refused (undecodable or malformed: counted, nothing of them merged)."""
    from swarm.core.wire import Rejected, unpack

    refused = 0
    for a, c in zip(agents, controllers, strict=True):
        share = getattr(c, "shares", None)
        if not share:
            continue
        for sender, s, payload in shared:
            if s != share or sender == a:
                continue
            data = unpack(payload, MAX_SHARE_BYTES)
            if isinstance(data, Rejected):
                refused += 1
                continue
            try:
                c.receive(sender, data)
            except ValueError:
                refused += 1
    return refused
