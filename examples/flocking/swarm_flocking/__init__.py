"""Reynolds flocking for swarm's arena: a controller package outside swarm (docs/controllers.md)."""
