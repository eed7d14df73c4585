"""roc service find: the services of a given type (like ros2 service find)."""

from __future__ import annotations

import argparse

from roc.commands.graph_query import add_find_arguments, run_find


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_find_arguments(parser, "service", "services", "std_srvs/srv/Empty")


def run(args: argparse.Namespace) -> int:
    return run_find(args, "services", args.service_type)
