"""roc param delete: delete parameters of a node (like ros2 param delete)."""

from __future__ import annotations

import argparse

from roc.commands.param.set import report, set_parameters
from roc.commands.param.target import add_node_arguments


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_node_arguments(parser)
    parser.add_argument("parameter_names", nargs="+", metavar="NAME", help="parameters to delete")


def run(args: argparse.Namespace) -> int:
    """Exit 1 when the node refused (a declared, statically typed parameter cannot be deleted)."""
    results = set_parameters(args, [{"name": name, "type": "not set", "value": None}
                                                    for name in args.parameter_names])
    return report(args, results, lambda _: "Deleted parameter successfully", lambda _: "Deleting parameter failed")
