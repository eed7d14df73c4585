"""roc action type: the type of an action (like ros2 action type)."""

from __future__ import annotations

import argparse

from roc.commands.graph_query import add_type_arguments, run_type


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_type_arguments(parser, "action", "actions", "/fibonacci", hidden=False)  # ros2 action type has none


def run(args: argparse.Namespace) -> int:
    return run_type(args, "actions", "action", args.action_name)
