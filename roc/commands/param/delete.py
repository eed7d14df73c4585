"""roc param delete: delete parameters of a node (like ros2 param delete)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.commands.param.set import report, set_parameters


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("node_name", help="fully qualified node name, e.g. /talker")
    parser.add_argument("parameter_names", nargs="+", metavar="NAME", help="parameters to delete")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    """Exit 1 when the node refused (a declared, statically typed parameter cannot be deleted)."""
    results = set_parameters(args, args.node_name, [{"name": name, "type": "not set", "value": None}
                                                    for name in args.parameter_names])
    return report(args, results, lambda _: "Deleted parameter successfully", lambda _: "Deleting parameter failed")
