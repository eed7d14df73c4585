"""roc topic type: the type of a topic (like ros2 topic type)."""

from __future__ import annotations

import argparse

from roc.commands.graph_query import add_type_arguments, run_type


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_type_arguments(parser, "topic", "topics", "/chatter")


def run(args: argparse.Namespace) -> int:
    return run_type(args, "topics", "topic", args.topic_name)
