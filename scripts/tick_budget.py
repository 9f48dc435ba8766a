"""The tick budget of a big distributed run, from costs measured on this project's benchmarks.

A model, not a measurement: it adds up what one lock-step tick costs the world host (sensing,
physics, reading and writing the agents' messages), the network (bytes through the world host's
link, router hops) and the slowest agent host, for a run spread over hosts, with the world whole
or split into regions (each region's owner simulates its robots and a ghost band of its neighbours'
robots within sensing range, and hands over the robots that cross its border).  docs/scale.md
explains every input and what the table says.

    python scripts/tick_budget.py                         # 10,000 laser robots over 20 hosts
    python scripts/tick_budget.py --robots 100000 --sensor animat
    python scripts/tick_budget.py --world-cores 16 --link-gbit 10
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass, replace

# Measured on this 2-core machine (the commands in docs/scale.md); per core, per robot or per message.
# rays per CPU-second of the whole sensing (noise and read-outs included), one thread, per suite: swarm bench
# arena (its cores table for the laser, 8.9-10.7 M; its suite table, 1000 animats and 100 e-pucks)
RAYS_PER_SECOND = {"laser64": 10.4e6, "animat": 6.3e6, "epuck": 4.4e6}
PHYSICS_SECONDS_PER_ROBOT = 3.3e-6  # swarm bench arena: 3.1-3.4 ms a tick for 1000 robots, one thread, idle machine
WORLD_SECONDS_PER_ROBOT_MESSAGE = 0.67e-6  # swarm bench distributed: 0.31 + 0.36 ms for 1000 packed agents
WORLD_SECONDS_PER_PROCESS_MESSAGE = 29e-6  # swarm bench distributed: the world's zenoh thread, 100 processes
AGENT_PARSE_SECONDS = 46e-6  # docs/distributed.md: one robot's arena observation parsed (8 readings)
BEAMS = {"laser64": 64, "animat": 60, "epuck": 8}  # rays per robot and tick (swarm bench arena's suites)
BYTES_PER_BEAM = 4  # float32 readings on the wire
MESSAGE_OVERHEAD_BYTES = 120  # pose, tick, ids and msgpack framing per robot, each way


@dataclass(frozen=True)
class Setup:
    robots: int = 10_000
    sensor: str = "laser64"
    hosts: int = 20  # agent hosts; the world has its own
    world_cores: int = 16  # cores of the world host (and of each region owner)
    agent_cores: int = 16  # cores of each agent host
    robots_per_process: int = 50  # agents packed per agent process (swarm agent --count)
    agent_step_seconds: float = 50e-6  # a controller's step (a laser wanderer; a DFT robot: 1.3 ms)
    parallel_efficiency: float = 0.8  # of the sensing pass over the world's cores (numba prange)
    link_gbit: float = 1.0  # each host's network link
    hop_seconds: float = 150e-6  # one router hop on a LAN, each way
    arena_side_m: float = 200.0  # square arena
    sensing_range_m: float = 4.0  # the ghost band's width
    speed_m_per_tick: float = 0.02  # how far a robot moves in a tick (hand-overs)
    physics_strips: int = 1  # the world's floor in physics strips stepped side by side (docs/arena.md)
    # Amdahl's serial share with strips: swarm bench arena's 10,000 laser robots on two threads, two
    # strips taking 0.63-0.89 (mean 0.748) of one space's time over eleven runs, their ghosts 7% of the robots
    physics_serial_share: float = 0.46
    physics_halo_m: float = 1.06  # a strip's ghost band each side: a laser robot's physics_halo


def sensing(s: Setup, robots: float, cores: int) -> float:
    return robots * BEAMS[s.sensor] / (RAYS_PER_SECOND[s.sensor] * max(1.0, cores * s.parallel_efficiency))


def physics(s: Setup, robots: float, width_m: float) -> float:
    """One space's physics, or the floor's `width_m` in strips: the serial share stays on one thread,
    the rest divides over the strips (the world's cores at most), each stepping its ghosts too."""
    one = robots * PHYSICS_SECONDS_PER_ROBOT
    if s.physics_strips <= 1:
        return one
    ghosts = min(1.0, 2 * s.physics_halo_m * s.physics_strips / width_m)
    parallel = (1 - s.physics_serial_share) * (1 + ghosts) / min(s.physics_strips, s.world_cores)
    return one * (s.physics_serial_share + parallel)


def message_bytes(s: Setup) -> int:
    return BEAMS[s.sensor] * BYTES_PER_BEAM + MESSAGE_OVERHEAD_BYTES


def tick(s: Setup, regions: int = 1) -> dict[str, float]:
    """Seconds of one tick, part by part, with the world split into `regions` square regions."""
    side = math.sqrt(regions)
    region_side = s.arena_side_m / side
    # the ghost band: robots within sensing range of a neighbour's border, simulated by both owners
    ghost = 0.0 if regions == 1 else min(1.0, 4 * s.sensing_range_m / region_side)
    owned = s.robots / regions
    simulated = owned * (1 + ghost)
    processes = math.ceil(owned / s.robots_per_process)
    world = (
        sensing(s, simulated, s.world_cores)
        + physics(s, simulated, region_side)
        + owned * WORLD_SECONDS_PER_ROBOT_MESSAGE
        + processes * WORLD_SECONDS_PER_PROCESS_MESSAGE
    )
    wire = owned * message_bytes(s) * 8 / (s.link_gbit * 1e9)  # through the owner's link, both ways overlap
    per_host = s.robots / s.hosts
    agents = per_host * (s.agent_step_seconds + AGENT_PARSE_SECONDS) / s.agent_cores
    hops = 4 * s.hop_seconds  # world -> its router -> the agent host's router -> agent, and back
    exchange = 0.0
    if regions > 1:  # the ghost band's state and the hand-overs go to the (up to 8) neighbours once a tick
        handed = owned * 4 * s.speed_m_per_tick / region_side
        exchange = 2 * s.hop_seconds + (owned * ghost + handed) * 64 * 8 / (s.link_gbit * 1e9)
    total = world + max(wire, agents) + hops + exchange
    return {"world": world, "wire": wire, "agents": agents, "hops": hops, "exchange": exchange, "total": total}


def table(s: Setup, splits: tuple[int, ...]) -> str:
    rows = ["| regions | world ms | wire ms | agent host ms | hops ms | region exchange ms | tick ms | ticks/s |",
            "|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for k in splits:
        t = tick(s, k)
        rows.append(f"| {k} | {t['world'] * 1e3:.1f} | {t['wire'] * 1e3:.1f} | {t['agents'] * 1e3:.1f} | "
                    f"{t['hops'] * 1e3:.1f} | {t['exchange'] * 1e3:.2f} | {t['total'] * 1e3:.1f} | "
                    f"{1 / t['total']:.1f} |")  # fmt: skip
    return "\n".join(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    defaults = Setup()
    for name, value in vars(defaults).items():
        parser.add_argument(f"--{name.replace('_', '-')}", type=type(value), default=value,
                            choices=sorted(BEAMS) if name == "sensor" else None)  # fmt: skip
    parser.add_argument("--splits", default="1,4,16,64", help="region counts to compare (square numbers)")
    args = vars(parser.parse_args())
    splits = tuple(int(k) for k in args.pop("splits").split(","))
    setup = replace(defaults, **args)
    print(f"{setup.robots:,} {setup.sensor} robots over {setup.hosts} agent hosts; world host(s) of "
          f"{setup.world_cores} cores, {setup.link_gbit:g} Gbit/s links\n")  # fmt: skip
    print(table(setup, splits))


if __name__ == "__main__":
    main()
