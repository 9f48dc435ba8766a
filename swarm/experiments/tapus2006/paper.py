"""The numbers of Tapus, Battaglia & Siegwart (2006), section 4, that we reproduce.

The paper reports one mapping run and one localization run of one robot on its institute's floor
(its Figure 4, not available), without intervals.
"""

# Mapping (Figure 4): a 75 m tour, 500 fingerprints, a map of 20 nodes.
MAPPING_TOUR_M = 75
MAPPING_FINGERPRINTS = 500
NODES = 20

# Localization: "more than 1000 fingerprint samples ... a new path of 250 m".
LOCALIZE_TOUR_M = 250
LOCALIZE_FINGERPRINTS = 1000  # "more than 1000": the least it can be
MATCH = 0.81  # "a percentage of successful matches of 81%" (fingerprint matching alone)
MARKOV = 1.00  # "A success rate of 100%" (matching with the robot's motion, POMDP)
MISSED_RANKS = (2, 3)  # "false-classified nodes have delivered high probability (2nd or 3rd highest)"

# Loop closing: "The robot succeeded all the times to close the loops."
LOOPS_CLOSED = 1.00
