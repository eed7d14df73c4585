"""What the param verbs share: the node they talk to and, as ros2 param, how long to wait for it."""

from __future__ import annotations

import argparse
from typing import Any

from roc.cli.options import add_graph_arguments
from roc.commands.graph_query import ask


def absolute_node_name(name: str) -> str:
    """ros2 param's reading of a node name: a relative one is taken from the root (``foo/n`` -> ``/foo/n``)."""
    return name if name.startswith("/") else f"/{name}"


def add_node_arguments(parser: argparse.ArgumentParser) -> None:
    """``NODE_NAME`` (the first positional argument), ``--timeout`` and the graph options."""
    parser.add_argument("node_name", type=absolute_node_name,
                        help="node name, e.g. /talker (a relative name is taken from the root)")
    parser.add_argument("--timeout", type=int, default=1, metavar="N",
                        help="wait up to N seconds for the node to appear (default: 1)")
    add_graph_arguments(parser)


def ask_node(args: argparse.Namespace, method: str, params: dict[str, Any] | None = None) -> Any:
    """A request about ``args.node_name``: ros2's "Node not found" when the graph has had no such node
    for ``args.timeout`` seconds."""
    return ask(args, method, {"node": args.node_name, "timeout": args.timeout, **(params or {})})
