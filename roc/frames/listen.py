"""A tf buffer filled from /tf and /tf_static (roc.ros.dataplane's ``frames`` stream, in the daemon
when it runs), for the frame verbs."""

from __future__ import annotations

import time
from collections.abc import Callable

from roc.errors import RocError
from roc.frames.buffer import Buffer
from roc.frames.transform import Transform
from roc.ros.client import stream
from roc.ros.types import TF_TYPE, UnknownTypeError, message_class


def require_tf2_msgs() -> None:
    """One line saying what to do when tf2_msgs is not installed (the ROS wheels of PyPI lack it)."""
    try:
        message_class(TF_TYPE)
    except UnknownTypeError:
        raise RocError("tf2_msgs is not installed (the ROS 2 wheels from PyPI lack it): source a ROS "
                         "install that has it, or build roc's example workspace (workspaces/example, which has a "
                         "tf2_msgs package) with 'roc work build' and source its install/setup.bash") from None


class Listener:
    """The buffer, the delays seen (reception minus stamp) and the nodes that sent each child frame
    (more than one when several nodes publish the same frame)."""

    def __init__(self, use_daemon: bool = True, early: bool = False):
        """``early``: a daemon that is starting serves it before its discovery period (for a verb that
        waits until it has heard what it needs, not for a fixed time)."""
        require_tf2_msgs()
        self.buffer = Buffer()
        self.delays: dict[str, list[float]] = {}
        self.publishers: dict[str, set[str]] = {}
        self._subscribed = False
        self._events = stream("frames", {"early": early}, use_daemon=use_daemon, heartbeats=True)

    def listen(self, done: Callable[[], bool] = lambda: False, seconds: float | None = None) -> bool:
        """Take in transforms until ``done()`` (True) or ``seconds`` have passed (False), counted from
        the subscription (a cold daemon takes a while to start)."""
        start = time.monotonic() if self._subscribed else None
        if done():
            return True
        for event in self._events:
            if event["event"] == "subscribed":
                self._subscribed, start = True, time.monotonic()
            for message in event.get("messages", ()):
                for parent, child_frame, stamp, translation, rotation in message["transforms"]:
                    received = message["received"] or time.time_ns()
                    self.buffer.add(parent, child_frame, stamp, Transform(tuple(translation), tuple(rotation)),
                                    message["static"], received)
                    child = child_frame.lstrip("/")
                    if message.get("publisher"):
                        self.publishers.setdefault(child, set()).add(message["publisher"])
                    if not message["static"]:
                        self.delays.setdefault(child, []).append((received - stamp) * 1e-9)
            if done():
                return True
            if seconds is not None and start is not None and time.monotonic() - start >= seconds:
                return False
        return False

    def close(self) -> None:
        self._events.close()
