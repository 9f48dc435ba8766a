"""The grid world kind (Simonin et al. 2007): cells of obstacles, resources, marks, trails and
pheromone; the tick rules (world.py), robot bodies (bodies.py), the scenario section
(scenario.py), the world process's binding (server.py) and the face its controllers see (face/)."""
