"""Rerun recordings: written by real runs, read back through rerun's own reader,
served to a real headless browser."""

import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from swarm.engines.grid import Engine
from swarm.recording.grid import STATES, Recorder, agent_states, run_meta
from swarm.review.report import RecordingError, read_recording, summary_from
from swarm.scenario import load_scenario
from tests.distributed import free_endpoint

SWARM = [sys.executable, "-m", "swarm"]
SHARED_KEYS = ("scenario", "controller", "agents", "seed", "until", "iterations", "finished", "delivered",
               "total", "in_transit", "apf_optimal", "optimal_cells", "explored_cells", "reachable_cells", "grid",
               "physics")  # fmt: skip


def _swarm(*args, cwd=None, timeout=300):
    return subprocess.run([*SWARM, *args], capture_output=True, text=True, timeout=timeout, cwd=cwd)


def test_swarm_run_record_reads_back_to_the_printed_summary(tmp_path):
    rrd = tmp_path / "run.rrd"
    ran = _swarm("run", "maze", "--agents", "5", "--seed", "3", "--record", str(rrd), "--json")
    assert ran.returncode == 0, ran.stderr[-2000:]
    printed = json.loads(ran.stdout)
    assert f"swarm replay {rrd}" in ran.stderr  # the run says how to open it
    rep = _swarm("report", str(rrd), "--out", str(tmp_path / "plots"), "--json")
    assert rep.returncode == 0, rep.stderr[-2000:]
    read = json.loads(rep.stdout)
    for key in SHARED_KEYS:
        assert read[key] == printed[key], key
    for name in ("delivered.png", "optimal_share.png", "agent_states.png", "summary.json"):
        assert (tmp_path / "plots" / name).stat().st_size > 1000 or name == "summary.json"


def test_the_recording_holds_the_world_the_agents_the_metrics_and_the_metadata(tmp_path):
    from rerun.chunk import RrdReader

    scenario = load_scenario("maze").with_overrides(agents=4, seed=1)
    engine = Engine(scenario)
    rrd = tmp_path / "r.rrd"
    recorder = Recorder(rrd, engine.world, run_meta(scenario, engine.world, "r", "foraged", "in-process"))
    summary = engine.run(recorder=recorder).summary
    recorder.close(summary)
    reader = RrdReader(rrd)
    assert reader.blueprints(), "a default blueprint is stored"
    chunks = list(reader.stream())
    entities = {c.entity_path.lstrip("/") for c in chunks}
    assert {"world/obstacles", "world/base", "world/marks", "world/trails", "world/resources", "world/agents",
            "metrics/delivered", "metrics/optimal_share", "metrics/agents_alive", "metrics/tick_ms",
            "metrics/rejected_messages", "run/meta", "run/summary"} <= entities  # fmt: skip
    assert {f"metrics/agents/{s}" for s in STATES} <= entities
    points = [c for c in chunks if c.entity_path.lstrip("/") == "world/agents" and not c.is_static]
    rows = sum(c.num_rows for c in points)
    assert rows == summary["iterations"]  # one batched cloud per tick
    batch = points[0].to_record_batch()
    assert len(batch.column("Points2D:positions")[0]) == 4 and len(batch.column("Points2D:class_ids")[0]) == 4
    rec = read_recording(rrd)
    assert rec.meta["seed"] == 1 and rec.meta["agents"] == 4 and "rerun-sdk" in rec.meta["versions"]
    ticks = rec.values("agents/searching")[0]
    total = sum(rec.values(f"agents/{s}")[1] for s in STATES)
    np.testing.assert_array_equal(total, np.full(len(ticks), 4.0))  # every agent in exactly one state


def test_agent_states_from_mode_payload_and_presence():
    from world_server.grid.face.layout import ERASE, RETURN, RETURN_COLOUR, RETURN_MEND, RETURN_REMOVE, SEARCH

    modes = np.array([SEARCH, RETURN, RETURN, RETURN_COLOUR, RETURN_MEND, RETURN_REMOVE, ERASE, SEARCH])
    payload = np.array([0, 0, 50, 50, 50, 50, 0, 0])
    present = np.array([True] * 7 + [False])
    names = [STATES[s] for s in agent_states(modes, payload, present)]
    assert names == ["searching", "returning", "carrying", "colouring", "colouring", "removing", "removing", "absent"]


def test_a_distributed_run_records_by_default_and_reads_back(tmp_path):
    up = _swarm("up", "setup2", "--agents", "3", "--seed", "2", "--run-id", "rec-up", "--listen", free_endpoint(),
                "--json", cwd=tmp_path)  # fmt: skip
    assert up.returncode == 0, up.stderr[-3000:]
    printed = json.loads(up.stdout)
    assert printed["recording"] == "runs/rec-up.rrd"
    read = summary_from(read_recording(tmp_path / "runs" / "rec-up.rrd"))
    for key in (*SHARED_KEYS, "run_id", "mode", "rejected_messages"):
        assert read[key] == printed[key], key
    assert read["tick_ms_p50"] == pytest.approx(printed["tick_ms_p50"], rel=1e-3)


