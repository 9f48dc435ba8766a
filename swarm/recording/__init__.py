"""Rerun recordings of runs, one module per world kind (grid.py, arena.py); what explains a
controller is recorded by the logs its registry entry names, in its own folder."""
