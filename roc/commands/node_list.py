"""roc node list: the nodes of the ROS graph (like ros2 node list); names shared by several nodes are
flagged on stderr."""

from __future__ import annotations

import argparse
import sys
from collections import Counter

from roc.cli.options import add_graph_arguments
from roc.render import print_lines, render
from roc.ros.client import query


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-a", "--all", action="store_true", help="display all nodes, hidden ones too")
    parser.add_argument("-c", "--count-nodes", action="store_true", help="print only the number of nodes")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    nodes = query("snapshot", use_daemon=not args.no_daemon, spin_time=args.spin_time)["nodes"]
    names = sorted(n["full_name"] for n in nodes if args.all or not n["name"].startswith("_"))
    duplicates = sorted(name for name, count in Counter(names).items() if count > 1)
    if args.count_nodes:
        render({"count": len(names)}, args.format, [str(len(names))])
        return 0
    data = [{"name": n["full_name"], "duplicate": n["full_name"] in duplicates} for n in nodes
            if args.all or not n["name"].startswith("_")]
    render(sorted(data, key=lambda n: n["name"]), args.format, names)
    if duplicates and args.format == "text":
        print_lines([f"roc: warning: several nodes are named {name}: {Counter(names)[name]} nodes; give each a "
                     "unique name (parameters, services and node info mix them up)" for name in duplicates],
                    sys.stderr)
    return 0
