"""scripts/tick_budget.py: the model behind docs/scale.md adds up a tick's parts and splits them by region."""

import subprocess
import sys
from pathlib import Path

from tests.helpers import load_script

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "tick_budget.py"


def test_a_split_divides_the_worlds_work_and_adds_a_region_exchange():
    budget = load_script("tick_budget")
    setup = budget.Setup()
    whole, split = budget.tick(setup, 1), budget.tick(setup, 16)
    assert whole["exchange"] == 0 < split["exchange"]
    assert whole["world"] / 16 < split["world"] < whole["world"] / 8  # a ghost band on top of a 16th
    assert whole["total"] == sum(whole[k] for k in ("world", "hops", "exchange")) + max(whole["wire"], whole["agents"])
    slower = budget.tick(budget.Setup(agent_step_seconds=1.3e-3), 1)  # DFT robots: the agent hosts set the pace
    assert slower["agents"] > slower["wire"]


def test_physics_strips_divide_all_but_the_serial_share_and_pay_for_their_ghosts():
    budget = load_script("tick_budget")
    setup = budget.Setup()
    one = budget.physics(setup, 10_000, 63.2)
    two = budget.physics(budget.Setup(physics_strips=2), 10_000, 63.2)
    assert one == 10_000 * budget.PHYSICS_SECONDS_PER_ROBOT
    assert abs(two / one - 0.748) < 0.01  # the measured share of one space's time that the serial share comes from
    many = budget.Setup(physics_strips=64, world_cores=16)
    assert budget.physics(many, 10_000, 63.2) > budget.physics(budget.Setup(physics_strips=16), 10_000, 63.2)
    assert budget.tick(budget.Setup(physics_strips=16))["world"] < budget.tick(setup)["world"]


def test_the_command_prints_one_row_per_split():
    done = subprocess.run([sys.executable, str(SCRIPT), "--robots", "1000", "--splits", "1,4"], capture_output=True,
                          text=True, timeout=60)  # fmt: skip
    assert done.returncode == 0, done.stderr
    rows = [line for line in done.stdout.splitlines() if line.startswith("| 1 |") or line.startswith("| 4 |")]
    assert len(rows) == 2
