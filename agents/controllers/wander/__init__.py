"""`wander`: a reactive explorer for any robot model - drive ahead, turn away
from what the range sensors see in front, and now and then turn at random."""

from agents.controllers.wander.controller import WanderController, WanderParams

__all__ = ["WanderController", "WanderParams"]
