"""Where a recording goes: its file, and a live viewer only if one answers.

rerun streams to a viewer through a bounded queue: when the viewer's address takes no connection,
the queue fills and every flush of the recording (the file's included) waits on it for ever, so
the run would hang.  A viewer that does not answer when the run starts is therefore left out, in
one line, and the run records to its file alone, as it does when no viewer can be spawned.  A viewer
that goes away during the run makes rerun's flushes raise; `Flusher` says so in one line and the run
goes on, its file whole (the file sink is written beside the viewer's, not after it).
"""

from __future__ import annotations

import socket
import sys
from typing import Any
from urllib.parse import urlsplit

ANSWER_SECONDS = 3.0  # a viewer on another host of the run answers well within this


def answers(url: str, timeout: float = ANSWER_SECONDS) -> str | None:
    """None if the viewer at `url` (rerun+http://HOST:PORT/proxy) takes a connection, else why not."""
    try:
        parts = urlsplit(url)
        host, port = parts.hostname, parts.port or 9876
    except ValueError as exc:
        return f"not a viewer URL ({exc})"
    if not host:
        return "not a viewer URL (expected rerun+http://HOST:PORT/proxy)"
    try:
        with socket.create_connection((host, port), timeout=timeout):
            return None
    except OSError as exc:
        return exc.strerror or str(exc) or type(exc).__name__


def stream_to(rr: Any, rec: Any, path: str, viewer: str | None, blueprint: Any) -> Flusher:
    """Point `rec` at its file, and at the viewer when the viewer answers (one line on stderr if not);
    returns the recording's flush, which knows whether a viewer is streamed to."""
    out = [rr.FileSink(path)]
    if viewer and (why := answers(viewer)) is not None:
        print(f"swarm: the rerun viewer at {viewer} does not answer ({why}); recording to {path} only",
              file=sys.stderr)  # fmt: skip
        viewer = None
    if viewer:
        out.append(rr.GrpcSink(viewer))
    rec.set_sinks(*out, default_blueprint=blueprint)
    return Flusher(viewer, path)


class Flusher:
    """The recording's flushes, for a run whose viewer (`viewer`, or None) may go away mid-run: rerun then
    raises at every flush ("gRPC connection severed", "unable to connect"); the first such error is one
    line on stderr and the rest are ignored, while any other error (the file's) is raised."""

    def __init__(self, viewer: str | None, path: str):
        self.viewer, self.path, self.gone = viewer, path, False

    def __call__(self, rec: Any, **kwargs: Any) -> None:
        try:
            rec.flush(**kwargs)
        except RuntimeError as exc:
            if not self.viewer or "grpc" not in str(exc).lower():
                raise
            if not self.gone:
                self.gone = True
                print(f"swarm: the rerun viewer at {self.viewer} went away ({str(exc).splitlines()[0]}); "
                      f"recording to {self.path} only", file=sys.stderr)  # fmt: skip
