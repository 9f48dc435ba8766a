"""`dft`: simultaneous planning and action with dynamic neural fields (Billing,
Lowe & Sandamirskaya 2015): an architecture declared as fields and couplings
(architecture.py), one engine that steps any such table (fields.py), and the
e-puck's faces to it (robot.py)."""

from agents.controllers.dft.controller import DftController, DftParams

__all__ = ["DftController", "DftParams"]
