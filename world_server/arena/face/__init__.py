"""What an arena controller sees of its world and how it travels: the robot models the papers
give (robots.py), their sensors (sensors/: one module each) and the messages (wire.py).  The only
part of the arena an agent may import."""
