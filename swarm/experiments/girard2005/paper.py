"""What our setup of Girard et al. (2005) does differently from the paper's, for the report (the paper's
printed numbers are bg.py's PAPER_* constants, which the experiments print too)."""

SURVIVAL_CAP = 4 * 3600.0  # s: "each run lasting at most 4 h"

KNOWN_DIFFERENCES = (
    "The paper's condition A median (14,431.5 s) and maximum (17,274 s) exceed its own 4 h cap (14,400 s); we "
    "cap at 4 h, count a run alive at the cap as censored there, and compare medians as Kaplan-Meier medians.",
    "bg-exp1 sets, for this floor only, usable_threshold = 0.5, closure_radius = 1.0 m and pursuit = 0.5, chosen "
    "on development seeds against failures traced there; the paper varies none of them.",
    "bg-exp3 sets navigation ways = 'places' and reach = 8.0 m, and bg-fear's tests known_explore = 0 (through "
    "its 'explore' mapping mode); the paper changes only F, the dangerous area and the start level of Ep.",
    "Oracle inputs: A(res) and the learning of which node holds a resource read the world's zone bits, not "
    "mProx(res) from the camera; mapping runs end when the harness sees every resource visited, with E lasting "
    "4 h and the dangerous area costing nothing while mapping.",
    "Any dorsal selection sets the wheels to zero directly (the paper's trans-subthalamic coordination, eq. 10, "
    "is not what stops the animat); the ventral read-out counts a channel released up to 1.6 times its resting "
    "output, with an incumbent-persists rule.",
    "Odometry and compass errors are drawn independently each tick, without bias, which flatters mapping.",
    "Experiments 2 and 3 load a map from a mapping run of their own floor (test k on map k, so conditions share "
    "maps and seeds); the paper's maps came from its animat's earlier life.  A test that has not reloaded Ep "
    "within 900 s counts as 'none' (censored for the time to forget).",
    "The 3.1 control removes the dangerous area and also sets F = 0.",
)
