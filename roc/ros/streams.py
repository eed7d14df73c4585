"""The streaming requests of the daemon protocol (docs/daemon.md), by name, and how to run one without
the daemon (roc.ros.in_process)."""

from __future__ import annotations

import contextlib
from typing import Any

from roc.ros.calls import call, goal
from roc.ros.dataplane import echo, frames, publish, stats
from roc.ros.decoded import decode, values
from roc.ros.protocol import Events

STREAMS = {"echo": echo, "publish": publish, "stats": stats, "call": call, "goal": goal, "frames": frames,
           "values": values, "decode": decode}


def run_on(graph, method: str, params: dict[str, Any], **in_process: Any) -> Events:
    """A stream on an existing Graph; its endpoint is destroyed when the caller stops iterating."""
    with contextlib.closing(STREAMS[method](graph, params, **in_process)) as events:
        yield from events
