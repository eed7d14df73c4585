"""roc action list: the actions of the ROS graph (like ros2 action list, which has no hidden-name option)."""

from __future__ import annotations

import argparse

from roc.commands.graph_query import add_list_arguments, run_list


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_list_arguments(parser, "action", "actions", hidden=False)


def run(args: argparse.Namespace) -> int:
    return run_list(args, "actions")
