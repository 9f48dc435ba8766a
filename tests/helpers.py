"""Small helpers shared by the tests."""

import importlib.util
import sys
from pathlib import Path

import numpy as np

from swarm.scenario import parse_scenario_text
from world_server.grid.face.layout import MARK_NONE
from world_server.grid.scenario import Scenario
from world_server.grid.world import L_BFS, L_MARK, L_OBST


def ascii_scenario(rows: list[str], **fields) -> Scenario:
    head = "\n".join(f"{k} = {v!r}" if isinstance(v, str) else f"{k} = {v}" for k, v in fields.items())
    body = "\n".join(rows)
    return parse_scenario_text(f'{head}\n[map]\nascii = """\n{body}\n"""\n', "test.toml")


def maze_rows(height: int, width: int, seed: int) -> list[str]:
    """A perfect maze (depth-first carving), base in a corner: every corridor
    is a dead end or a junction, the hardest case for a wavefront."""
    rng = np.random.default_rng(seed)
    h, w = 2 * height + 1, 2 * width + 1
    grid = np.full((h, w), "#")
    stack = [(0, 0)]
    seen = {(0, 0)}
    grid[1, 1] = "."
    while stack:
        r, c = stack[-1]
        options = [(r + dr, c + dc) for dr, dc in ((-1, 0), (1, 0), (0, -1), (0, 1))
                   if 0 <= r + dr < height and 0 <= c + dc < width and (r + dr, c + dc) not in seen]  # fmt: skip
        if not options:
            stack.pop()
            continue
        nr, nc = options[rng.integers(len(options))]
        grid[2 * nr + 1, 2 * nc + 1] = "."
        grid[r + nr + 1, c + nc + 1] = "."
        seen.add((nr, nc))
        stack.append((nr, nc))
    grid[1, 1] = "B"
    grid[h - 2, w - 2] = "R"
    return ["".join(row) for row in grid]


def lemma41_violations(layers: np.ndarray, base: tuple[int, int]) -> int:
    """Marked non-base cells with no strictly lower marked 4-neighbour."""
    marks = layers[L_MARK]
    h, w = marks.shape
    padded = np.full((h + 2, w + 2), MARK_NONE, dtype=np.int64)
    padded[1:-1, 1:-1] = np.where(layers[L_OBST] != 0, MARK_NONE, marks)
    lowest = np.minimum.reduce([padded[:-2, 1:-1], padded[2:, 1:-1], padded[1:-1, :-2], padded[1:-1, 2:]])
    bad = (marks != MARK_NONE) & (lowest >= marks)
    bad[base] = False
    return int(bad.sum())


def marks_equal_bfs(layers: np.ndarray) -> bool:
    reachable = layers[L_BFS] >= 0
    return bool((layers[L_MARK][reachable] == layers[L_BFS][reachable]).all())


def load_script(name: str):
    """A module of scripts/ (not a package), imported as the script runs it."""
    path = Path(__file__).resolve().parents[1] / "scripts" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # a dataclass in it looks its module up there
    spec.loader.exec_module(module)
    return module
