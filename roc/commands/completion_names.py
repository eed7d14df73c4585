"""The names a shell completes from the ROS graph (``roc completion --names KIND``): topics, nodes,
services, actions, parameters and tf frames from the roc daemon when one runs for this environment,
interface types from the ament index (and the graph). Never a participant of its own: without a
running daemon only the installed types are offered, and every answer is bounded by a short timeout.
"""

from __future__ import annotations

import time

from roc.ros.client import Connection, connect
from roc.ros.present import is_hidden

KINDS = ("topics", "nodes", "services", "actions", "types", "msg-types", "srv-types", "action-types", "params",
         "frames")
TIMEOUT = 2.0  # seconds for one answer of the daemon
FRAMES_SECONDS = 0.5  # how long to listen to /tf (a static frame comes at once, a dynamic one at its rate)


def _graph_names(connection: Connection, kind: str) -> list[str]:
    snapshot = connection.request("snapshot", timeout=TIMEOUT)
    if kind == "nodes":
        return [n["full_name"] for n in snapshot["nodes"] if not n["name"].startswith("_")]
    return [entry["name"] for entry in snapshot[kind] if not is_hidden(entry["name"])]


def _types(kind: str, connection: Connection | None) -> list[str]:
    """Installed interface types (of one kind for ``msg-types`` ...), and the types of the graph's
    topics for messages."""
    from roc.ros.interfaces import package_interfaces

    kinds = ("msg", "srv", "action") if kind == "types" else (kind.split("-")[0],)
    names = {f"{package}/{k}/{name}" for package, interfaces in package_interfaces().items()
             for k in kinds for name in interfaces[k]}
    if connection is not None and "msg" in kinds:
        names.update(t for topic in connection.request("snapshot", timeout=TIMEOUT)["topics"] for t in topic["types"])
    return sorted(names)


def _params(connection: Connection, node: str | None) -> list[str]:
    if not node:
        return []
    found = connection.request("param_list", {"node": node}, timeout=TIMEOUT)
    return [p["name"] for entry in found for p in entry["parameters"]]


def _frames(connection: Connection) -> list[str]:
    """The frames /tf and /tf_static carry, heard for FRAMES_SECONDS (the daemon decodes them; a daemon
    without tf2_msgs answers with an error, which ``names`` turns into no names)."""
    frames: set[str] = set()
    deadline = time.monotonic() + FRAMES_SECONDS
    for event in connection.stream("frames", {}, timeout=TIMEOUT):
        for message in event.get("messages", ()):
            for parent, child, *_ in message["transforms"]:
                frames.update((parent.lstrip("/"), child.lstrip("/")))
        if time.monotonic() >= deadline or event.get("final"):
            break
    return sorted(frames)


def names(kind: str, node: str | None = None) -> list[str]:
    """What to offer for ``kind``; nothing the daemon would have to be started for."""
    connection = connect()
    try:
        if kind.endswith("types"):
            return _types(kind, connection)
        if connection is None:
            return []
        if kind == "params":
            return _params(connection, node)
        if kind == "frames":
            return _frames(connection)
        return sorted(set(_graph_names(connection, kind)))
    except Exception:  # noqa: BLE001 - a completion offers nothing rather than an error
        return []
    finally:
        if connection is not None:
            connection.close()


def offered(kind: str, node: str | None = None) -> list[str]:
    """``names``, for the shell (a list it can split on white space)."""
    return [name for name in names(kind, node) if name and not any(c.isspace() for c in name)]

