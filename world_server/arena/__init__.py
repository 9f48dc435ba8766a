"""The arena world kind: a continuous floor of walls, zones and scheduled obstacles with
differential-drive robots; ray-cast sensing (raycast.py, sensors.py), bodies (drive.py), the BG
paper's metabolism, the scenario section, the summary, the world process's binding (server.py)
and the face its controllers see (face/)."""
