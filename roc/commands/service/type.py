"""roc service type: the type of a service (like ros2 service type)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.commands.graph_query import run_type


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("service_name", help="name of the service, e.g. /talker/list_parameters")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    return run_type(args, "services", "service", args.service_name)
