"""Simonin, Charpillet & Thierry (2007): c-marking foraging on the grid, its tables and studies."""

from swarm.core.registry import ExperimentSpec, Option, PaperSpec

_RUN = "swarm.experiments.simonin2007.tables:run_experiment"
EXPERIMENTS = (
    ExperimentSpec("table1", "simonin2007", "setup 1, agents 5..160", _RUN),
    ExperimentSpec("table2", "simonin2007", "setup 2, agents 1..8, projected vs experimental", _RUN),
    ExperimentSpec("table3", "simonin2007", "setup 3, 50 agents, sizes 12..200", _RUN),
    ExperimentSpec("ants", "simonin2007", "c-marking vs the ant model, setup 3 sizes", _RUN),
    ExperimentSpec("congestion", "simonin2007", "setup 1, ideal vs physical bodies, agents 10..160", _RUN),
    ExperimentSpec(
        "tuning",
        "simonin2007",
        "the ant and c-marking models tuned with the same budget on development seeds",
        "swarm.experiments.simonin2007.tuning:run_tuning",
        options=(
            Option(
                "--tuning-sizes",
                "setup 3 sizes to tune at (default 25,50,100)",
                type="swarm.experiments.simonin2007.tuning:sizes_option",
                metavar="N,N",
            ),
        ),
        smoke=(("reps", 1), ("tuning_sizes", (12,))),
    ),
)
PAPER = PaperSpec(
    "simonin2007",
    "Simonin, Charpillet & Thierry (2007): c-marking agents foraging",
    "swarm.experiments.simonin2007.reproduce:reproduce",
    "docs/cmarking.md",
)
