"""What the daemon client, the daemon, the rclpy graph and the data plane share, without rclpy: the
discovery variables, discovery timing, name rules and the parameter type names of the wire format
(docs/daemon.md). Every module of roc/ros/ may import this one; it imports none of them."""

from __future__ import annotations

import os
from collections.abc import Generator, Mapping
from typing import Any

# The variables that decide what a participant discovers: a daemon serves one set of values.
DISCOVERY_VARIABLES = ("ROS_DOMAIN_ID", "RMW_IMPLEMENTATION", "ROS_AUTOMATIC_DISCOVERY_RANGE",
                       "ROS_STATIC_PEERS", "ROS_LOCALHOST_ONLY")
# A fresh participant's discovery lasts this long at most (see roc.ros.graph: Graph.wait_for_discovery).
DEFAULT_SPIN_TIME = 3.5
# A stream sends an event at least this often, so a client can act between messages.
HEARTBEAT_SECONDS = 0.5

# A stream's events (docs/daemon.md): a generator, so that closing it ends the stream and removes its endpoint.
Events = Generator[dict[str, Any], None, None]

# rcl_interfaces' ParameterType codes, by the names roc sends on the wire ({"type": ..., "value": ...}).
PARAMETER_TYPES = {0: "not set", 1: "boolean", 2: "integer", 3: "double", 4: "string", 5: "byte array",
                   6: "boolean array", 7: "integer array", 8: "double array", 9: "string array"}
VALUE_FIELDS = {1: "bool_value", 2: "integer_value", 3: "double_value", 4: "string_value",
                5: "byte_array_value", 6: "bool_array_value", 7: "integer_array_value",
                8: "double_array_value", 9: "string_array_value"}


# roc's own participants (the daemon's, a daemon-less verb's) are nodes named _roc_<pid>: no listing or
# count roc prints includes them or their endpoints (roc.ros.graph).
OWN_NODE_PREFIX = "_roc_"


def own_node_name(pid: int) -> str:
    return f"{OWN_NODE_PREFIX}{pid}"


def is_own_node(name: str) -> bool:
    """A node of roc's own (see OWN_NODE_PREFIX); a bridge's (``_roc_bridge_*``) is not."""
    return name.startswith(OWN_NODE_PREFIX) and name[len(OWN_NODE_PREFIX):].isdigit()


def task_node_name(task: str, pid: int | None = None) -> str:
    """The node of something a user asked roc to do, named for it (``frame_pub`` -> ``roc_frame_pub_<pid>``,
    of the process that asked): what it publishes is listed like any other node's, unlike what roc's own
    nodes do (see OWN_NODE_PREFIX)."""
    return f"roc_{task}_{os.getpid() if pid is None else pid}"


def discovery_environment(env: Mapping[str, str] | None = None) -> dict[str, str]:
    env = os.environ if env is None else env
    return {name: env.get(name, "") for name in DISCOVERY_VARIABLES}


def discovery_range(env: Mapping[str, str] | None = None) -> str:
    """The range rcl uses: LOCALHOST also for the deprecated ROS_LOCALHOST_ONLY=1."""
    env = os.environ if env is None else env
    if env.get("ROS_LOCALHOST_ONLY") == "1":
        return "LOCALHOST"
    return env.get("ROS_AUTOMATIC_DISCOVERY_RANGE") or "SUBNET"


def middleware(environment: Mapping[str, str] | None = None) -> str:
    """The RMW implementation rcl will load (Fast DDS unless RMW_IMPLEMENTATION says otherwise)."""
    environment = os.environ if environment is None else environment
    return environment.get("RMW_IMPLEMENTATION") or "rmw_fastrtps_cpp"


def discovery_stays_local(env: Mapping[str, str] | None = None) -> bool:
    """Discovery reaches no other host: the LOCALHOST (or OFF) range without static peers."""
    env = os.environ if env is None else env
    return discovery_range(env) in ("LOCALHOST", "OFF") and not env.get("ROS_STATIC_PEERS")


def full_name(namespace: str, name: str) -> str:
    """A node's full name from its namespace and name (``/ns`` + ``n`` -> ``/ns/n``)."""
    return f"{namespace.rstrip('/')}/{name}"
