"""roc topic type: the type of a topic (like ros2 topic type)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.errors import RocError
from roc.render import render
from roc.ros.client import query


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("topic_name", help="name of the topic, e.g. /chatter")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    topics = query("snapshot", use_daemon=not args.no_daemon, spin_time=args.spin_time)["topics"]
    types = next((t["types"] for t in topics if t["name"] == args.topic_name), None)
    if types is None:
        raise RocError(f"Unknown topic '{args.topic_name}'")
    render({"name": args.topic_name, "types": types}, args.format, types)
    return 0
