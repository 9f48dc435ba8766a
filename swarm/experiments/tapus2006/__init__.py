"""Tapus, Battaglia & Siegwart (2006): topological mapping and localization with fingerprints of
places on the office floor."""

from swarm.core.registry import ExperimentSpec, Option, PaperSpec

_FLOOR = Option("--scenario", "a floor with place zones, a 'mapping' route and localization tours among "
                "'new-path', 'localize' and 'localize-off-map' (default office; office-l is another)")  # fmt: skip
_TEAM_FLOOR = Option("--scenario", "a floor with a 'mapping' route (robot k of N drives its k-th stretch) and place "
                     "zones (default office: robot k surveys the k-th stretch of the corridor and its rooms)",
                     metavar="FILE")  # fmt: skip
_RUN = "swarm.experiments.tapus2006.fingerprint:run_fingerprint_experiment"
EXPERIMENTS = (
    ExperimentSpec("fingerprint-calibrate", "tapus2006", "fit the alignment's defaults on the mapping tour", _RUN,
                   options=(_FLOOR,), writes="runs.csv, table.md"),
    ExperimentSpec("fingerprint-map", "tapus2006", "map the floor on one tour", _RUN, options=(_FLOOR,),
                   writes="runs.csv, table.md, summary.csv, plot.png", smoke=(("reps", 1),)),
    ExperimentSpec("fingerprint-localize", "tapus2006", "map on one tour, localize on another", _RUN,
                   options=(_FLOOR,), writes="runs.csv, table.md, summary.csv, plot.png",
                   smoke=(("reps", 1), ("tours", ("new-path",)))),
    ExperimentSpec("fingerprint-together", "tapus2006", "surveyors of office sharing one map",
                   "swarm.experiments.tapus2006.team:run_team_experiment", options=(_TEAM_FLOOR,),
                   writes="runs.csv, table.md, plot.png",
                   smoke=(("reps", 1), ("teams", (1, 2)))),
    ExperimentSpec("fingerprint-robustness", "tapus2006", "localization under camera noise, biased odometry and "
                   "compass, a kidnapping, and against delta-d and theta",
                   "swarm.experiments.tapus2006.robustness:run_robustness_experiment", options=(_FLOOR,),
                   writes="runs.csv, summary.csv, table.md, plot.png",
                   smoke=(("reps", 1), ("waypoints", 8), ("conditions", ("camera", "kidnap")))),
)  # fmt: skip
PAPER = PaperSpec(
    "tapus2006",
    "Tapus, Battaglia & Siegwart (2006): fingerprints of places, topological mapping and localization",
    "swarm.experiments.tapus2006.reproduce:reproduce",
    "docs/fingerprint.md",
)
