"""roc topic list: the topics of the ROS graph (like ros2 topic list)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.render import render
from roc.ros.client import query
from roc.ros.present import is_hidden, plural


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-t", "--show-types", action="store_true", help="show each topic's type")
    parser.add_argument("-c", "--count-topics", action="store_true", help="print only the number of topics")
    parser.add_argument("-v", "--verbose", action="store_true", help="list publishers and subscribers with counts")
    parser.add_argument("--include-hidden-topics", action="store_true", help="include hidden topics too")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    topics = query("snapshot", use_daemon=not args.no_daemon, spin_time=args.spin_time)["topics"]
    topics = [t for t in topics if args.include_hidden_topics or not is_hidden(t["name"])]
    if args.count_topics:
        lines = [str(len(topics))]
        data = {"count": len(topics)}
    elif args.verbose:
        lines = ["Published topics:"]
        lines += [f" * {t['name']} [{', '.join(t['types'])}] {plural(t['publishers'], 'publisher')}"
                  for t in topics if t["publishers"]]
        lines += ["", "Subscribed topics:"]
        lines += [f" * {t['name']} [{', '.join(t['types'])}] {plural(t['subscribers'], 'subscriber')}"
                  for t in topics if t["subscribers"]]
        lines += [""]
        data = topics
    else:
        lines = [f"{t['name']} [{', '.join(t['types'])}]" if args.show_types else t["name"] for t in topics]
        data = topics
    render(data, args.format, lines)
    return 0
