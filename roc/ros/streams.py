"""The streaming requests of the daemon protocol (docs/daemon.md), by name, and how to run one without
the daemon."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import Any

from roc.ros.calls import call, goal
from roc.ros.dataplane import echo, frames, publish, stats

STREAMS = {"echo": echo, "publish": publish, "stats": stats, "call": call, "goal": goal, "frames": frames}


def local_stream(method: str, params: dict[str, Any], node_name: str | None = None,
                 **in_process: Any) -> Iterator[dict[str, Any]]:
    """A stream without the daemon: its endpoint on a fresh participant of this process, on a node
    named ``node_name`` (default: a hidden one)."""
    from roc.ros.graph import Graph

    graph = Graph(node_name)
    try:
        with contextlib.closing(STREAMS[method](graph, params, **in_process)) as events:
            yield from events
    finally:
        graph.close()
