"""The in-process fallback of roc.ros.client: queries and streams on a participant of this process
(``--no-daemon``, or a type the daemon's environment lacks). The one seam through which the client
reaches the rclpy graph; importing this module imports rclpy."""

from __future__ import annotations

from typing import Any

from roc.ros.discovery import LocalParticipantProbe
from roc.ros.graph import Graph
from roc.ros.protocol import Events
from roc.ros.streams import run_on


def discovered_graph(spin_time: float | None = None, node_name: str | None = None, asks_only: bool = False,
                     probe: LocalParticipantProbe | None = None) -> Graph:
    """A fresh participant that has waited for discovery (at most ``spin_time``; see
    Graph.wait_for_discovery for the default and ``probe``, which this closes); ``asks_only``: see Graph."""
    try:
        graph = Graph(node_name, asks_only=asks_only)
    except BaseException:
        if probe is not None:
            probe.close()
        raise
    try:
        graph.wait_for_discovery(spin_time, probe)
    except BaseException:
        graph.close()
        raise
    return graph


def stream(method: str, params: dict[str, Any], **in_process: Any) -> Events:
    """A stream without the daemon: its endpoints on a fresh participant of this process."""
    graph = Graph()
    try:
        yield from run_on(graph, method, params, **in_process)
    finally:
        graph.close()


def stream_on(graph: Graph, method: str, params: dict[str, Any]) -> Events:
    """A stream on a participant made by discovered_graph."""
    return run_on(graph, method, params)
