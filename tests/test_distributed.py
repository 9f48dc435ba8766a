"""The distributed runtime: a real zenoh router, real agent processes.

Lock-step runs must equal the in-process engine bit for bit, and bad traffic
must be counted and rejected without touching the world."""

import time

import numpy as np
import pytest

from swarm.core import wire
from swarm.core.bus import LOSSLESS, open_client, open_router
from swarm.engines.grid import Engine
from swarm.scenario import load_scenario
from tests.distributed import ServerThread, free_endpoint, run_world, saving_world_cmd, start_agents, stop
from world_server.grid.face import wire as proto
from world_server.grid.world import L_MARK


def _run_distributed(scenario, run_id, count=1, attack=None, told=None):
    return run_world(scenario, run_id, [(scenario.controller, scenario.agents // count, count)], attack, told=told)


@pytest.mark.parametrize(
    ("ref", "controller", "agents", "seed", "physics"),
    [("setup2", "cmarking", 3, 12, "ideal"), ("setup2", "marking", 2, 5, "ideal"), ("maze", "cmarking", 4, 2, "ideal"),
     ("setup3-12", "cmarking", 6, 8, "ideal"), ("maze", "cmarking", 6, 3, "physical")],
)  # fmt: skip
def test_lockstep_equals_the_in_process_engine(ref, controller, agents, seed, physics):
    scenario = load_scenario(ref).with_overrides(agents=agents, controller=controller, seed=seed, physics=physics)
    engine = Engine(scenario)
    expected = engine.run().summary
    summary, world = _run_distributed(scenario, f"eq-{ref}-{seed}", count=2 if agents % 2 == 0 else 1)
    for key in ("iterations", "delivered", "total", "finished", "explored_cells", "optimal_cells"):
        assert summary[key] == expected[key], key
    np.testing.assert_array_equal(world.layers, engine.world.layers)
    np.testing.assert_array_equal(world.pos, engine.world.pos)
    np.testing.assert_array_equal(world.body_xy, engine.world.body_xy)
    assert summary["rejected_messages"] == 0 and summary["agents_lost"] == 0
    assert summary.get("blocked_moves") == expected.get("blocked_moves")


def test_the_runs_own_puts_wait_for_a_slow_reader():
    """Sixty 1 MB messages (an animat's memory and maps come to this) to a reader that takes 10 ms each,
    more than the link's queue and the sockets' buffers hold: LOSSLESS loses none.  (zenoh's default
    drops a put once the queue stays full: 22 of 60 of these arrived on an idle machine, and all 60 when
    a busy one slowed the writer too, so how many it drops is no test.)"""
    import threading

    import zenoh

    endpoint = free_endpoint()
    router, client = open_router(endpoint), open_client(endpoint)
    try:
        inbox = router.declare_subscriber("slow/reader", zenoh.handlers.FifoChannel(4))
        publisher = client.declare_publisher("slow/reader", congestion_control=LOSSLESS)
        deadline = time.monotonic() + 10
        while not publisher.matching_status.matching:  # the subscription has reached the client
            assert time.monotonic() < deadline
            time.sleep(0.02)
        got = []

        def read():
            while (data := inbox.recv().payload.to_bytes()) != b"end":
                got.append(int.from_bytes(data[:4], "little"))
                time.sleep(0.01)

        reader = threading.Thread(target=read, daemon=True)
        reader.start()
        for i in range(60):
            publisher.put(i.to_bytes(4, "little") + bytes(1_000_000))
        client.put("slow/reader", b"end", congestion_control=LOSSLESS)
        reader.join(30)
        assert not reader.is_alive()
        assert got == list(range(60)), len(got)
    finally:
        client.close()
        router.close()


def test_bad_traffic_is_counted_and_changes_nothing():
    scenario = load_scenario("setup2").with_overrides(agents=2, seed=21)
    engine = Engine(scenario)
    expected = engine.run().summary

    def attack(endpoint, keys):
        s = open_client(endpoint)
        stay = np.array([[4, 0, 0, 0, 0, 0, 0, 0]], dtype=np.int64)
        rows = proto.action_rows([0], stay, [False])

        def act(**fields):
            return wire.pack({"type": "act", "family": "grid", "tick": 0, "rows": rows.tobytes(), **fields})

        try:
            s.put(keys.act("intruder"), b"\x00\xffgarbage")  # not msgpack
            s.put(keys.act("intruder"), wire.pack({"type": "act", "tick": "soon"}))  # wrong schema
            s.put(keys.act("intruder"), proto.actions(0, [0], stay, [False]))  # another process's agent
            s.put(keys.act("intruder"), proto.actions(0, [99], stay, [False]))  # unknown agent
            s.put(keys.act("intruder"), proto.actions(0, [-1], stay, [False]))  # a negative id
            s.put(keys.act("intruder"), act(tick=float("nan")))
            s.put(keys.act("intruder"), act(tick=2**64 - 1))
            s.put(keys.act("intruder"), act(rows=b"short"))
            s.put(keys.act("intruder"), act(family="bees"))
            s.put(
                keys.mark("intruder"),
                wire.pack({"type": "mark", "family": "grid", "tick": 0, "agents": [0], "cells": [0], "values": [0]}),
            )  # a mark write: not on this key
            for _ in range(300):  # a flood
                s.put(keys.act("flood"), b"\x93\x01\x02")
            deadline = time.monotonic() + 60  # garbage to every agent process once both have joined:
            while len(list(s.liveliness().get(keys.alive("*"), timeout=1.0))) < 2 and time.monotonic() < deadline:
                time.sleep(0.05)
            for _ in range(5):  # each process counts it and says so when it ends
                s.put(keys.obs("*"), b"\x00\xffgarbage")
            replies = list(s.get(keys.marks, timeout=5.0))
            assert replies and replies[0].ok is not None
        finally:
            s.close()  # fmt: skip

    told = []
    summary, world = _run_distributed(scenario, "attack", attack=attack, told=told)
    assert summary["rejected_messages"] >= 300
    assert len(told) == 2 and all("swarm: agent process refused 5 messages" in err for err in told), told
    assert all("obs: not msgpack: 5" in err and "Traceback" not in err for err in told), told
    assert summary["iterations"] == expected["iterations"]
    np.testing.assert_array_equal(world.layers[L_MARK], engine.world.layers[L_MARK])


def test_a_flood_is_counted_by_reason_and_changes_nothing():
    """Flooding clients in their own processes for the whole run, forged and repeated actions on the agent
    process's own key, and a stream of garbage on a key no agent process has: the run ends as in process,
    none of the agents' answers was dropped, and every message of the stream is counted (world_server.gate)."""
    import zenoh

    from swarm.bench.flood.clients import Floods

    ticks, stream = 1500, 3000
    scenario = load_scenario("setup1").with_overrides(agents=2, seed=5)
    engine = Engine(scenario)
    engine.step(ticks)
    endpoint = free_endpoint()
    world = ServerThread(scenario, "flood", endpoint, deadline=10.0, max_iterations=ticks).start()
    procs = []
    try:
        with Floods(endpoint, "flood", "grid", ("forged", "own"), rate=20_000, nice=19) as floods:
            floods.wait_ready(60)  # listening before the first observation
            s = open_client(endpoint)
            try:
                pub = s.declare_publisher(wire.Keys("flood").mark("intruder"),
                                          congestion_control=zenoh.CongestionControl.BLOCK)  # fmt: skip
                for _ in range(stream):
                    pub.put(b"\x00\xffgarbage")
            finally:
                s.close()
            procs = start_agents(endpoint, "flood", scenario.controller, 1, count=2)
            summary = world.join(timeout=240)
        assert all(floods.counts().values()), floods.counts()  # both flooded the agent process's key
        assert procs[0].wait(timeout=30) == 0
    finally:
        stop(procs)
        world.close()
    w = world.server.world
    np.testing.assert_array_equal(w.layers, engine.world.layers)
    np.testing.assert_array_equal(w.pos, engine.world.pos)
    assert summary["iterations"] == ticks and summary["missed_ticks"] == 0 and summary["agent_steps"] == 2 * ticks
    reasons = summary["rejected_by_reason"]
    assert sum(n for r, n in reasons.items() if r.startswith("mark: ")) == stream  # every one, counted
    assert reasons.get("mark: over budget", 0) > stream // 2 and reasons.get("act: over budget", 0) > 0
    assert not any(ch.isdigit() for reason in reasons for ch in reason)  # reasons are a fixed few, no counts


def test_a_client_declaring_liveliness_tokens_by_the_hundred_spends_its_own_budget():
    """Tokens declared and dropped again on agents' liveliness keys nobody joined for, all through the
    run: the world lets in a stranger's share of them and counts the rest, while the joining agents'
    tokens, on their own budget, still come in, so the run ends as in process."""
    import threading

    ticks = 300
    scenario = load_scenario("setup1").with_overrides(agents=2, seed=5)
    engine = Engine(scenario)
    engine.step(ticks)
    endpoint = free_endpoint()
    world = ServerThread(scenario, "tokens", endpoint, deadline=10.0, max_iterations=ticks).start()
    intruder, procs, done = open_client(endpoint), [], threading.Event()
    keys = wire.Keys("tokens")

    def flood() -> None:
        while not done.is_set():
            tokens = [intruder.liveliness().declare_token(keys.alive(a)) for a in range(2, 400)]
            for token in tokens:
                token.undeclare()

    flooding = threading.Thread(target=flood, daemon=True)
    try:
        flooding.start()
        time.sleep(0.5)  # the world's budget for strangers' tokens is spent before the agents come
        procs = start_agents(endpoint, "tokens", scenario.controller, 1, count=2)
        summary = world.join(timeout=120)
        assert procs[0].wait(timeout=30) == 0
    finally:
        done.set()
        flooding.join(30)
        intruder.close()
        stop(procs)
        world.close()
    np.testing.assert_array_equal(world.server.world.pos, engine.world.pos)
    assert summary["iterations"] == ticks and summary["missed_ticks"] == 0 and summary["agent_steps"] == 2 * ticks
    assert summary["joins"] == 2 and summary["agents_lost"] == 0
    assert summary["rejected_by_reason"].get("alive: over budget", 0) > 500, summary["rejected_by_reason"]


def test_the_marks_key_space_can_be_read_by_any_client():
    scenario = load_scenario("maze").with_overrides(agents=2, seed=3, controller="marking")
    endpoint = free_endpoint()
    world = ServerThread(scenario, "keyspace", endpoint, deadline=10.0).start()
    procs = start_agents(endpoint, "keyspace", "marking", 2)
    try:
        world.join(timeout=240)
        s = open_client(endpoint)
        try:
            reply = next(iter(s.get("swarm/keyspace/marks/**", timeout=5.0))).ok
            msg = wire.unpack(reply.payload.to_bytes())
        finally:
            s.close()
        marks = np.array(msg["marks"]).reshape(msg["height"], msg["width"])
        truth = world.server.world.layers[L_MARK]
        np.testing.assert_array_equal(marks, np.where(truth > 2**61, -1, truth))
    finally:
        stop(procs)
        world.close()


def test_kill_9_an_agent_then_a_fresh_one_joins_and_the_run_finishes():
    import os
    import signal
    import time

    # setup1 lasts ~10,000 ticks: the newcomer's process has time to start on any machine (`open` ends in ~3 s)
    scenario = load_scenario("setup1").with_overrides(agents=3, seed=7)
    endpoint = free_endpoint()
    world = ServerThread(scenario, "faults", endpoint, deadline=5.0).start()
    procs = start_agents(endpoint, "faults", "cmarking", 3)
    server = world.server
    try:
        deadline = time.monotonic() + 120
        while server.tick < 100:
            assert time.monotonic() < deadline, "the run did not start"
            time.sleep(0.01)
        os.kill(procs[0].pid, signal.SIGKILL)
        while server.stats.agents_lost == 0:
            assert time.monotonic() < deadline, "the killed agent was never declared lost"
            time.sleep(0.01)
        lost_at = server.tick
        procs += start_agents(endpoint, "faults", "cmarking", 1)
        summary = world.join(timeout=240)
        assert summary["finished"] and summary["delivered"] == summary["total"]
        assert summary["agents_lost"] == 1 and summary["joins"] == 4
        assert summary["iterations"] > lost_at
        assert procs[-1].wait(timeout=30) == 0  # the newcomer worked until the world said stop
        assert procs[1].wait(timeout=30) == 0 and procs[2].wait(timeout=30) == 0
    finally:
        stop(procs)
        world.close()


def test_lost_agents_cargo_is_dropped_where_it_stood():
    scenario = load_scenario("setup2").with_overrides(agents=2, seed=1)
    from world_server.grid.world import L_RES, GridWorld

    w = GridWorld(scenario)
    w.pos[0] = (3, 4)
    w.payload[0] = 100
    before = int(w.layers[L_RES, 3, 4])
    w.drop_load(0)
    assert w.payload[0] == 0 and w.layers[L_RES, 3, 4] == before + 100
    w.payload[1] = 60  # on the base: delivered
    w.drop_load(1)
    assert w.delivered == 60


@pytest.mark.parametrize("kill_at, agents_too", [(40, False), (200, True)])
def test_kill_9_the_world_then_a_restart_ends_exactly_as_swarm_run(tmp_path, kill_at, agents_too):
    """The saved state holds the world and every controller's memory: after kill -9
    of the world (and, `agents_too`, of every agent process, with new ones started
    for the restarted world), the run ends with the in-process run's result."""
    import json
    import os
    import signal
    import subprocess
    import time

    from world_server import persist

    scenario = load_scenario("setup1").with_overrides(agents=3, seed=4)
    engine = Engine(scenario)
    expected = engine.run().summary
    endpoint = free_endpoint()
    state = persist.state_path(tmp_path, "exact")
    summary_file = tmp_path / "summary.json"
    world_cmd = saving_world_cmd(tmp_path, "exact", endpoint, 20)
    world = subprocess.Popen(world_cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    agents = start_agents(endpoint, "exact", "cmarking", 3)
    procs = [world, *agents]
    try:
        deadline = time.monotonic() + 120
        while True:
            saved = persist.load(state) if state.exists() else None
            if saved and saved["tick"] >= kill_at:
                break
            assert time.monotonic() < deadline and world.poll() is None, "the world never persisted"
            time.sleep(0.01)
        time.sleep(0.004)  # a few ticks past the save: the agents' controllers are ahead of the saved state
        os.kill(world.pid, signal.SIGKILL)
        world.wait()
        if agents_too:
            for p in agents:
                p.kill()
            procs += start_agents(endpoint, "exact", "cmarking", 3)
        before = persist.load(state)
        assert before["tick"] >= kill_at and before["tick"] % 20 == 0
        world = subprocess.Popen(world_cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        procs.append(world)
        assert world.wait(timeout=300) == 0, world.stderr.read().decode()[-3000:]
        summary = json.loads(summary_file.read_text())
        for key in ("iterations", "delivered", "total", "finished", "explored_cells", "optimal_cells"):
            assert summary[key] == expected[key], (key, before["tick"])
        assert summary["missed_ticks"] == 0 and summary["rejected_messages"] == 0
        final = persist.load(state)
        np.testing.assert_array_equal(final["layers"], engine.world.layers)
        np.testing.assert_array_equal(final["pos"], engine.world.pos)
    finally:
        stop(procs)


def _children_alive(run_id: str) -> list[str]:
    """World and agent processes of a run (full command lines: ps -ww)."""
    import subprocess

    out = subprocess.run(["ps", "-ww", "-eo", "args"], capture_output=True, text=True).stdout
    return [line for line in out.splitlines()
            if f"--run-id {run_id}" in line and (" world " in line or " agent " in line)]  # fmt: skip


@pytest.mark.parametrize("physics", ["ideal", "physical"])
def test_swarm_up_equals_swarm_run_and_leaves_no_process(tmp_path, physics):
    import json
    import subprocess
    import sys

    args = ["setup2", "--agents", "3", "--seed", "9", "--physics", physics]
    up = subprocess.run([sys.executable, "-m", "swarm", "up", *args, "--run-id", f"upeq{physics}",
                         "--listen", free_endpoint(), "--json"],
                        capture_output=True, text=True, timeout=300, cwd=tmp_path)  # fmt: skip
    assert up.returncode == 0, up.stderr[-3000:]
    ran = subprocess.run([sys.executable, "-m", "swarm", "run", *args, "--json"], capture_output=True, text=True,
                         timeout=300)  # fmt: skip
    a, b = json.loads(up.stdout), json.loads(ran.stdout)
    for key in ("iterations", "delivered", "total", "finished", "apf_optimal", "explored_cells", "reachable_cells",
                "physics"):  # fmt: skip
        assert a[key] == b[key], key
    assert a["physics"] == physics
    assert a["agent_process_rss_mb"] < 80  # the ahead-of-time step: no numba in agent processes
    assert {"rejected_messages", "agents_lost", "ticks_per_second"} <= set(a)
    assert _children_alive(f"upeq{physics}") == []


@pytest.mark.parametrize("signum", ["SIGINT", "SIGTERM"])
def test_ctrl_c_stops_swarm_up_and_every_child(tmp_path, signum):
    import signal
    import subprocess
    import sys
    import time

    # real time at 20 ticks/s: the run cannot end on its own before the signal comes (lock-step can, on a fast day)
    # SIGINT as a terminal's: a shell starts background jobs with it ignored, and that is inherited
    up = subprocess.Popen([sys.executable, "-m", "swarm", "up", "setup1", "--agents", "4", "--seed", "1",
                           "--run-id", f"ctrlc{signum}", "--listen", free_endpoint(), "--mode", "realtime",
                           "--rate", "20"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          cwd=tmp_path, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))  # fmt: skip
    try:
        deadline = time.monotonic() + 120
        while len(_children_alive(f"ctrlc{signum}")) < 5:  # the world and 4 agents
            assert time.monotonic() < deadline and up.poll() is None, up.stderr.read()[-2000:]
            time.sleep(0.1)
        time.sleep(1.0)
        up.send_signal(getattr(signal, signum))
        assert up.wait(timeout=30) == 130
        time.sleep(0.5)
        assert _children_alive(f"ctrlc{signum}") == []
    finally:
        if up.poll() is None:
            up.kill()


def test_realtime_mode_ticks_at_its_rate_and_finishes():
    scenario = load_scenario("setup2").with_overrides(agents=3, seed=9)
    endpoint = free_endpoint()
    world = ServerThread(scenario, "realtime", endpoint, mode="realtime", rate=25.0).start()
    procs = start_agents(endpoint, "realtime", "cmarking", 3)
    try:
        summary = world.join(timeout=240)
        assert summary["mode"] == "realtime" and summary["finished"]
        assert summary["delivered"] == summary["total"]
        # the world's clock, not the agents', sets the pace; a loaded machine's stalls may slow it (clock_slips)
        assert 17.5 <= summary["ticks_per_second"] <= 26, summary
        # the clock: a tick's answers are due one period after the last's, however late its work started,
        # unless that leaves the agents under half a period; then the clock slips a whole period, counted
        server, slips = world.server, summary["clock_slips"]
        server._due = 100.0
        assert server._beat(100.019) == pytest.approx(100.04) and server.stats.clock_slips == slips
        server._due = 100.0
        assert server._beat(100.025) == pytest.approx(100.065) and server.stats.clock_slips == slips + 1
    finally:
        stop(procs)
        world.close()
