"""Small arena scenarios for the tests."""

from swarm.scenario import parse_arena_text

BOX = """
kind = "arena"
size = [{w}, {h}]
robot = "{robot}"
noise = "{noise}"
max_ticks = {max_ticks}
[[wall]]
rect = [0.0, 0.0, {w}, 0.02]
[[wall]]
rect = [0.0, {h2}, {w}, {h}]
[[wall]]
rect = [0.0, 0.0, 0.02, {h}]
[[wall]]
rect = [{w2}, 0.0, {w}, {h}]
"""


def box(body: str = "", w: float = 1.0, h: float = 1.0, robot: str = "epuck", noise: str = "none",
        max_ticks: int = 200) -> str:  # fmt: skip
    """A walled w x h box (2 cm walls) plus `body` (more walls, groups...)."""
    head = BOX.format(w=w, h=h, w2=w - 0.02, h2=h - 0.02, robot=robot, noise=noise, max_ticks=max_ticks)
    return head + body


def arena(body: str, **kw):
    return parse_arena_text(box(body, **kw), "test.toml")


def rrd_rows(path) -> dict[str, int]:
    """Rows per entity path of a recording, read back through rerun's reader."""
    from rerun.chunk import RrdReader

    rows: dict[str, int] = {}
    for chunk in RrdReader(path).stream():
        rows[chunk.entity_path.lstrip("/")] = rows.get(chunk.entity_path.lstrip("/"), 0) + chunk.num_rows
    return rows


def resumed_pair(scenario, ticks: int):
    """(a, b): engine a runs 2 x `ticks`; b is a fresh engine given a's world and controller
    snapshots (through JSON) after the first `ticks`, then runs the rest.  Equal if resume is exact."""
    import json

    from swarm.engines.arena import ArenaEngine

    a = ArenaEngine(scenario)
    a.step(ticks)
    saved_world, saved_goals = a.world.snapshot(), a.goals.snapshot()
    saved = [json.loads(json.dumps(c.snapshot())) for c in a.controllers]
    b = ArenaEngine(scenario)
    b.world.restore(saved_world)
    b.goals.restore(saved_goals)
    for c, state in zip(b.controllers, saved, strict=True):
        c.restore(state)
    a.step(ticks)
    b.step(ticks)
    return a, b


class MapSharer:
    """A robot of the `map` share whose maps `target` (a SharedMap, a ColonyMap) receives: for `deliver`."""

    shares = "map"

    def __init__(self, target):
        self.target = target

    def receive(self, sender, data):
        self.target.receive(sender, data)
