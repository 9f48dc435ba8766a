"""Errors the `swarm` command reports as one line (exit status 2), and the
SIGTERM handler that turns termination into KeyboardInterrupt, kept in a module
that imports nothing heavy so the command can use them cheaply."""


class RunError(Exception):
    """A run cannot start or go on: a process of it failed, or the world refused an agent."""


class RecordingError(Exception):
    """A recording is missing, not a swarm recording, damaged or truncated."""


def raise_interrupt(signum, frame):
    """SIGTERM handler: end like Ctrl-C, so `finally` blocks close sessions, recordings and children
    (docker stop, kill, a timeout; python as a container's PID 1 would otherwise ignore SIGTERM)."""
    raise KeyboardInterrupt


class ScenarioError(ValueError):
    """A scenario that cannot be used; the message says where and what is expected."""

    def __init__(self, source: str, where: str, problem: str):
        self.source, self.where, self.problem = source, where, problem
        super().__init__(f"{source}: {where}: {problem}")

    def __reduce__(self):
        """Rebuilt from its three parts, so a worker process's error reaches the command as one line."""
        return type(self), (self.source, self.where, self.problem)


def one_line(exc: BaseException) -> str:
    """An exception as one line: its type and the first line of its message (a user's code raised it)."""
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0]}" if text else type(exc).__name__


class StateError(Exception):
    """A saved world state that cannot be resumed from: cut short, damaged, or of another format."""
