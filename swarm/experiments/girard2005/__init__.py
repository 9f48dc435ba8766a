"""Girard, Filliat, Meyer, Berthoz & Guillot (2005): the basal-ganglia animat's survival and its
choices between resources, alone and as a colony sharing one map."""

from swarm.core.registry import ExperimentSpec, Option, PaperSpec

_FLOOR = Option("--scenario", "the floor: a bundled name or a TOML file with the resources the experiment names "
                "(Ep1, Ep2, DA; a T-maze's stem walls below_left, below_right) (default: the experiment's)",
                metavar="FILE")  # fmt: skip
_TMAZE_FLOOR = Option("--scenario", "one floor for experiments 1 and 3.2 instead of bg-exp1 and the tmaze-R floors: "
                      "a T-maze with Ep1, Ep2, E and the stem's walls below_left, below_right (not with --ratios)",
                      metavar="FILE")  # fmt: skip
_COLONY_FLOOR = Option("--scenario", "the colony's floor instead of bg-colony: an ingesting (Ep) and a digesting (E) "
                       "resource and a first [[group]] of bg animats, at its starts (drawn where it gives fewer)",
                       metavar="FILE")  # fmt: skip
_MAPS = Option("--maps", "mapping runs per scenario; test k loads map k mod N (default: one per test; 1: one map for "
               "every test)", type="swarm.core.tables:positive", metavar="N")  # fmt: skip
_MAPPING = Option("--mapping", "how the mapping animat maps: hungry, planning back to what it found, or exploring "
                  "without planning for at least 30 min (default: explore; docs/bg.md)",
                  choices=("hungry", "explore"))  # fmt: skip
_OPTIONS = "swarm.experiments.girard2005.options"
_BG = Option("--bg", "change a [bg] setting in every run, mapping runs included (repeatable; e.g. "
             "dorsal_threshold=0.8, navigation.pursuit=0: docs/bg.md)", type=f"{_OPTIONS}:bg_setting",
             metavar="KEY=VALUE", repeat=True, collect=f"{_OPTIONS}:bg_table")  # fmt: skip
_RATIOS = Option("--ratios", "right / left branch length ratios to run (default 1,1.5,2: tmaze-R scenarios)",
                 type=f"{_OPTIONS}:ratios", metavar="R,R,...")  # fmt: skip
_SIZES = Option("--sizes", "colony sizes to run (default 1,2,4,8)", type=f"{_OPTIONS}:sizes",
                metavar="N,N,...")  # fmt: skip
_RUN = "swarm.experiments.girard2005.standalone:run_bg_experiment"
# Smoke runs: reps 2, the least run_bg_experiment takes ("at least 2 runs per condition"), one map for every test,
# mapping runs of 2 minutes and survival runs cut short: every file is written in seconds.
EXPERIMENTS = (
    ExperimentSpec("bg-survival", "girard2005", "survival with and without its map", _RUN, options=(_FLOOR, _BG),
                   smoke=(("reps", 2), ("max_ticks", 2000))),
    ExperimentSpec("bg-choice", "girard2005", "a new resource", _RUN, options=(_FLOOR, _MAPS, _MAPPING, _BG),
                   smoke=(("reps", 2), ("maps", 1), ("mapping_seconds", 120.0))),
    ExperimentSpec("bg-forget", "girard2005", "a removed resource", _RUN, options=(_FLOOR, _MAPS, _MAPPING, _BG),
                   smoke=(("reps", 2), ("maps", 1), ("mapping_seconds", 120.0))),
    ExperimentSpec("bg-fear", "girard2005", "fear against need", _RUN, options=(_FLOOR, _MAPS, _MAPPING, _BG),
                   smoke=(("reps", 2), ("maps", 1), ("mapping_seconds", 120.0))),
    ExperimentSpec("bg-tmaze", "girard2005", "the T-maze", _RUN, options=(_FLOOR, _MAPS, _MAPPING, _BG, _RATIOS),
                   smoke=(("reps", 2), ("maps", 1), ("ratios", (1.0,)), ("mapping_seconds", 120.0))),
    ExperimentSpec("bg-ablations", "girard2005", "eq. 10's cross term, the literal feedback, the wheels, dopamine, "
                   "biased odometry: what each does to experiments 1 and 3.2",
                   "swarm.experiments.girard2005.ablations:run_ablations", options=(_TMAZE_FLOOR, _MAPS, _RATIOS),
                   smoke=(("reps", 2), ("maps", 1), ("ratios", (1.0,)), ("max_ticks", 200),
                          ("mapping_seconds", 120.0))),
    ExperimentSpec("bg-colony", "girard2005", "survival against colony size, with and without a shared map",
                   "swarm.experiments.girard2005.colony:run_colony_experiment",
                   options=(_COLONY_FLOOR, _SIZES),
                   smoke=(("reps", 1), ("sizes", (1, 2)), ("max_ticks", 200))),
)  # fmt: skip
PAPER = PaperSpec(
    "girard2005",
    "Girard, Filliat, Meyer, Berthoz & Guillot (2005): basal-ganglia action selection for a surviving animat",
    "swarm.experiments.girard2005.reproduce:reproduce",
    "docs/bg.md",
)
