"""The Python API: docs/api.md's examples run as they are written, and the function gives what
the command gives."""

from __future__ import annotations

import doctest
import json
import subprocess
import sys
from pathlib import Path

import swarm

API_DOC = Path(__file__).parents[1] / "docs" / "api.md"


def test_the_api_pages_examples_run():
    flags = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
    result = doctest.testfile(str(API_DOC), module_relative=False, optionflags=flags, verbose=False)
    assert result.attempted >= 10 and result.failed == 0


def test_a_run_from_python_equals_the_command_and_its_metrics_are_the_recordings(tmp_path):
    args = ["zmaze", "--controller", "wander", "--agents", "2", "--seed", "4", "--max-ticks", "120"]
    done = subprocess.run([sys.executable, "-m", "swarm", "run", *args, "--json"], capture_output=True, text=True)
    printed = json.loads(done.stdout)
    result = swarm.run("zmaze", controller="wander", agents=2, seed=4, max_ticks=120, record=tmp_path / "r.rrd")
    keep = lambda s: {k: v for k, v in s.items() if k not in ("wall_seconds", "ticks_per_second")}  # noqa: E731
    assert keep(result.summary) == keep(printed)
    assert result.recording == tmp_path / "r.rrd" and result.recording.exists()
    assert list(result.ticks) == list(range(120))
    assert abs(result.metrics["distance"][-1] - sum(r["distance"] for r in printed["robots"])) < 1e-3  # rounded
