"""roc topic type: the type of a topic (like ros2 topic type)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.commands.graph_query import run_type


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("topic_name", help="name of the topic, e.g. /chatter")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    return run_type(args, "topics", "topic", args.topic_name)
