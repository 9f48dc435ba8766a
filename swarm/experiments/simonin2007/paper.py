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
