"""Billing, Lowe & Sandamirskaya (2015): the dft controller beside follow the carrot (its Appendix
B baseline) in the Z-maze and the large maze."""

from swarm.core.registry import ExperimentSpec, Option, PaperSpec

_MAZE = Option("--scenario", "zmaze or large-maze (default both)")
_NOISE = Option("--noise", "only the conditions at this noise level", choices=("none", "low", "high"))
_STEPS = Option("--max-steps", "run length limit in steps of 64 ms (default 3000, the paper's; the code used 2000)",
                dest="max_ticks", type="swarm.core.tables:positive", metavar="T")  # fmt: skip
_FLOOR = Option("--scenario", "another arena floor (a file or a name) with pairs drawn from the seed as case 2 "
                "draws them (default: the paper's maze)")  # fmt: skip
_PAIRS = Option("--pairs", "start/goal pairs from a CSV with start_x, start_y, goal_x, goal_y and optionally heading "
                "(runs.csv is one)", metavar="FILE")  # fmt: skip
_FIGURES_MAZE = Option("--scenario", "none: the figures are drawn in the paper's zmaze and large-maze")
_CASE2 = Option("--scenario", "large-maze, the default and the only one (the paper's case 2)")
_PARAMETER = Option("--parameter", "only this parameter's levels (prox_gain, prox_width, c_prox, ir_width, map_noise)",
                    metavar="NAME")  # fmt: skip
_DFT = "swarm.experiments.billing2015.dft:run_dft_experiment"
_WRITES = "runs.csv, summary.csv, table.md, plot.png"
EXPERIMENTS = (
    ExperimentSpec("carrot", "billing2015", "follow the carrot, ours and Appendix B's, in zmaze and large-maze "
                   "at three noise levels (DFT paper, cases 1-2)",
                   "swarm.experiments.billing2015.carrot:run_carrot_experiment", options=(_MAZE,)),
    ExperimentSpec("dft-case1", "billing2015", "the dft controller in zmaze beside follow the carrot", _DFT,
                   options=(_FLOOR, _PAIRS, _NOISE, _STEPS)),
    ExperimentSpec("dft-case2", "billing2015", "the dft controller in large-maze beside follow the carrot", _DFT,
                   options=(_FLOOR, _PAIRS, _NOISE, _STEPS), smoke=(("reps", 1), ("max_ticks", 300))),
    ExperimentSpec("dft-case3", "billing2015", "replanning round an obstacle", _DFT,
                   options=(_MAZE, _NOISE, _STEPS), writes=f"{_WRITES}, paths.png, paths.npz"),
    ExperimentSpec("dft-together", "billing2015", "a scout shares the obstacle it meets over the context key space",
                   _DFT, options=(_MAZE, _NOISE, _STEPS)),
    ExperimentSpec("dft-sensitivity", "billing2015", "case 2's SPA success against the proximity and IR "
                   "parameters and the map noise, one declared parameter at a time",
                   "swarm.experiments.billing2015.sensitivity:run_sensitivity", options=(_CASE2, _PARAMETER, _STEPS),
                   smoke=(("reps", 1), ("max_ticks", 60))),
    ExperimentSpec("dft-figures", "billing2015", "the paper's figures from dft runs: motivation fields, activity at "
                   "four places, planning time against path length, a replanning velocity profile, case-2 paths",
                   "swarm.experiments.billing2015.figures:run_dft_figures", options=(_FIGURES_MAZE, _STEPS),
                   writes="runs.csv, planning.csv, summary.csv, table.md, motivation.png, activity.png, "
                          "planning.png, velocity.png, paths.png",
                   smoke=(("reps", 2), ("max_ticks", 150))),
)  # fmt: skip
PAPER = PaperSpec(
    "billing2015",
    "Billing, Lowe & Sandamirskaya (2015): planning with dynamic neural fields",
    "swarm.experiments.billing2015.reproduce:reproduce",
    "docs/dft.md",
)
