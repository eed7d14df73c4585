"""roc topic find: the topics of a given type (like ros2 topic find)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.render import render
from roc.ros.client import query
from roc.ros.present import is_hidden


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("topic_type", help="type of the topic, e.g. std_msgs/msg/String")
    parser.add_argument("-c", "--count-topics", action="store_true", help="print only the number of topics")
    parser.add_argument("--include-hidden-topics", action="store_true", help="include hidden topics too")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    topics = query("snapshot", use_daemon=not args.no_daemon, spin_time=args.spin_time)["topics"]
    names = [t["name"] for t in topics if args.topic_type in t["types"]
             and (args.include_hidden_topics or not is_hidden(t["name"]))]
    if args.count_topics:
        render({"count": len(names)}, args.format, [str(len(names))])
    else:
        render(names, args.format, names)
    return 0
