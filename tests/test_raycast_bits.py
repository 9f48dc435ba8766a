"""The sensing pass's readings, bit for bit, against fixed digests: a faster kernel must not move a
single bit.  The digests depend on the platform's maths library (cos, sin, log)."""

import hashlib
import math

import numpy as np
import pytest

from swarm.bench.arena.measure import LASER_BOT, bench_world
from world_server.arena import raycast
from world_server.arena.raycast import MARK, SOLID

# (robots, obstacles, seed, side) -> sha256 of the ray pass (ranges, hits) and of the noisy laser scans
EXPECTED = {
    (60, 20, 1, 10.0): "ecee625d26ca559de866f7dbdfcc4d5126f84c4e3a453dfe5f4906a9dd583e85",
    (200, 40, 2, 14.0): "ec531715a3ba6e15a9f7bec5474c15b5a5562d6c21929d1d9814345a0db9a352",
    (400, 60, 3, 20.0): "9936efdfbc5b53916f0ed1aa0fa5cdbb617e1090a9992521109772c5a460c83d",
}


def _rays(world, seed: int):
    """Random rays in runs of one robot each, in no robot order, some seeing walls only; cosines and
    sines from libm (math), as the kernel's own."""
    rng = np.random.default_rng([seed, 7])
    runs = rng.integers(1, 40, 300)
    robot = np.repeat(rng.integers(0, world.n, len(runs)), runs)
    bearing = rng.uniform(-math.pi, math.pi, len(robot))
    reach = rng.uniform(0.1, 9.0, len(robot))
    mask = np.where(rng.random(len(robot)) < 0.3, SOLID, SOLID | MARK).astype(np.uint8)
    cos_sin = (np.array([math.cos(b) for b in bearing]), np.array([math.sin(b) for b in bearing]))
    return robot, bearing, reach, cos_sin, mask


def _digest(key: tuple, threads: int) -> str:
    robots, obstacles, seed, side = key
    world = bench_world(robots, LASER_BOT, obstacles=obstacles, seed=seed, side=side)
    h = hashlib.sha256()
    try:
        raycast.set_threads(threads)
        ranges, what = world.cast(*_rays(world, seed))
        h.update(ranges.tobytes() + what.tobytes())
        world.in_world[::7] = False  # parked robots: neither cast nor seen
        for _ in range(3):
            for batch in world.perceive_groups():
                h.update(batch["laser"].tobytes())
            world.apply(np.tile([[1.0, 1.2]], (world.n, 1)))
    finally:
        raycast.set_threads(1)
    return h.hexdigest()


@pytest.mark.parametrize("key", list(EXPECTED))
@pytest.mark.parametrize("threads", [1, 2])
def test_readings_are_the_reference_bits(key, threads, monkeypatch):
    monkeypatch.setattr(raycast, "PARALLEL_RAYS", 0)  # every pass over the cores, however small
    monkeypatch.setattr(raycast, "PARALLEL_NORMALS", 0)
    assert _digest(key, threads) == EXPECTED[key]
