"""The in-process engines: the grid's compiled lock-step loop (grid.py), the arena's (arena.py),
and the one loop any world kind runs on (stepper.py)."""
