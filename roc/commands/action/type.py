"""roc action type: the type of an action (like ros2 action type)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.commands.graph_query import run_type


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("action_name", help="name of the action, e.g. /fibonacci")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    return run_type(args, "actions", "action", args.action_name)
