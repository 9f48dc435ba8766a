"""Navigation shared by the arena controllers: occupancy grids and A* with
clearance (the carrot baseline and every arena summary's optimum L_o), and
path following."""
