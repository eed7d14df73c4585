"""What the verbs that drive nodes through their services share (``lifecycle``, ``component``): one
participant for the whole verb (the daemon's, or with ``--no-daemon`` one of this process, discovered
once), the nodes of the graph, and a call to a node's service that gives up after a timeout.

Calls go through the daemon protocol's ``call`` stream (roc.ros.calls), so verbs never import rclpy;
the request and response are message objects of the service's generated classes.
"""

from __future__ import annotations

import argparse
import contextlib
import time
from collections.abc import Iterator
from typing import Any

from roc.errors import RocError
from roc.ros.client import Session

SERVICE_TIMEOUT = 5.0  # seconds for a node's service to appear and answer, as ros2's verbs wait


@contextlib.contextmanager
def session(args: argparse.Namespace) -> Iterator[Session]:
    """The participant of one verb run, closed at its end."""
    opened = Session(use_daemon=not args.no_daemon, spin_time=args.spin_time)
    try:
        yield opened
    finally:
        opened.close()


def absolute_node_name(name: str) -> str:
    """A node name as ros2 makes it absolute (``talker`` -> ``/talker``)."""
    return name if name.startswith("/") else f"/{name}"


def node_is_hidden(full_name: str) -> bool:
    """ros2's rule for nodes: the node's own name (not its namespace) starts with '_'."""
    return full_name.rsplit("/", 1)[-1].startswith("_")


def services_of_type(graph: dict[str, Any], suffix: str, type_name: str) -> set[str]:
    """The full names of the graph's nodes that serve ``NODE/suffix`` of ``type_name``."""
    nodes = {n["full_name"] for n in graph["nodes"]}
    return {s["name"][:-len(suffix) - 1] for s in graph["services"]
            if s["name"].endswith(f"/{suffix}") and type_name in s["types"]} & nodes


def call(opened: Session, service: str, service_type: str, request: Any, timeout: float = SERVICE_TIMEOUT) -> Any:
    """Call ``service`` with ``request`` and return the response; a RocError when no server answers
    within ``timeout`` seconds."""
    from roc.ros.cdr import decode, encode
    from roc.ros.types import service_class

    params = {"service": service, "type": service_type, "request": encode(request)}
    response_class = service_class(service_type).Response
    deadline = time.monotonic() + timeout
    events = opened.stream("call", params, heartbeats=True)
    try:
        for event in events:
            if event["event"] == "response":
                return decode(response_class, event["data"])
            if time.monotonic() > deadline:
                break
    finally:
        events.close()  # the client goes with the stream
    raise RocError(f"'{service}' did not answer within {timeout:g} s")
