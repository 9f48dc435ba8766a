"""A grid controller from a user's own package: its compiled step, its memory layout and its table.

The bundled grid controllers share one compiled step that dispatches on a kind code; a user's
controller cannot be a kind of it without editing swarm.  Instead both runtimes' compiled loops
take the step as an argument (numba compiles one specialization per step function), so a user's
`@njit` step runs inside the same loops, with no branch of swarm's dispatch and no Python per
agent.  Everything here is plain data the world process, the engine and the agent processes read
alike; docs/controllers.md shows a whole controller.

Every random choice of a step must come from (seed, agent, tick): `draw_below`, `draw_unit` and
`draw_normal` (swarm.core.rng, re-exported here when asked for: reading a spec imports no numba)
are the counter-based draws the bundled controllers use, so an agent process makes exactly the
in-process run's choices.
"""

from __future__ import annotations

import inspect
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from swarm.core.errors import one_line
from world_server.grid.face.layout import (
    ACT_LEN,
    CONTROLLERS,
    MEM_LEN,
    MODE_NAMES,
    STAY,
    TRAIL_ERASE,
    controller_params,
    new_memory,
)

__all__ = ["GridController", "own_controller", "run_memory", "run_params"]

DRAWS = ("draw_below", "draw_normal", "draw_unit")


