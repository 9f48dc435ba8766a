"""Arena controllers that live outside the swarm package, as a user's would: the tests load them
as "circlers:Circler" with this folder on the path, and as an installed package's entry point."""

from __future__ import annotations

from typing import Any

import numpy as np


class Circler:
    """Drives in a circle; its [table] sets the turn."""

    requires = ("ir",)

    def reset(self, seed: int, agent: int, params: dict[str, Any]) -> None:
        self.agent, self.ticks = agent, 0
        self.turn = float(params["table"].get("turn", 0.5))
        self.max_wheel = float(params["robot"]["max_wheel_speed"])

    def step(self, perception: dict[str, np.ndarray]) -> np.ndarray:
        self.ticks += 1
        near = float(np.max(perception["ir"])) if "ir" in perception else 0.0
        v = 0.5 * self.max_wheel
        return np.array([v * (1 - self.turn) - near * 1e-6, v])

    def snapshot(self) -> dict[str, Any]:
        return {"ticks": self.ticks}

    def restore(self, state: dict[str, Any]) -> None:
        self.ticks = int(state["ticks"])

    def record(self) -> dict[str, Any]:
        return {"ticks": self.ticks, "wheels": np.array([1.0 - self.turn, 1.0]), "grid": np.eye(3),
                "trail": np.array([[0.1, 0.1], [0.2, 0.3]]), "note": "left out"}  # fmt: skip

    @staticmethod
    def check_table(table: dict[str, Any]) -> None:
        for key, value in table.items():
            if key != "turn":
                raise ValueError(f"unknown field {key!r}; expected turn")
            if not isinstance(value, int | float) or not 0 <= value <= 1:
                raise ValueError(f"turn: expected a number from 0 to 1, got {value!r}")


class FailsAtTick(Circler):
    """Robot 1 raises at its fifth step; the others drive on."""

    def step(self, perception: dict[str, np.ndarray]) -> np.ndarray:
        if self.agent == 1 and self.ticks == 4:
            raise ZeroDivisionError("a user's bug\nwith a second line")
        return super().step(perception)


class AnswersNaN(Circler):
    def step(self, perception: dict[str, np.ndarray]) -> np.ndarray:
        wheels = super().step(perception)
        return np.array([np.nan, np.nan]) if self.agent == 0 else wheels


class NotAController:
    """Has no step."""

    def reset(self, seed: int, agent: int, params: dict[str, Any]) -> None: ...


class RecordsNowAndThen(Circler):
    """Its record() has a key only on even ticks, another from tick 5 on, and robot 1's record() raises."""

    def record(self) -> dict[str, Any]:
        if self.agent == 1:
            raise RuntimeError("no record today")
        out: dict[str, Any] = {"ticks": self.ticks}
        if self.ticks % 2 == 0:
            out["even"] = 1.0
        if self.ticks >= 5:
            out["late"] = float(self.ticks)
        return out


class FailsInReset(Circler):
    def reset(self, seed: int, agent: int, params: dict[str, Any]) -> None:
        super().reset(seed, agent, params)
        if agent == 0:
            raise KeyError("no such thing")


class AnswersText(Circler):
    def step(self, perception: dict[str, np.ndarray]) -> Any:
        return "forward"
