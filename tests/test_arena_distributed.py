"""The arena over zenoh: a real router, real agent processes, lock-step equal
to the in-process engine pose for pose, bad traffic counted and refused."""

import numpy as np
import pytest

from swarm.core import wire
from swarm.core.bus import open_client
from swarm.engines.arena import ArenaEngine
from swarm.review.report import read_recording, summary_from
from swarm.scenario import load_scenario, parse_scenario_text
from tests.arena_helpers import box
from tests.distributed import ServerThread, free_endpoint, run_world, start_agents, stop
from world_server.arena.face import wire as arena_proto
from world_server.grid.face import wire as proto


def _distributed(scenario, run_id, procs_for, attack=None, **kw):
    return run_world(scenario, run_id, procs_for, attack, deadline=20.0, **kw)


@pytest.mark.parametrize(("ref", "agents", "seed", "noise", "count"), [
    ("zmaze", 1, 0, "high", 1),
    ("large-maze", 4, 3, "low", 2),
])  # fmt: skip
def test_lockstep_arena_equals_in_process_bit_for_bit(ref, agents, seed, noise, count, tmp_path):
    scenario = load_scenario(ref).with_overrides(agents=agents, seed=seed, noise=noise, max_ticks=400)
    engine = ArenaEngine(scenario)
    expected = engine.run()
    rrd = tmp_path / "run.rrd"
    summary, world = _distributed(scenario, f"arena-{ref}-{seed}", [("carrot", agents // count, count)],
                                  record=str(rrd))  # fmt: skip
    np.testing.assert_array_equal(world.pose, engine.world.pose)
    np.testing.assert_array_equal(world.path_length, engine.world.path_length)
    assert summary["ticks"] == expected["ticks"] and summary["robots"] == expected["robots"]
    assert summary["rejected_messages"] == 0 and summary["agents_lost"] == 0
    from rerun.chunk import RrdReader

    entities = {c.entity_path.lstrip("/") for c in RrdReader(rrd).stream()}
    assert {f"world/plans/{a}" for a in range(agents)} <= entities  # the agents sent their plans
    read = summary_from(read_recording(rrd))  # the distributed recording rebuilds the same run
    assert read["ticks"] == summary["ticks"] and read["reached"] == summary["reached"]
    assert [r["path_length"] for r in read["robots"]] == [r["path_length"] for r in summary["robots"]]


MIXED = box(
    '[[group]]\ncount = 2\ncontroller = "carrot"\nstarts = [[0.2, 0.2, 0.0], [0.2, 0.8, 0.0]]\n'
    'goals = [[0.8, 0.8], [0.8, 0.2]]\n'
    '[[group]]\ncount = 2\ncontroller = "wander"\nrobot = "animat"\nclearance = 0.05\n',
    w=3.0, h=3.0, noise="low", max_ticks=300,
)  # fmt: skip


def test_mixed_controllers_and_robots_equal_in_process():
    scenario = parse_scenario_text(MIXED, "mixed.toml")
    engine = ArenaEngine(scenario)
    engine.run()
    _, world = _distributed(scenario, "arena-mixed", [("carrot", 2, 1), ("wander", 1, 2)])
    np.testing.assert_array_equal(world.pose, engine.world.pose)
    assert engine.world.bodies.distance[2:].min() > 0.5  # the wanderers went places


def test_bad_arena_traffic_is_counted_and_never_acted_on():
    scenario = load_scenario("zmaze").with_overrides(max_ticks=60, noise="none")
    engine = ArenaEngine(scenario)
    engine.run()

    def attack(endpoint, keys):
        s = open_client(endpoint)
        try:
            s.put(keys.act("intruder"), b"\x00\xffgarbage")
            s.put(keys.act("intruder"), wire.pack({"type": "act", "family": "arena", "tick": 0}))
            s.put(keys.act("intruder"), arena_proto.actions(0, [0], np.array([[0.1, 0.1]])))  # another's agent
            s.put(keys.act("intruder"), arena_proto.actions(0, [7], np.array([[0.1, 0.1]])))  # unknown agent
            s.put(keys.act("intruder"), wire.pack({"type": "act", "family": "arena", "tick": 0, "agents": [0],
                                                    "wheels": b"short"}))  # fmt: skip
            s.put(keys.act("intruder"), proto.actions(0, [0], np.zeros((1, 8), np.int64), [False]))  # grid family
            s.put(keys.act("intruder"), arena_proto.actions(0, [0], np.array([[0.1, 0.1]]), memory=[(0, b"x")]))
            s.put(keys.act("intruder"), arena_proto.actions(0, [0], np.array([[0.1, 0.1]]), memory=[(5, b"x")]))
            s.put(keys.plan("intruder"), arena_proto.plan_message(0, 0, np.zeros((3, 2))))  # another's plan
            s.put(keys.plan("intruder"), b"\x01plan?")
        finally:
            s.close()

    summary, world = _distributed(scenario, "arena-attack", [("carrot", 1, 1)], attack=attack)
    np.testing.assert_array_equal(world.pose, engine.world.pose)
    assert summary["rejected_messages"] >= 5 and summary["agents_lost"] == 0
    reasons = summary["rejected_by_reason"]
    assert any("not msgpack" in r for r in reasons) and any("wheels" in r for r in reasons)
    assert any("another process" in r or "unknown agent" in r for r in reasons)  # before or after it joined
    assert any("unknown controller family" in r for r in reasons)
    assert reasons.get("plan: names an agent of another process") == 1 and reasons.get("plan: not msgpack") == 1
    assert reasons.get("memory: not with an accepted action before a save") == 1  # another's memory: never stored
    assert reasons.get("act: memory: names an agent the message does not act for") == 1


def test_copies_of_an_agent_process_own_answers_change_nothing():
    """A client floods an agent process's key with copies of its answers, map publications and all, and
    garbage between them: the run, each robot's publications included, ends as in process."""
    from swarm.bench.flood.clients import Floods

    scenario = load_scenario("office").with_overrides(agents=2, seed=3, max_ticks=300, controller="fingerprint")
    engine = ArenaEngine(scenario)
    expected = engine.run()
    endpoint = free_endpoint()
    world = ServerThread(scenario, "arena-copies", endpoint, deadline=20.0).start()
    procs = []
    try:
        with Floods(endpoint, "arena-copies", "arena", ("own",), rate=20_000, nice=19) as floods:
            floods.wait_ready(60)  # listening before the first answer
            procs = start_agents(endpoint, "arena-copies", "fingerprint", 2)
            summary = world.join(timeout=240)
        assert floods.counts()["own"] > 0
    finally:
        stop(procs)
        world.close()
    np.testing.assert_array_equal(world.server.world.pose, engine.world.pose)
    for got, want in zip(summary["robots"], expected["robots"], strict=True):
        assert got.get("shared") == want.get("shared") and got["path_length"] == want["path_length"]
    assert summary["missed_ticks"] == 0
    # copies reached the world and were refused as copies: after the answer in its tick, or late, after it (under
    # load the per-sender budget may drop most of them before they are read)
    refused = summary["rejected_by_reason"]
    assert refused.get("act: second action in one tick", 0) + refused.get("act: not for this tick", 0) > 0, refused


def test_nan_and_huge_wheel_speeds_from_an_agent_are_refused():
    """A hand-made agent process sends NaN, then 50 m/s: both are counted and the robot never moves."""
    import threading
    import time
    import uuid

    scenario = load_scenario("zmaze").with_overrides(max_ticks=4, noise="none")
    endpoint = free_endpoint()
    world = ServerThread(scenario, "arena-nan", endpoint, deadline=1.0, max_misses=10).start()
    s = open_client(endpoint)
    group, nonce = uuid.uuid4().hex, uuid.uuid4().hex
    got: list = []
    sub = s.declare_subscriber(wire.Keys("arena-nan").obs(group), lambda smp: got.append(smp.payload.to_bytes()))
    try:
        keys = wire.Keys("arena-nan")
        for _ in range(50):
            request = wire.join_request(nonce, group, family="arena", controller="carrot")
            replies = list(s.get(keys.join, payload=request, timeout=2.0))
            if replies and replies[0].ok:
                break
            time.sleep(0.1)
        agent = wire.unpack(replies[0].ok.payload.to_bytes(), wire.MAX_WELCOME_BYTES)["agent"]
        token = s.liveliness().declare_token(keys.alive(agent))
        answered = set()
        stop_at = time.monotonic() + 30
        while not world.finished.is_set() and time.monotonic() < stop_at:
            for raw in list(got):
                obs = arena_proto.parse_obs(raw)
                if isinstance(obs, arena_proto.ArenaObs) and obs.tick not in answered:
                    answered.add(obs.tick)
                    bad = [np.nan, 0.1] if obs.tick % 2 == 0 else [50.0, 50.0]
                    s.put(keys.act(group), arena_proto.actions(obs.tick, [agent], np.array([bad])))
            time.sleep(0.01)
        summary = world.join(timeout=30)
        token.undeclare()
        w = world.server.world
        assert w.in_world[agent]
        np.testing.assert_array_equal(w.pose[agent], w.start_pose[agent])  # it entered and never moved
        reasons = summary["rejected_by_reason"]
        assert reasons.get("act: not finite", 0) >= 1 and reasons.get("act: over the wheel limit", 0) >= 1
    finally:
        sub.undeclare()
        s.close()
        world.close()
        threading.Event().wait(0.1)


def test_a_killed_agents_body_stays_put_and_a_newcomer_drives_it_on():
    import time

    from world_server.server import LOST

    scenario = load_scenario("large-maze").with_overrides(agents=3, seed=4, max_ticks=1500)
    endpoint = free_endpoint()
    world = ServerThread(scenario, "arena-kill", endpoint, deadline=2.0, max_misses=2).start()
    procs = start_agents(endpoint, "arena-kill", "carrot", 3)
    try:
        server = world.server
        deadline = time.monotonic() + 120
        while server.tick < 60 and time.monotonic() < deadline:
            time.sleep(0.05)
        procs[0].kill()  # kill -9
        while not (server.slots == LOST).any() and time.monotonic() < deadline:
            time.sleep(0.05)
        lost = int(np.flatnonzero(server.slots == LOST)[0])
        held = server.world.pose[lost].copy()
        tick = server.tick
        while server.tick < tick + 20 and time.monotonic() < deadline:
            time.sleep(0.05)
        np.testing.assert_array_equal(server.world.pose[lost], held)  # stopped, an obstacle where it stood
        procs += start_agents(endpoint, "arena-kill", "carrot", 1)  # a newcomer takes the slot over
        summary = world.join(timeout=240)
        assert summary["agents_lost"] == 1 and summary["joins"] == 4
        assert np.hypot(*(server.world.pose[lost, :2] - held[:2])) > 0.05  # driven on from there
    finally:
        stop(procs)
        world.close()


def test_real_time_arena_run_reaches_its_goal():
    scenario = load_scenario("zmaze").with_overrides(noise="none")
    summary, _ = _distributed(scenario, "arena-rt", [("carrot", 1, 1)], mode="realtime", rate=100.0)
    assert summary["mode"] == "realtime" and summary["robots"][0]["reached"]


@pytest.mark.parametrize(("args", "finishes"), [
    (["zmaze", "--noise", "high", "--seed", "5"], True),
    (["large-maze", "--controller", "dft", "--max-ticks", "120"], False),  # the largest agent: 16 fields of 210 x 210
])  # fmt: skip
def test_swarm_up_runs_an_arena_and_equals_swarm_run(args, finishes):
    import json
    import subprocess
    import sys

    args = [*args, "--json"]
    ran = subprocess.run([sys.executable, "-m", "swarm", "run", *args], capture_output=True, text=True, timeout=300)
    up = subprocess.run([sys.executable, "-m", "swarm", "up", *args, "--no-record", "--listen", free_endpoint()],
                        capture_output=True, text=True, timeout=300)  # fmt: skip
    assert up.returncode == ran.returncode == (0 if finishes else 1), up.stderr[-2000:]  # 1: stopped short of the goal
    a, b = json.loads(ran.stdout), json.loads(up.stdout)
    assert a["robots"] == b["robots"] and a["ticks"] == b["ticks"] and b["rejected_messages"] == 0
    if finishes:  # a carrot agent: ahead-of-time kernels, no numba, no scipy
        assert b["agent_process_rss_mb"] < 80
    # a dft agent on large-maze owns ~43 MB, but its resident size also counts the pages of numpy's and
    # zenoh's libraries it maps: 74 MB here, 83 MB right after a fresh install (docs/distributed.md)


def test_swarm_status_answers_for_an_arena_world():
    import subprocess
    import sys

    endpoint = free_endpoint()
    world = ServerThread(load_scenario("zmaze"), "arena-status", endpoint, start_timeout=5.0).start()
    try:
        out = subprocess.run([sys.executable, "-m", "swarm", "status", "--connect", endpoint, "--run-id",
                              "arena-status"], capture_output=True, text=True, timeout=60)  # fmt: skip
        assert out.returncode == 0 and "reached 0/0" in out.stdout and "Traceback" not in out.stderr, out.stderr
    finally:
        world.finished.wait(10)  # no agent comes: the world gives up waiting
        world.close()


RESUMES = [  # scenario, agents, seed, max ticks, the saved tick to kill after, kill the agents too, controller
    ("large-maze", 3, 4, 3000, 100, False, None),
    ("large-maze", 3, 4, 3000, 300, True, None),
    # animats that share their maps: publications in flight at the save, and messages of 100 KB and more,
    # which zenoh would drop on a busy machine but for the run's lossless puts (swarm.core.bus.LOSSLESS)
    ("bg-colony", 4, 0, 700, 250, False, None),
    ("zmaze", 3, 0, 300, 100, True, "circlers:FailsAtTick"),  # robot 1's controller raised at tick 4: it stays out
]


@pytest.mark.parametrize(("ref", "agents", "seed", "max_ticks", "kill_at", "agents_too", "own"), RESUMES)
def test_kill_9_the_arena_world_then_a_restart_ends_exactly_as_swarm_run(ref, agents, seed, max_ticks, kill_at,
                                                                        agents_too, own, tmp_path,
                                                                        monkeypatch):  # fmt: skip
    """kill -9 of the world (and of every agent process, whose places newcomers
    take over) a few ticks after a save; the restarted world resumes from disk
    and the run ends with the in-process run's poses, paths, collisions,
    publications and metabolism, robot for robot.  A controller that failed
    before the save stays failed after it (`own`: a user's, from tests/outside)."""
    import json
    import os
    import re
    import signal
    import subprocess
    import sys
    import time
    from pathlib import Path

    from swarm.scenario import BUNDLED_DIR
    from world_server import persist
    from world_server.history import SharedHistory, ShareLog

    text = (BUNDLED_DIR / f"{ref}.toml").read_text()
    (scenario_file := tmp_path / f"{ref}.toml").write_text(re.sub(r"(?m)^max_ticks = .*$", f"max_ticks = {max_ticks}",
                                                                  text))  # fmt: skip
    if own:
        outside = str(Path(__file__).parent / "outside")
        monkeypatch.syspath_prepend(outside)
        monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [outside, os.environ.get("PYTHONPATH")])))
    scenario = load_scenario(str(scenario_file)).with_overrides(agents=agents, seed=seed, controller=own)
    engine = ArenaEngine(scenario)
    expected = engine.run()
    controller = scenario.groups[0].controller
    endpoint = free_endpoint()
    state = tmp_path / "aresume.arena.npz"
    summary_file = tmp_path / "summary.json"
    world_cmd = [sys.executable, "-m", "swarm", "world", str(scenario_file), "--agents", str(agents), "--seed",
                 str(seed), "--run-id", "aresume", "--listen", endpoint, "--state-dir", str(tmp_path),
                 "--persist-every", "50", "--deadline", "10", "--summary-file", str(summary_file),
                 *(["--controller", own] if own else [])]  # fmt: skip
    world = subprocess.Popen(world_cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    agent_procs = start_agents(endpoint, "aresume", controller, agents)
    procs = [world, *agent_procs]
    try:
        deadline = time.monotonic() + 180
        while True:
            saved = persist.load_arrays(state) if state.exists() else None
            if saved and int(saved[0]["tick"]) >= kill_at:
                break
            assert time.monotonic() < deadline and world.poll() is None, "the world never persisted"
            time.sleep(0.02)
        time.sleep(0.05)  # a few ticks past the save: the controllers are ahead of the saved state
        os.kill(world.pid, signal.SIGKILL)
        world.wait()
        if agents_too:
            for p in agent_procs:
                p.kill()
            procs += start_agents(endpoint, "aresume", controller, agents)
        before, _ = persist.load_arrays(state)
        assert int(before["tick"]) % 50 == 0 and (before["memory_at"][:, 1] > 0).all()  # every controller's memory
        world = subprocess.Popen(world_cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        procs.append(world)
        stopped = 1 if own else 0  # circlers reach no goal: the run stops at its last tick, exit 1
        assert world.wait(timeout=300) == stopped, world.stderr.read().decode()[-3000:]
        summary = json.loads(summary_file.read_text())
        assert summary["ticks"] == expected["ticks"]
        # a tick that went on without an answer moves robots differently: say so first
        assert summary["missed_ticks"] == 0 and summary["agents_lost"] == 0, summary
        for got, want in zip(summary["robots"], expected["robots"], strict=True):  # the world's view of each robot
            assert got == {k: want[k] for k in got}, int(before["tick"])
        assert summary["rejected_messages"] == 0
        assert summary["agents_lost"] == 0  # killed agents: newcomers took their places where they were saved
        final, _ = persist.load_arrays(state)
        np.testing.assert_array_equal(final["pose"], engine.world.pose)
        history = SharedHistory(tmp_path / "aresume.arena.shared.msgpack")
        replayed = ShareLog()  # every publication of the run on disk, once each, in order, across the restart
        for tick, share, agent, payload in history._read(keep_before=2**62):
            replayed.add(tick, [(agent, share, payload)])
        assert [replayed.of(r["agent"]) for r in expected["robots"]] == [r.get("shared") for r in expected["robots"]]
    finally:
        stop(procs)


def test_an_arena_state_of_another_scenario_is_refused_in_one_line(tmp_path):
    import subprocess
    import sys

    from world_server import persist
    from world_server.arena.world import ArenaWorld

    world = ArenaWorld(load_scenario("zmaze"))
    persist.save_arrays(tmp_path / "other.arena.npz", {**world.snapshot(), "slots": np.zeros(1, np.int64)},
                        {"scenario": load_scenario("zmaze").describe(), "stats": {}})  # fmt: skip
    out = subprocess.run([sys.executable, "-m", "swarm", "world", "large-maze", "--run-id", "other", "--state-dir",
                          str(tmp_path), "--listen", free_endpoint(), "--start-timeout", "1"],
                         capture_output=True, text=True, timeout=120)  # fmt: skip
    assert out.returncode == 2 and "another scenario" in out.stderr and "Traceback" not in out.stderr, out.stderr
