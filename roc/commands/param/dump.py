"""roc param dump: a node's parameters as a YAML parameter file (like ros2 param dump)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.commands.graph_query import ask
from roc.render import render, to_yaml


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("node_name", help="fully qualified node name, e.g. /talker")
    add_graph_arguments(parser)


def nested(values: dict[str, dict]) -> dict:
    """Dotted names as nested mappings, keys sorted (ros2's layout)."""
    tree: dict = {}
    for name in sorted(values):
        *parents, leaf = name.split(".")
        branch = tree
        for part in parents:
            branch = branch.setdefault(part, {})
        branch[leaf] = values[name]["value"]
    return tree


def run(args: argparse.Namespace) -> int:
    values = ask(args, "param_dump", {"node": args.node_name})
    document = {args.node_name: {"ros__parameters": nested(values)}}
    render(document, args.format, [to_yaml(document)])
    return 0
