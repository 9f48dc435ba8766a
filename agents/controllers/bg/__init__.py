"""`bg`: basal-ganglia action selection and navigation for a surviving animat
(Girard et al. 2005): the GPR loops (gpr.py), the animat's senses
(senses.py), its saliences (saliences.py) and its map (places.py, on the
shared topological map)."""

from agents.controllers.bg.controller import BgController, BgParams

__all__ = ["BgController", "BgParams"]
