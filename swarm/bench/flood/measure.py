"""`swarm bench flood`: each world kind's short run under `swarm up` on this machine, unflooded and under
the flood of swarm.bench.flood.clients (three processes, `rate` messages a second together), in turn
`pairs` times; the tick's p50 and p99 of both, their ratio (the median pair's), whether the result was
the same every time, and what the world refused, by reason.

The flooding clients run at niceness 19: on one machine they stand for clients on other machines, whose
processor is not the world's, while the world's process still receives, counts and drops every message
that reaches it.  The result is the summary without its runtime fields (timings, the rejections, bytes
received, the run id): the world's outcome, its counts of joins, losses and missed ticks, the agents' steps.
"""

from __future__ import annotations

from swarm.bench.flood.clients import KINDS, Floods
from swarm.core import wire
from swarm.core.mesh import free_endpoint
from swarm.launcher import swarm_up
from world_server.server import new_run_id

# kind -> its run (swarm_up's arguments): long enough that the flood, which starts with the world, covers it
RUNS = {
    wire.FAMILY_GRID: {"scenario_ref": "setup1", "agents": 4, "per_process": 2, "seed": 3, "max_iterations": 6000},
    wire.FAMILY_ARENA: {"scenario_ref": "office", "agents": 2, "per_process": 1, "seed": 3,
                        "world_args": ["--max-ticks", "2000"]},
}  # fmt: skip
# --quick: shorter runs, each still a few seconds long: the forged and own clients flood only once they have
# heard an observation, and then at niceness 19: on a loaded machine their first puts can come a second late
QUICK = {
    wire.FAMILY_GRID: {"scenario_ref": "setup2", "agents": 2, "per_process": 1, "seed": 3},
    wire.FAMILY_ARENA: {"scenario_ref": "office", "agents": 1, "per_process": 1, "seed": 3,
                        "world_args": ["--max-ticks", "600"]},
}  # fmt: skip
RUNTIME = ("run_id", "rejected_messages", "rejected_by_reason", "ticks_per_second", "wall_seconds", "tick_ms_p50",
           "tick_ms_p99", "tick_ms_max", "payload_bytes_in", "recording", "agent_process_rss_mb")  # fmt: skip
RATE = 173_000  # messages a second the flooding clients are asked for together (--rate)
NICE = 19
TARGET = 2.0  # tick p99 under the flood at most this many times the unflooded run's


def _up(family: str, run: dict, rate: float) -> tuple[dict, dict]:
    """One run's summary, and what the flooding clients sent (none when `rate` is 0): messages by
    client, and per second."""
    run_id, endpoint = f"flood{new_run_id()}", free_endpoint()
    floods = Floods(endpoint, run_id, family, kinds=KINDS if rate else (), rate=rate, nice=NICE)
    with floods:
        summary = swarm_up(controller=None, run_id=run_id, listen=endpoint, progress=False, deadline=10.0,
                           on_loss="strict", **run)  # fmt: skip
    sent = {"by_client": floods.counts(), "per_second": round(floods.rate())}
    if rate and not all(sent["by_client"].values()):
        raise RuntimeError(f"a flooding client sent nothing: {sent['by_client']}")
    return summary, sent


def result_of(summary: dict) -> dict:
    """What the run came to, without what only says how fast or what it refused."""
    return {k: v for k, v in summary.items() if k not in RUNTIME}


def _pair(family: str, run: dict, rate: float) -> dict:
    calm, _ = _up(family, run, 0)
    flooded, sent = _up(family, run, rate)
    return {
        "unflooded": {k: calm[k] for k in ("tick_ms_p50", "tick_ms_p99", "rejected_messages")},
        "flooded": {k: flooded[k] for k in ("tick_ms_p50", "tick_ms_p99", "rejected_messages")},
        # what reached the world: every message of the flood it heard is refused (over budget, or decoded and
        # refused), over the run's ticking (it heard some before, as its agents joined)
        "refused_per_second": round(flooded["rejected_messages"] / max(flooded["wall_seconds"], 1e-9)),
        "p99_ratio": round(flooded["tick_ms_p99"] / max(calm["tick_ms_p99"], 1e-9), 2),
        "results": (result_of(calm), result_of(flooded)), "sent": sent,
        "dropped_by_reason": dict(sorted(flooded["rejected_by_reason"].items())),
        "ticks": calm.get("iterations", calm.get("ticks")),
    }  # fmt: skip


