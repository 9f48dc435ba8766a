"""What a grid controller sees of its world and how it travels: the perception, memory and action
rows (layout.py), the marking rule both sides apply (marks.py) and the messages (wire.py,
wire_bytes.py).  The only part of the grid an agent may import."""
