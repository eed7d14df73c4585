"""roc service find: the services of a given type (like ros2 service find)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.commands.graph_common import add_count_argument, add_hidden_argument, run_find


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("service_type", help="type of the service, e.g. std_srvs/srv/Empty")
    add_count_argument(parser, "services")
    add_hidden_argument(parser, "services")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    return run_find(args, "services", args.service_type)
