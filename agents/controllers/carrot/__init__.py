"""`carrot`: the DFT paper's baseline (Appendix B): A* on the map the robot is
given, then follow the carrot from the noisy position sensor and the compass."""

from agents.controllers.carrot.controller import CarrotController, CarrotParams

__all__ = ["CarrotController", "CarrotParams"]
