"""roc node list: the nodes of the ROS graph (like ros2 node list); names shared by several nodes are
flagged on stderr."""

from __future__ import annotations

import argparse
import sys
from collections import Counter

from roc.cli.options import add_graph_arguments
from roc.commands.graph_query import add_count_argument, render_listing, snapshot
from roc.render import print_lines


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-a", "--all", action="store_true", help="display all nodes, hidden ones too")
    add_count_argument(parser, "nodes")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    # ros2's rule for nodes: hidden when the node's own name (not its namespace) starts with "_".
    nodes = [n for n in snapshot(args, "nodes") if args.all or not n["name"].startswith("_")]
    counts = Counter(n["full_name"] for n in nodes)
    data = sorted(({"name": name, "duplicate": counts[name] > 1} for name in counts.elements()),
                  key=lambda n: n["name"])
    render_listing(args, data, [n["name"] for n in data])
    if args.format == "text" and not args.count:
        print_lines([f"roc: warning: several nodes are named {name}: {count} nodes; give each a unique name "
                     "(parameters, services and node info mix them up)" for name, count in sorted(counts.items())
                     if count > 1], sys.stderr)
    return 0
