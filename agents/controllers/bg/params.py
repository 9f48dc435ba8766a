"""The bg animat's one declared parameter set (Girard et al. 2005): every number of the model, each
with its provenance (swarm.core.params): the paper's, with the equation, table or section that gives
it; or ours, with the reason.  Every experiment runs this set and changes only what the paper says
that experiment changes (swarm.experiments.girard2005): the saliences' variant (eqs. 15-20),
W_plan, F, the planning condition and the start levels of E and Ep.

The GPR's constants (GprParams), the saliences' weights (SalienceWeights) and the senses' numbers
(SenseParams) are read by compiled kernels: their modules take module constants from these
defaults.  The metabolism is the world's (world_server.arena.metabolism.MetabolismParams)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from swarm.core.params import OURS, PAPER, declared

SALIENCES = ("survival", "fear", "tmaze")  # eqs. 15-17 (exps. 1, 2); 15, 16, 18 (exp. 3.1); 19, 20 (exp. 3.2)
WAYS = ("best", "places")  # NavParams.ways


@dataclass(frozen=True)
class BgParams:
    saliences: str = declared(
        "survival",
        source=PAPER,
        where="appendix A.2.1, eqs. 15-17 (experiments 1 and 2); fear: eq. 18 (exp. 3.1); tmaze: eqs. 19-20 (exp. 3.2)",
    )
    planning: bool = declared(
        True,
        source=PAPER,
        where="section 4.1: condition A, taxon and topological navigation (False: condition B, taxon only)",
    )
    w_plan: float = declared(0.65, source=PAPER, where="appendix A.2.1, after eq. 17: W_plan = 0.65")
    w_taxon: float = declared(0.55, source=PAPER, where="appendix A.2.1, after eq. 17: W_taxon(Ep) = 0.55")
    fear: float = declared(0.2, source=PAPER, where="section 4.3.1 (experiment 3.1): F = 0.2, m(DA)")
    # disinhibition an act needs to start (it goes on while above 0: docs/bg.md) ...
    dorsal_threshold: float = declared(
        0.9,
        source=OURS,
        reason="the paper's selection has no threshold; lower (0.3, "
        "0.5) the 0.6 mProx(E) m(E) term of eq. 15 starts ReloadE far from E and "
        "most animats die so (docs/bg.md, Selection)",
    )
    # ... a direction channel needs to join the vector sum (EP/SNr below 1.6 x rest)
    ventral_threshold: float = declared(
        -0.6,
        source=OURS,
        reason="in a 36-channel loop the diffuse STN lifts every "
        "output, so the winner hardly drops below rest; a dorsal selection lifts "
        "them to 1.6-2.2 x rest (docs/bg.md, Selection)",
    )
    feedback: str = declared(
        "rest",
        source=OURS,
        reason="the cortical feedback of eqs. 15-20 counts from the cortex's resting level: taken "
        "literally ('literal', an ablation), each dorsal channel gets 0.33 of salience from it at "
        "rest, above D1's threshold, and a salience of 0.1 selects an act outright, where 0.35 is "
        "needed from rest: the animat would reload at the faintest need (docs/bg.md, The GPR model)",
    )
    ventral_min_share: float = declared(
        0.1,
        source=OURS,
        reason="the ventral vector sum must be at least this share of its weights to give a direction: "
        "released channels pointing every way (a sum that nearly cancels) are no choice, and the animat "
        "holds its heading; the paper's read-out of a direction from 36 channels is not given",
    )
    hold_wheels: bool = declared(
        False,
        source=PAPER,
        where="section 2.2.3 and eq. 10: the loops alone stop the animat during an act (the "
        "trans-subthalamic cross term); True, which sets the wheels to zero whenever a dorsal act "
        "is selected, is an ablation (docs/bg.md, Selection)",
    )
    too_close: float = declared(
        0.45,
        source=OURS,
        reason="m from the centre: the paper's sonar reflex (section 3.2) "
        "has no distance; the bg corridors are 0.8 m for a 0.3 m body (docs/bg.md)",
    )
    reflex_hold: float = declared(
        2.0,
        source=OURS,
        reason="s the reflex drives straight on once the front is clear, past the obstacle (docs/bg.md, Sonar reflex)",
    )
    align: float = declared(
        math.radians(30),
        source=OURS,
        reason="heading error beyond which the animat turns on "
        "the spot; the paper gives no steering (docs/bg.md, Steering)",
    )
    learn_map: bool = declared(
        True,
        source=OURS,
        reason="a switch of ours: the paper's animat always maps; False "
        "keeps a loaded map as it is and only localizes on it",
    )
    share: bool = declared(
        False,
        source=OURS,
        reason="a colony (publish and merge maps on swarm/<run>/map/**) is ours; the paper has one animat",
    )
    map: str = declared(
        "",
        source=OURS,
        reason="a saved map (BgController.map_data() as JSON) to start from; the paper's animat starts with none",
    )


@dataclass(frozen=True)
class GprParams:
    """The GPR's numbers (appendix A.1).  The module constants below are taken from these defaults;
    the weights of eqs. 9-12 (`gp_to_ep`, `stn_diffuse`, `trn_lateral`) are literals of `_euler`,
    recorded here."""

    # Table 5: threshold epsilon and slope m of each nucleus's output, in NUCLEI order.
    epsilon: tuple[float, ...] = declared(
        (0.2, 0.2, -0.25, -0.2, -0.2, -0.8, 0.0, 0.0), source=PAPER, where="Table 5 (epsilon per nucleus)"
    )
    slope: tuple[float, ...] = declared(
        (1.0, 1.0, 1.0, 1.0, 1.0, 0.62, 0.5, 1.0), source=PAPER, where="Table 5 (m per nucleus)"
    )
    tau: float = declared(0.025, source=PAPER, where="appendix A.1, eq. 3: tau = 25 ms (Gurney's own code: 40 ms)")
    dopamine: float = declared(0.2, source=PAPER, where="appendix A.1, eqs. 5-6: lambda, the dopamine level (0.2)")
    dt: float = declared(
        0.001,
        source=OURS,
        reason="s, the Euler step: explicit Euler with the diffuse STN is "
        "stable only below 1.5 ms at 36 channels (docs/bg.md, Integration)",
    )
    cross: float = declared(0.4, source=PAPER, where="eq. 10: dorsal STN onto ventral EP/SNr, 0.4")
    feedback_dorsal: float = declared(0.4, source=PAPER, where="eqs. 15-16, 19-20: 0.4 P_E, 0.4 P_Ep")
    feedback_ventral: float = declared(0.2, source=PAPER, where="eqs. 17-18: 0.2 P_i")
    gp_to_ep: float = declared(0.4, source=PAPER, where="eqs. 9-10: -0.4 y_GP")
    stn_diffuse: float = declared(0.8, source=PAPER, where="eqs. 9-11: 0.8 sum y_STN")
    trn_lateral: float = declared(0.13, source=PAPER, where="eq. 12: -0.13 sum y_TRN")
    ventral_channels: int = declared(36, source=PAPER, where="section 2.2.2: 36 channels, directions 10 degrees apart")


@dataclass(frozen=True)
class SalienceWeights:
    """The weights of eqs. 15-20 (appendix A.2), recorded with their provenance: `_saliences` writes
    them as literals, in the order of the equations, so that it gives numpy's numbers to the bit.
    W_plan and W_taxon, which experiment 2.1 varies, are BgParams'; the feedback weights GprParams'."""

    e_usable: float = declared(1.2, source=PAPER, where="eq. 15: 1.2 A(E) m(E)")
    e_prox: float = declared(0.6, source=PAPER, where="eq. 15: 0.6 mProx(E) m(E)")
    ep_usable: float = declared(1.0, source=PAPER, where="eq. 16: A(Ep) m(Ep)")
    ep_prox: float = declared(0.2, source=PAPER, where="eq. 16: 0.2 mProx(Ep) m(Ep)")
    taxon_e: float = declared(0.55, source=PAPER, where="eq. 17: 0.55 sqrt(Prox(E)) m(E)")
    bka: float = declared(0.4, source=PAPER, where="eqs. 17-18: 0.4 BKA m(BKA)")
    expl: float = declared(0.25, source=PAPER, where="eq. 17: Exp (0.25 + ...)")
    expl_need: float = declared(0.05, source=PAPER, where="eqs. 17-18: 0.05 (1 - mProx(res)) m(res), Ep and E")
    fear_plan: float = declared(0.45, source=PAPER, where="eq. 18: 0.45 sqrt(Plan)")
    fear_taxon: float = declared(0.35, source=PAPER, where="eq. 18: 0.35 sqrt(Prox(E)) m(E), 0.35 sqrt(Prox(Ep)) m(Ep)")
    fear_danger: float = declared(0.19, source=PAPER, where="eq. 18: 0.19 (1 - Prox(DA)) m(DA)")
    fear_expl: float = declared(0.05, source=PAPER, where="eq. 18: Exp (0.05 + ...)")
    tmaze_usable: float = declared(0.9, source=PAPER, where="eqs. 19-20: 0.9 A(res) m(res)")
    tmaze_prox: float = declared(0.1, source=PAPER, where="eqs. 19-20: 0.1 mProx(res) m(res)")
    tmaze_plan: float = declared(
        0.55, source=PAPER, where="appendix A.2.3: 0.55 sqrt(Plan) (1 - mProx(E)) (1 - mProx(Ep))"
    )


@dataclass(frozen=True)
class SenseParams:
    """The numbers of the animat's senses; the module constants below are taken from these defaults."""

    grey: tuple[int, ...] = declared(
        (31, 127, 255),
        source=OURS,
        reason="grey levels of DA, Ep and E (RESOURCES "
        "order): the paper's simulated camera sees colours directly (section 3.2) and "
        "gives none; three levels far apart (docs/bg.md)",
    )
    window: int = declared(
        7, source=PAPER, where="section 3.2: contiguous pixels in a 7 pixels window centred on the direction"
    )
    side: float = declared(
        1 / 3,
        source=OURS,
        reason="the +-45 degree sonars set the reflex off at this share of "
        "too_close: in the bg corridors (0.8 m for a 0.3 m body) anything more sets it off at "
        "every sway (docs/bg.md, Sonar reflex)",
    )


