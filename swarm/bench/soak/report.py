"""The text `swarm bench soak` prints: the run, the losses, the recording, memory and the verdict."""

from __future__ import annotations

from swarm.bench.soak.checks import TARGET_GROWTH

LABELS = {"world": "world", "launcher": "launcher", "agent": "agent process"}


def _mb(kb: float | None) -> str:
    return "-" if kb is None else f"{kb / 1024:.1f}"


def format_soak_bench(r: dict) -> str:
    lo, start, end = r["losses"], *r["span_s"]
    missing = r["missing_ticks"]
    lines = [
        f"Soak: {r['kind']}, {r['agents']} agents in {r['agents'] // r['per_process']} processes, real-time at "
        f"{r['rate']:g} ticks/s, recording on, a SIGKILL every {r['kill_every']:g} s, respawned",
        "",
        f"{'duration':<28}{r['seconds'] / 60:.1f} min ({r['seconds']} s since every agent process joined)",
        f"{'kills (SIGKILL)':<28}{lo['kills']}",
        f"{'agent processes died':<28}{lo['died']}",
        f"{'agent processes replaced':<28}{lo['replaced']}",
        f"{'agents lost (world)':<28}{lo['agents_lost']} (kills x {r['per_process']} agents a process: "
        f"{lo['kills'] * r['per_process']}; beyond the kills: {lo['beyond_kills']})",
        f"{'ticks played / recorded':<28}{r['played']} / {r['recorded']}",
        f"{'ticks missing':<28}{len(missing)}{'' if not missing else ' (first ' + str(missing[:5]) + ')'}",
        f"{'missed agent-ticks (world)':<28}{r['missed_ticks']} (an agent's answer not in by its tick's end)",
        f"{'clock slips (world)':<28}{r['clock_slips']} (ticks begun too late to keep the rate: the world behind)",
        "",
        f"Resident memory (MB, median of the samples near each moment), growth over {start / 60:.1f}..{end / 60:.1f}"
        " min",
        "",
        f"{'process':<16}{f'at {start / 60:.1f} min':>13}{'at the end':>12}{'growth':>9}  target",
    ]
    for role, g in r["memory"].items():
        pct = "-" if g["growth_pct"] is None else f"{g['growth_pct']:+.1f}%"
        target = f"<= {TARGET_GROWTH:g}%" if g["verdict"] else "(replaced by the kills: not judged)"
        lines.append(f"{LABELS[role]:<16}{_mb(g['start_kb']):>13}{_mb(g['end_kb']):>12}{pct:>9}  {target}")
    lines += [
        "",
        "The world's process holds its router; an agent process: the mean of those alive.",
        "Agents lost beyond the kills: a live agent process's agents that missed 3 real-time ticks in a row",
        "(the world drops them and counts them lost; the process joins again).",
        "",
    ]
    if r.get("files"):
        lines += [f"files: {', '.join(r['files'])}", ""]
    counted = "every kill counted" if lo["all_counted"] else "NOT every kill counted"
    lines.append(f"verdict: {'met' if r['met'] else 'NOT met'} (memory growth <= {TARGET_GROWTH:g}% for the world and "
                 f"the launcher, {len(missing)} ticks missing, {counted})")  # fmt: skip
    return "\n".join(lines)
