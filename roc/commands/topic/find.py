"""roc topic find: the topics of a given type (like ros2 topic find)."""

from __future__ import annotations

import argparse

from roc.commands.graph_query import add_find_arguments, run_find


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_find_arguments(parser, "topic", "topics", "std_msgs/msg/String")


def run(args: argparse.Namespace) -> int:
    return run_find(args, "topics", args.topic_type)
