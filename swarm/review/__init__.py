"""Reading recordings back: `swarm report` and `swarm replay` (report.py), the arena's summary and
plots from a recording (arena.py)."""
