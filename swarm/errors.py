"""Errors the `swarm` command reports as one line (exit status 2), kept in a
module that imports nothing heavy so the command can catch them cheaply."""


class RecordingError(Exception):
    """A recording is missing, not a swarm recording, damaged or truncated."""