def __getattr__(name: str) -> Any:
    """The draws of swarm.core.rng, imported when a step's module asks for them."""
    if name in DRAWS:
        from swarm.core import rng

        return getattr(rng, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


STEP_ARGS = ("perception", "float_perception", "memory", "action", "params", "seed", "agent", "tick")
MAX_PARAMS = 64  # fields of a controller's table (the welcome carries them as a list of floats)
# The action fields a step may get wrong, by the code its check raises (dispatch.own_step).
FAULTS = ("move (expected 0..4)", "trail operation (expected 0..2)", "trail colour (expected >= 0)",
          "load (expected 0 or 1)", "unload (expected 0 or 1)", "deposit (expected 0 or 1)",
          f"mode (expected 0..{len(MODE_NAMES) - 1})", "mark (below UPDATE-VALUE on its cell)")  # fmt: skip
assert ACT_LEN == 8 and STAY == 4 and TRAIL_ERASE == 2  # the ranges FAULTS states


@dataclass(frozen=True)
class GridController:
    """A user's grid controller, named "module:NAME" or by an entry point of `swarm.controllers`.

    `step(pi, pf, mem, act, params, seed, agent, tick)`: a numba `@njit` function writing this
    tick's action into `act` (world_server.grid.face.layout: the perception, action and mode
    codes), given an action reset to "stay, write nothing".  `memory`: its slots in the agent's
    memory row, in order, each (name, words) or (name, words, start value): at most MEM_LEN words
    in all, kept between ticks by whoever runs it and saved for an exact resume.  `parameters`:
    its table's fields and their defaults, in the order `params` holds them.  `marks`: whether it
    writes marks (a run of it may then end "converged")."""

    world: ClassVar[str] = "grid"
    step: Any
    memory: tuple[tuple, ...] = ()
    parameters: tuple[tuple[str, float], ...] = ()
    description: str = ""
    marks: bool = False

    def __post_init__(self) -> None:
        self.check()

    def check(self) -> None:
        """Raise ValueError in one line for a step that is not a numba function of the grid's
        arguments, a memory layout over the row's capacity, or a bad parameter table."""
        if not callable(getattr(self.step, "py_func", None)):
            raise ValueError(f"step {self.step!r} is not a numba @njit function")
        args = tuple(inspect.signature(self.step.py_func).parameters)
        if len(args) != len(STEP_ARGS):
            raise ValueError(f"step {self.step.py_func.__name__}({', '.join(args)}) takes {len(args)} arguments; "
                             f"a grid step takes {len(STEP_ARGS)}: {', '.join(STEP_ARGS)}")  # fmt: skip
        _check_memory(self.memory)
        _check_parameters(self.parameters)

    def slot(self, name: str) -> int:
        """The index of memory slot `name` in the memory row."""
        at = 0
        for slot in self.memory:
            if slot[0] == name:
                return at
            at += slot[1]
        raise KeyError(f"no memory slot {name!r}")

    def start(self) -> np.ndarray:
        """The memory row an agent starts with: each slot's start value (default 0), the rest 0."""
        row, at = np.zeros(MEM_LEN, dtype=np.int64), 0
        for slot in self.memory:
            row[at : at + slot[1]] = slot[2] if len(slot) == 3 else 0
            at += slot[1]
        return row

    def check_table(self, table: dict) -> None:
        """Refuse an unknown field or a value that is not a finite number, in one line."""
        fields = [p[0] for p in self.parameters]
        if unknown := sorted(set(table) - set(fields)):
            raise ValueError(f"unknown field(s) {unknown}; expected {', '.join(fields) or 'none'}")
        for key, value in table.items():
            if isinstance(value, bool) or not isinstance(value, int | float) or not np.isfinite(value):
                raise ValueError(f"{key}: expected a finite number, got {value!r}")

    def params_of(self, table: dict) -> np.ndarray:
        """The float vector `params` the step gets: its table's values over the defaults."""
        self.check_table(table)
        return np.array([float(table.get(name, default)) for name, default in self.parameters], dtype=np.float64)


def _whole(x: Any) -> bool:
    return isinstance(x, int | np.integer) and not isinstance(x, bool)


def _check_memory(memory: Any) -> None:
    """Memory slots: a tuple of (name, words) or (name, words, start value), distinct names, at most
    MEM_LEN words in all; anything else refused in one line before it is used."""
    shaped = isinstance(memory, tuple | list) and all(
        isinstance(s, tuple) and len(s) in (2, 3) and isinstance(s[0], str) and _whole(s[1]) and s[1] >= 1
        and (len(s) == 2 or _whole(s[2])) for s in memory
    )  # fmt: skip
    if not shaped:
        raise ValueError(f"memory {memory!r}: expected a tuple of (name, words) or (name, words, start) with "
                         "words >= 1 and whole-number starts")  # fmt: skip
    names = [s[0] for s in memory]
    if len(set(names)) != len(names):
        raise ValueError(f"memory slots {names}: expected distinct names")
    if (used := sum(s[1] for s in memory)) > MEM_LEN:
        raise ValueError(f"memory layout of {used} words is over the memory row's {MEM_LEN}")


def _check_parameters(parameters: Any) -> None:
    """The table's fields: a tuple of (name, finite number default) pairs, at most MAX_PARAMS distinct names."""
    shaped = isinstance(parameters, tuple | list) and all(
        isinstance(p, tuple) and len(p) == 2 and isinstance(p[0], str) and isinstance(p[1], int | float)
        and not isinstance(p[1], bool) and np.isfinite(p[1]) for p in parameters
    )  # fmt: skip
    if not shaped:
        raise ValueError(f"parameters {parameters!r}: expected a tuple of (name, default) pairs, each default a "
                         "finite number")  # fmt: skip
    fields = [p[0] for p in parameters]
    if len(fields) > MAX_PARAMS or len(set(fields)) != len(fields):
        raise ValueError(f"parameters {fields}: expected at most {MAX_PARAMS} distinct names")


def own_controller(scenario) -> GridController | None:
    """The user's controller a grid scenario names (None: a bundled one)."""
    if scenario.controller in CONTROLLERS:
        return None
    target = scenario.known_controllers[scenario.controller].make()
    if not isinstance(target, GridController):
        raise ValueError(f"controller {scenario.controller!r} is not a grid controller")
    return target


def run_params(scenario) -> np.ndarray:
    """The float parameter vector of a grid scenario's controller, bundled or a user's."""
    own = own_controller(scenario)
    if own is None:
        return controller_params(scenario)
    return own.params_of(scenario.tables.get(scenario.controller, {}))


def run_memory(scenario, n: int) -> np.ndarray:
    """The memory rows `n` agents of a grid scenario's controller start with."""
    own = own_controller(scenario)
    return new_memory(n) if own is None else np.tile(own.start(), (n, 1))


def fault_line(name: str, exc: BaseException) -> str | None:
    """One line for a step's refused action (the ValueError `dispatch.own_step` raises), naming the
    controller; None for any other error."""
    args = exc.args
    if len(args) != 5 or args[0] != "grid action":
        return None
    _, fault, value, agent, tick = args
    return (f"grid controller {name!r} gave robot {agent} an invalid {FAULTS[fault]}: {value} at tick {tick}; "
            "the run ends")  # fmt: skip


def compile_line(name: str, exc: BaseException) -> str:
    """One line for whatever a user's step raised when compiled or run: a refused action
    (`fault_line`), numba's many-line typing error (its first line that names a cause), or the
    exception itself."""
    if (line := fault_line(name, exc)) is not None:
        return line
    if type(exc).__module__.startswith("numba"):
        return f"grid controller {name!r} does not compile: {numba_cause(str(exc))}"
    return f"grid controller {name!r} raised {one_line(exc)}; the run ends"


_WRAPPING = ("Failed in", "During:", "No implementation of", ">>>", "There are", "- Of which", "Overload in",
             "With argument", "Rejected as", "TypingError: Failed", "raised from", "<source elided>")  # fmt: skip


def numba_cause(text: str) -> str:
    """The cause in numba's error text (nested through every compiled caller) and where it is."""
    lines = [t.strip() for t in text.splitlines() if t.strip()]
    for i, line in enumerate(lines):
        if not line.startswith(_WRAPPING):
            where = next((t for t in lines[i + 1 :] if t.startswith('File "')), "")
            return f"{line[:300]}{f' ({where})' if where else ''}"
    return lines[0][:300] if lines else "numba could not compile it"