def measure(family: str, run: dict, pairs: int, rate: float) -> dict:
    """`pairs` unflooded and flooded runs in turn; the row is the pair whose p99 ratio is the median (this
    machine's speed drifts within minutes, and a run taken right beside its flooded twin shares its
    conditions).  The result must be the same in every run."""
    measured = [_pair(family, run, rate) for _ in range(pairs)]
    results = [r for pair in measured for r in pair.pop("results")]
    row = sorted(measured, key=lambda r: r["p99_ratio"])[(pairs - 1) // 2]
    differ = sorted({k for r in results for k in {*r, *results[0]} if r.get(k) != results[0].get(k)})
    return {"kind": family, "scenario": run["scenario_ref"], "agents": run["agents"], "seed": run["seed"], **row,
            "pair_ratios": [r["p99_ratio"] for r in measured], "same_result": not differ, "differ": differ,
            "pair_refused_per_second": [r["refused_per_second"] for r in measured]}  # fmt: skip


def run(quick: bool = False, pairs: int = 3, rate: int = RATE) -> dict:
    """`swarm bench flood` (--quick: one pair of a shorter run of each kind)."""
    runs = QUICK if quick else RUNS
    pairs = 1 if quick else pairs
    return {"benchmark": "flood", "target_ratio": TARGET, "rate": rate, "nice": NICE, "pairs": pairs,
            "runs": [measure(family, r, pairs, rate) for family, r in runs.items()]}  # fmt: skip


def format_flood_bench(result: dict) -> str:
    lines = [f"Each kind's run under `swarm up`, unflooded and under a flood of {result['rate']} garbage, forged and",
             f"repeated messages a second from three processes at niceness {result['nice']}; tick latency of the",
             f"world (ms): the median of {result['pairs']} pairs by p99 ratio (each pair's ratio in the last column);",
             "sent/s: what the clients sent, heard/s: what the world refused, a second of its run",
             "",
             f"{'kind':>6}{'scenario':>12}{'agents':>7}{'ticks':>6}{'p50':>8}{'p99':>8}{'p50 fl':>8}{'p99 fl':>8}"
             f"{'ratio':>7}{'same':>6}{'sent/s':>9}{'heard/s':>9}  pairs"]  # fmt: skip
    for r in result["runs"]:
        calm, fl, same = r["unflooded"], r["flooded"], "yes" if r["same_result"] else "NO"
        lines.append(f"{r['kind']:>6}{r['scenario']:>12}{r['agents']:>7}{r['ticks']:>6}{calm['tick_ms_p50']:>8}"
                     f"{calm['tick_ms_p99']:>8}{fl['tick_ms_p50']:>8}{fl['tick_ms_p99']:>8}{r['p99_ratio']:>7}"
                     f"{same:>6}{r['sent']['per_second']:>9}{r['refused_per_second']:>9}"
                     f"  {' '.join(map(str, r['pair_ratios']))}")  # fmt: skip
    for r in result["runs"]:
        if r["differ"]:
            lines += ["", f"{r['kind']}: the result differs between runs in {', '.join(r['differ'])}"]
        lines += [
            "",
            f"{r['kind']}: heard/s in each pair {' '.join(map(str, r['pair_refused_per_second']))}; "
            f"sent {r['sent']['by_client']}; refused by the world, by reason:",
        ]
        lines += [f"  {count:>9}  {reason}" for reason, count in r["dropped_by_reason"].items()]
    return "\n".join([*lines, "", *map(_target, result["runs"])])


def _target(r: dict) -> str:
    met = r["p99_ratio"] <= TARGET and r["same_result"]
    return (
        f"target: {r['kind']} tick p99 under the flood at most {TARGET:g}x unflooded, the same result: "
        f"{r['p99_ratio']}x, {'the same' if r['same_result'] else 'changed'} ({'met' if met else 'not met'})"
    )
