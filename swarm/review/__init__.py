"""Reading recordings back: `swarm report` and `swarm replay` (report.py), each world kind's summary
and plots from a recording (grid.py, arena.py: the review its entry in world_server.WORLD_KINDS names)."""
