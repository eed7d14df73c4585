"""roc lifecycle nodes: the managed (lifecycle) nodes of the graph (like ros2 lifecycle nodes)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.commands.graph_query import add_count_argument, render_listing
from roc.commands.lifecycle.managed import managed_nodes
from roc.commands.node_services import session


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-a", "--all", action="store_true", help="display all nodes, hidden ones too")
    add_count_argument(parser, "nodes")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    with session(args) as opened:
        names = managed_nodes(opened, args.all)
    render_listing(args, names, names)
    return 0
