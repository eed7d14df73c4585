"""What the lifecycle verbs share: which nodes are managed (they serve ``NODE/get_state`` of type
lifecycle_msgs/srv/GetState, as ros2 decides), and their states and transitions as plain data."""

from __future__ import annotations

import argparse
from typing import Any

from roc.cli.options import add_graph_arguments
from roc.commands.node_services import absolute_node_name, call, node_is_hidden, services_of_type
from roc.errors import RocError
from roc.ros.client import Session

GET_STATE = "lifecycle_msgs/srv/GetState"


def add_node_arguments(parser: argparse.ArgumentParser, optional: bool = False) -> None:
    """The node name (``optional``: every managed node when left out) and ``--include-hidden-nodes``."""
    parser.add_argument("node_name", nargs="?" if optional else None,
                        help="name of the node" + (", every managed node when left out" if optional else ""))
    parser.add_argument("--include-hidden-nodes", action="store_true", help="consider hidden nodes as well")
    add_graph_arguments(parser)


def managed_nodes(opened: Session, hidden: bool) -> list[str]:
    """The sorted full names of the graph's managed nodes (hidden ones only with ``hidden``)."""
    names = services_of_type(opened.query("snapshot"), "get_state", GET_STATE)
    return sorted(name for name in names if hidden or not node_is_hidden(name))


def managed_node(opened: Session, args: argparse.Namespace) -> str:
    """The full name of the node the command line names; ros2's "Node not found" when it is not managed."""
    name = absolute_node_name(args.node_name)
    if name not in managed_nodes(opened, args.include_hidden_nodes):
        raise RocError("Node not found")
    return name


def state_data(state: Any) -> dict[str, Any]:
    return {"id": state.id, "label": state.label}


def state(opened: Session, node: str) -> dict[str, Any]:
    from lifecycle_msgs.srv import GetState

    return state_data(call(opened, f"{node}/get_state", GET_STATE, GetState.Request()).current_state)


def transitions(opened: Session, node: str, every: bool = False) -> list[dict[str, Any]]:
    """The transitions available from the node's state (``every``: its whole transition graph), each
    {transition: {id, label}, start: {id, label}, goal: {id, label}}."""
    from lifecycle_msgs.srv import GetAvailableTransitions

    service = "get_transition_graph" if every else "get_available_transitions"
    response = call(opened, f"{node}/{service}", "lifecycle_msgs/srv/GetAvailableTransitions",
                    GetAvailableTransitions.Request())
    return [{"transition": state_data(t.transition), "start": state_data(t.start_state),
             "goal": state_data(t.goal_state)} for t in response.available_transitions]
