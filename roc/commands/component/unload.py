"""roc component unload: unload components from a container node by unique id (like ros2 component
unload)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.commands.component.containers import CONTAINER_SERVICES, container
from roc.commands.node_services import call, session
from roc.errors import RocError
from roc.render import print_lines, render


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("container_node_name", help="container node to unload the components from")
    parser.add_argument("component_uid", type=int, nargs="+", help="unique id of a component to unload")
    parser.add_argument("-q", "--quiet", action="store_true", help="only print the unloaded components' ids")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    from composition_interfaces.srv import UnloadNode

    name = args.container_node_name
    unloaded: list[int] = []
    with session(args) as opened:
        container(opened, name)
        for uid in args.component_uid:
            try:
                response = call(opened, f"{name}/_container/unload_node", CONTAINER_SERVICES["_container/unload_node"],
                                UnloadNode.Request(unique_id=uid))
            except RocError:
                raise RocError(f"No 'unload_node' service found for '{name}' container") from None
            if not response.success:
                if args.format == "json":
                    render({"container": name, "unloaded": unloaded}, args.format)
                raise RocError(f"Failed to unload component {uid} from '{name}' container node\n    "
                               f"{response.error_message.capitalize()}")
            unloaded.append(uid)
            if args.format == "text":
                print_lines([str(uid) if args.quiet else f"Unloaded component {uid} from '{name}' container node"])
    render({"container": name, "unloaded": unloaded}, args.format, [])
    return 0
