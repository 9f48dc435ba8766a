"""What an arena controller sees of its world and how it travels: the robot models and sensor
suites the papers give (robots.py) and the messages (wire.py).  The only part of the arena an
agent may import."""
