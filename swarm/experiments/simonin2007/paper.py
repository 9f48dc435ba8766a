"""The numbers of Simonin, Charpillet & Thierry (2007) that we reproduce."""

# Table 1 (setup 1): agents -> (mean iterations, std deviation)
TABLE1 = {5: (19200, 10071), 10: (8697, 4282), 20: (4114, 1890), 40: (2263, 1134),
          80: (1070, 448), 160: (574, 420)}  # fmt: skip

# Table 2 (setup 2): agents -> experimental mean iterations (5000 runs each);
# projected = V_ref / n with V_ref the one-agent mean.
TABLE2 = {1: 1790.4, 2: 871.5, 3: 582.9, 4: 438.7, 5: 356.1, 6: 302.0, 7: 266.5, 8: 236.2}

# Table 3 (setup 3, 50 agents): side -> mean iterations; R = ratio to the previous size.
TABLE3 = {12: 155.5, 25: 345, 50: 805, 100: 2290, 200: 7844}

# Section 5.5: "as the environment grows the difference in the time required to
# forage by marking agents and by ants decreases (from 73% to 52% to 37%)".
# The text does not say at which sizes; we read them as the three largest sizes
# plotted in Figure 9 and compare our gap, 1 - cmarking / ant, at every size.
ANT_GAP_PERCENT = (73, 52, 37)

# What our setup does differently from the paper's, and why (the report's last section).
KNOWN_DIFFERENCES = (
    "Maps: the paper does not say how TurtleKit drew its 30% obstacles (a probability per cell or an exact count) "
    "nor whether a resource may sit where the base cannot reach; ours draw an exact count and place resources only "
    "where the base can reach (world_server/grid/scenario.py).",
    "Scheduling: TurtleKit steps agents one after another, each seeing the writes of those before it; ours all "
    "decide from the start-of-tick world, so lock-step distributed runs equal in-process runs (docs/engine.md).",
    "Loading takes the tick (choice 2 of docs/cmarking.md): about one iteration per trip.",
    "Rules 5 and 6 are open in the paper: ours mend the trail home and remember the previous cell at the base; "
    "the ablation above shows what each reading does.",
    "climb_patience (choice 9): a climber circling a loop of trail cells gives up after 20 steps; the literal "
    "rules livelock there.",
    "The ant model: the paper gives only its rates and compass homing; ours is NetLogo's Ants model (wiggle 40, "
    "sniffing ahead-left, ahead and ahead-right), tuned with the budget c-marking had (`swarm experiment tuning`).",
)
