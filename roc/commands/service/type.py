"""roc service type: the type of a service (like ros2 service type)."""

from __future__ import annotations

import argparse

from roc.commands.graph_query import add_type_arguments, run_type


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_type_arguments(parser, "service", "services", "/talker/list_parameters")


def run(args: argparse.Namespace) -> int:
    return run_type(args, "services", "service", args.service_name)
