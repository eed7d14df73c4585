"""roc node info: what a node publishes, subscribes, serves and calls (like ros2 node info)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.commands.graph_query import ask
from roc.errors import RocError
from roc.render import render
from roc.ros.present import is_hidden

SECTIONS = (("subscribers", "Subscribers"), ("publishers", "Publishers"), ("service_servers", "Service Servers"),
            ("service_clients", "Service Clients"), ("action_servers", "Action Servers"),
            ("action_clients", "Action Clients"))


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("node_name", help="fully qualified node name, e.g. /talker")
    parser.add_argument("--include-hidden", action="store_true",
                        help="show a hidden node, and hidden topics, services and actions")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    info = ask(args, "node_info", {"node": args.node_name})
    if not args.include_hidden and args.node_name.rpartition("/")[2].startswith("_"):  # ros2's rule for nodes
        raise RocError(f"Unable to find node '{args.node_name}' (a hidden node: add --include-hidden)")
    for key, _ in SECTIONS:
        info[key] = [e for e in info[key] if args.include_hidden or not is_hidden(e["name"])]
    lines = [info["name"]]
    for key, title in SECTIONS:
        lines.append(f"  {title}:")
        lines += [f"    {e['name']}: {', '.join(e['types'])}" for e in info[key]] or [""]
    render(info, args.format, lines)
    return 0
