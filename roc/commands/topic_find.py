"""roc topic find: the topics of a given type (like ros2 topic find)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.commands.graph_common import add_count_argument, add_hidden_argument, run_find


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("topic_type", help="type of the topic, e.g. std_msgs/msg/String")
    add_count_argument(parser, "topics")
    add_hidden_argument(parser, "topics")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    return run_find(args, "topics", args.topic_type)