def test_damaged_cut_and_unfinished_recordings_give_clear_errors(tmp_path):
    scenario = load_scenario("maze").with_overrides(agents=3, seed=2)
    engine = Engine(scenario)
    whole = tmp_path / "whole.rrd"
    recorder = Recorder(whole, engine.world, run_meta(scenario, engine.world, "w", "foraged", "in-process"),
                        flush_every=16)  # fmt: skip
    recorder.close(engine.run(recorder=recorder).summary)
    data = whole.read_bytes()
    cut = tmp_path / "cut.rrd"
    cut.write_bytes(data[: len(data) * 2 // 3])
    garbage = tmp_path / "garbage.rrd"
    garbage.write_bytes(b"not a recording at all" * 10)
    unfinished = tmp_path / "unfinished.rrd"  # a world killed mid-run: ticks, but no end-of-run record
    engine = Engine(scenario)
    recorder = Recorder(unfinished, engine.world, run_meta(scenario, engine.world, "u", "foraged", "in-process"))
    engine.step(5)
    for t in range(5):
        recorder.capture(t)
    recorder.flush()
    recorder.rec.flush()
    recorder.rec.disconnect()
    for path, message in ((cut, "truncated"), (garbage, "damaged"), (unfinished, "truncated"),
                          (tmp_path / "missing.rrd", "no such file")):  # fmt: skip
        with pytest.raises(RecordingError, match=message):
            read_recording(path)
        rep = _swarm("report", str(path))
        assert rep.returncode == 2 and message in rep.stderr and "Traceback" not in rep.stderr, rep.stderr


def _chromium() -> str | None:
    return shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.mark.skipif(_chromium() is None, reason="Debian's chromium is not installed (make test installs it)")
@pytest.mark.parametrize("run", [("maze", "--agents", "4", "--seed", "1"), ("large-maze", "--agents", "3")],
                         ids=["grid", "arena"])  # fmt: skip
def test_the_web_viewer_is_served_and_loads_in_a_headless_browser(tmp_path, run):
    from playwright.sync_api import sync_playwright

    rrd = tmp_path / "web.rrd"
    assert _swarm("run", *run, "--record", str(rrd)).returncode in (0, 1)
    web, grpc = (int(free_endpoint().rsplit(":", 1)[1]) for _ in range(2))
    proc = subprocess.Popen([*SWARM, "replay", str(rrd), "--web", "--port", str(web), "--grpc-port", str(grpc)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)  # fmt: skip
    try:
        line = proc.stdout.readline()
        assert "open http://" in line, line + proc.stderr.read()
        url = line.split("open ", 1)[1].split()[0]
        flags = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync"]  # fmt: skip
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=_chromium(), args=flags)
            page = browser.new_page(viewport={"width": 1280, "height": 800})
            deadline = time.monotonic() + 5
            while True:  # the server may take a moment to listen
                try:
                    page.goto(url)
                    break
                except Exception:
                    if time.monotonic() > deadline:
                        raise
                    time.sleep(0.3)
            page.wait_for_selector("#the_canvas_id:not(.hidden)", timeout=120_000)  # the wasm viewer started
            page.wait_for_timeout(3000)
            shot = tmp_path / "viewer.png"
            page.screenshot(path=str(shot))
            size = page.evaluate(
                "() => { const c = document.getElementById('the_canvas_id'); return [c.width, c.height] }"
            )
            browser.close()
        assert size[0] > 0 and size[1] > 0
        assert shot.stat().st_size > 20_000  # a rendered viewer, not a blank page
    finally:
        proc.terminate()
        proc.wait(timeout=20)
    time.sleep(0.5)
    left = subprocess.run(["pgrep", "-f", str(rrd)], capture_output=True, text=True).stdout.split()
    assert left == [], "swarm replay left its viewer running"


def test_replay_without_a_display_says_what_to_do(tmp_path, monkeypatch):
    rrd = tmp_path / "x.rrd"
    assert _swarm("run", "maze", "--agents", "2", "--seed", "1", "--record", str(rrd)).returncode == 0
    env = {k: v for k, v in __import__("os").environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    out = subprocess.run([*SWARM, "replay", str(rrd)], capture_output=True, text=True, timeout=60, env=env)
    assert out.returncode == 2 and "--web" in out.stderr


def test_recording_files_stay_small(tmp_path):
    """Only changed layers are stored: a long run's file grows with what changes."""
    rrd = tmp_path / "s.rrd"
    ran = _swarm("run", "setup1", "--agents", "20", "--seed", "1", "--record", str(rrd), "--json")
    assert ran.returncode == 0
    iterations = json.loads(ran.stdout)["iterations"]
    assert rrd.stat().st_size / iterations < 5_000  # bytes per tick (40x40 grid, 20 agents)
    assert Path(rrd).stat().st_size < 50_000_000


def test_the_live_viewer_stream_carries_the_same_run(tmp_path):
    """--viewer URL streams to a rerun gRPC server (here one that saves what it
    gets, as a compose viewer service would show it) besides the file."""
    from swarm.review.report import rerun_binary

    port = int(free_endpoint().rsplit(":", 1)[1])
    live = tmp_path / "live.rrd"
    # its own process group: the `rerun` entry point runs the viewer binary as a child, and Ctrl-C in a
    # terminal reaches both; a signal to the entry point alone would leave the binary running
    # (and SIGINT as a terminal's: a shell starts background jobs with it ignored, and that is inherited)
    import os
    import signal

    server = subprocess.Popen([rerun_binary(), "--serve-grpc", "--port", str(port), "--save", str(live)],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
                              preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))  # fmt: skip
    try:
        time.sleep(2)
        ran = _swarm("run", "maze", "--agents", "3", "--seed", "4", "--record", str(tmp_path / "file.rrd"),
                     "--viewer", f"rerun+http://127.0.0.1:{port}/proxy", "--json")  # fmt: skip
        assert ran.returncode == 0, ran.stderr[-2000:]
        time.sleep(2)
    finally:
        os.killpg(server.pid, signal.SIGINT)  # Ctrl-C: the server finishes its file (slow on a loaded machine)
        try:
            server.wait(timeout=60)
        except subprocess.TimeoutExpired:
            os.killpg(server.pid, signal.SIGKILL)
            raise
    printed = json.loads(ran.stdout)
    read = summary_from(read_recording(live))
    for key in SHARED_KEYS:
        assert read[key] == printed[key], key


def test_a_viewer_that_does_not_answer_is_left_out_and_the_file_is_whole(tmp_path):
    """A viewer address that takes no connection would fill rerun's queue and hang every flush: the run
    says so in one line, records to its file alone and ends."""
    port = int(free_endpoint().rsplit(":", 1)[1])  # nothing listens there
    rrd = tmp_path / "file.rrd"
    ran = _swarm("run", "maze", "--agents", "3", "--seed", "4", "--record", str(rrd),
                 "--viewer", f"rerun+http://127.0.0.1:{port}/proxy", "--json", timeout=180)  # fmt: skip
    assert ran.returncode == 0, ran.stderr[-2000:]
    assert f"the rerun viewer at rerun+http://127.0.0.1:{port}/proxy does not answer" in ran.stderr
    assert "Traceback" not in ran.stderr
    printed = json.loads(ran.stdout)
    read = summary_from(read_recording(rrd))
    for key in SHARED_KEYS:
        assert read[key] == printed[key], key


def test_a_viewer_that_goes_away_mid_run_is_left_out_and_the_file_is_whole(tmp_path):
    """rerun raises at every flush once its viewer is gone: the run says so in one line, goes on to its end
    and its file holds every tick."""
    import os
    import signal

    from swarm.bench.soak.measure import _recorded_ticks
    from swarm.review.report import rerun_binary

    port, rrd = int(free_endpoint().rsplit(":", 1)[1]), tmp_path / "file.rrd"
    server = subprocess.Popen([rerun_binary(), "--serve-grpc", "--port", str(port)], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL, start_new_session=True)  # fmt: skip
    run = None
    try:
        time.sleep(2)
        run = subprocess.Popen([sys.executable, "-m", "swarm", "run", "zmaze", "--agents", "3", "--controller",
                                "wander", "--max-ticks", "20000", "--record", str(rrd), "--viewer",
                                f"rerun+http://127.0.0.1:{port}/proxy", "--json"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)  # fmt: skip
        deadline = time.monotonic() + 120
        while not (rrd.exists() and rrd.stat().st_size > 200_000):  # ticks flushed: the viewer got them too
            assert run.poll() is None and time.monotonic() < deadline, "the run never got going"
            time.sleep(0.05)
        os.killpg(server.pid, signal.SIGKILL)
        out, err = run.communicate(timeout=180)
    finally:
        os.killpg(server.pid, signal.SIGKILL) if server.poll() is None else None
        if run is not None and run.poll() is None:
            run.kill()
    assert run.returncode == 1 and "Traceback" not in err, err[-3000:]  # 1: ended unfinished, as wander does
    assert f"swarm: the rerun viewer at rerun+http://127.0.0.1:{port}/proxy went away" in err
    printed = json.loads(out)
    assert printed["ticks"] == 20000 and not printed["finished"] and summary_from(read_recording(rrd))["ticks"] == 20000
    assert _recorded_ticks(rrd).tolist() == list(range(20000))
