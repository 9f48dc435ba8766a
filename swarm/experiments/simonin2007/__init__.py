"""Simonin, Charpillet & Thierry (2007): c-marking foraging on the grid, its tables and studies."""

from swarm.core.registry import ExperimentSpec, Option, PaperSpec
from swarm.experiments.simonin2007.floors import HELP


def _floor(name: str) -> Option:
    """The experiment's --scenario: the grid floor it runs on instead of the paper's (floors.py)."""
    return Option("--scenario", HELP[name], metavar="FILE")


_RUN = "swarm.experiments.simonin2007.tables:run_experiment"
_TUNING_SIZES = Option("--tuning-sizes", "setup 3 sizes to tune at (default 25,50,100)",
                       type="swarm.experiments.simonin2007.tuning:sizes_option", metavar="N,N")  # fmt: skip
EXPERIMENTS = (
    ExperimentSpec("table1", "simonin2007", "setup 1, agents 5..160", _RUN, options=(_floor("table1"),)),
    ExperimentSpec("table2", "simonin2007", "setup 2, agents 1..8, projected vs experimental", _RUN,
                   options=(_floor("table2"),)),
    ExperimentSpec("table3", "simonin2007", "setup 3, 50 agents, sizes 12..200", _RUN, options=(_floor("table3"),)),
    ExperimentSpec("ants", "simonin2007", "c-marking vs the ant model, setup 3 sizes", _RUN,
                   options=(_floor("ants"),)),
    ExperimentSpec("congestion", "simonin2007", "setup 1, ideal vs physical bodies, agents 10..160", _RUN,
                   options=(_floor("congestion"),)),
    ExperimentSpec("tuning", "simonin2007",
                   "the ant and c-marking models tuned with the same budget on development seeds",
                   "swarm.experiments.simonin2007.tuning:run_tuning", options=(_floor("tuning"), _TUNING_SIZES),
                   smoke=(("reps", 1), ("tuning_sizes", (12,)))),
)  # fmt: skip
PAPER = PaperSpec(
    "simonin2007",
    "Simonin, Charpillet & Thierry (2007): c-marking agents foraging",
    "swarm.experiments.simonin2007.reproduce:reproduce",
    "docs/cmarking.md",
)
