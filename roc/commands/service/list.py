"""roc service list: the services of the ROS graph (like ros2 service list)."""

from __future__ import annotations

import argparse

from roc.commands.graph_query import add_list_arguments, run_list


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_list_arguments(parser, "service", "services")


def run(args: argparse.Namespace) -> int:
    return run_list(args, "services")
