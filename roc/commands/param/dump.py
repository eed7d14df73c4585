"""roc param dump: a node's parameters as a YAML parameter file (like ros2 param dump)."""

from __future__ import annotations

import argparse

from roc.commands.param.target import add_node_arguments, ask_node
from roc.render import render, to_yaml


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_node_arguments(parser)


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
    values = ask_node(args, "param_dump")
    document = {args.node_name: {"ros__parameters": nested(values)}}
    render(document, args.format, [to_yaml(document)])
    return 0