@dataclass(frozen=True)
class NavParams:
    """Filliat-style navigation (section 2.1 describes it and gives no numbers: every value is ours,
    calibrated on bg-exp1 where docs/bg.md, Navigation, says so)."""

    spacing: float = declared(
        0.3,
        source=OURS,
        reason="odometric metres between two observations (the map's "
        "delta d): views 0.3 m apart match with median 0.65 on bg-exp1 (docs/bg.md)",
    )
    theta: float = declared(
        0.6,
        source=OURS,
        reason="largest dissimilarity (1 - P(match)) that joins the current "
        "node: P > 0.4, calibrated on bg-exp1 views (docs/bg.md, Navigation)",
    )
    closure_match: float = declared(
        0.45,
        source=OURS,
        reason="P(match) with which a known node the belief points at "
        "closes a loop, calibrated on bg-exp1 (docs/bg.md, Navigation)",
    )
    extent: float = declared(
        1.0,
        source=OURS,
        reason="m: a node stretches no farther from where it was first seen "
        "(Filliat's maps are dense; a uniform corridor stays a chain of nodes)",
    )
    closure_radius: float = declared(
        1.0,
        source=OURS,
        reason="m: a loop closes only onto a node this near by odometry, so alike places elsewhere "
        "do not fold the map; one node's extent (`extent`): farther, it is another place, and a "
        "closure 2 m off joins rooms that mirror each other through a 0.1 m wall (docs/bg.md, Navigation)",
    )
    merge_match: float = declared(
        0.6,
        source=OURS,
        reason="P(match) with which another animat's node is one of ours (within closure_radius); colonies are ours",
    )
    grey_scale: float = declared(
        35.0,
        source=OURS,
        reason="grey levels of one unit of dissimilarity, calibrated on bg-exp1 views (docs/bg.md, Navigation)",
    )
    sonar_scale: float = declared(
        1.0,
        source=OURS,
        reason="metres of one unit of dissimilarity, calibrated on bg-exp1 views (docs/bg.md, Navigation)",
    )
    d_rise: float = declared(
        0.1,
        source=OURS,
        reason="D rises 10% of the way to 1 per new node: the paper says only "
        "that D rises while nodes are made (section 2.1)",
    )
    d_fall: float = declared(
        0.9,
        source=OURS,
        reason="D falls by this factor per observation in a known node: the "
        "paper says only that it falls in well known areas (section 2.1)",
    )
    gain: float = declared(
        1.0,
        source=OURS,
        reason="Hebbian gain while a resource is usable, 1/s: a few seconds "
        "there and the node holds it; the paper gives no gain (section 4.2.2)",
    )
    forget: float = declared(
        0.02,
        source=OURS,
        reason="1/s while a resource is not even in sight: half forgotten in "
        "about 35 s there (the paper's forgetting took 178 s on average, section 4.2.2)",
    )
    reach: float = declared(15.0, source=OURS, reason="m: P falls by e over this route length (docs/bg.md, Navigation)")
    anchor: float = declared(
        0.0,
        source=OURS,
        reason="share of the way odometry is pulled to a recognized node: off, since a view matched "
        "to another place would pull the frame there (docs/bg.md, Alternatives considered)",
    )
    lookahead: float = declared(
        1.0,
        source=OURS,
        reason="m of route whose direction P points along: the route's first metre (docs/bg.md, Navigation)",
    )
    pursuit: float = declared(
        0.5,
        source=OURS,
        reason="m: P points at the first node of the route this far from the last observation, "
        "the next place on the way, not along the route's first metre, which cuts through a wall's "
        "end round a corner (0: the first metre; docs/bg.md, Navigation)",
    )
    width: float = declared(
        4.0,
        source=OURS,
        reason="von Mises concentration of a direction's bump over the 36 channels (kappa = 4, docs/bg.md)",
    )
    known_age: int = declared(
        20,
        source=OURS,
        reason="observations after its creation from which coming back to a "
        "node means a known area (docs/bg.md, Disorientation)",
    )
    near: float = declared(
        0.0,
        source=OURS,
        reason="m: link a new node to nodes observed this close; 0, only to "
        "nodes driven between: two places 0.5 m apart on either side of a wall are no route",
    )
    recent: float = declared(
        10.0,
        source=OURS,
        reason="m of travel within which `near` links (odometry drifts: "
        "farther back, near means little); unused while near is 0",
    )
    open_range: float = declared(
        1.0, source=OURS, reason="m of sonar room from which a direction counts as open (docs/bg.md, Expl)"
    )
    novelty_radius: float = declared(
        2.0, source=OURS, reason="m: nodes nearer than this, in a direction, make it known (docs/bg.md, Expl)"
    )
    wander_period: float = declared(
        20.0, source=OURS, reason="s between two draws of the exploration preference (docs/bg.md, Expl)"
    )
    wander_weight: float = declared(
        0.5, source=OURS, reason="weight of the random preference beside room and novelty when Expl picks its direction"
    )
    known_explore: float = declared(
        1.0,
        source=OURS,
        reason="Expl's height where the map knows its direction: a full bump wherever it points.  "
        "The paper's Expl points 'to explore unmapped areas' (section 2.1), but our novelty (no node "
        "within 2 m that way) is local: scaled by it (0), exploration dies out in corridors before "
        "the floor is mapped (on development seeds, 2 h mapping runs on bg-exp3 met 1-2 of its 4 "
        "resources, against all 4 in 30 min at 1; docs/bg.md, Expl)",
    )
    ways: str = declared(
        "places",
        source=OURS,
        reason="P(res) as a bump towards each place holding res (the largest where they overlap): "
        "the paper's P gives 'the proximity of that resource in 36 directions' (section 2.1), so "
        "two places of a resource pull two ways; 'best', one bump along the best route only "
        "(docs/bg.md, Navigation)",
    )
    place_radius: float = declared(
        2.0,
        source=OURS,
        reason="m: with ways = 'places', the nodes holding res this near "
        "the one holding it most are one place (docs/bg.md)",
    )
