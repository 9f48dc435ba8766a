"""A grid controller of a user's own, outside swarm: a correlated random walk forager (walk.py)."""
