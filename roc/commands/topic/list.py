"""roc topic list: the topics of the ROS graph (like ros2 topic list)."""

from __future__ import annotations

import argparse

from roc.commands.graph_query import add_list_arguments, render_listing, run_list, snapshot, visible
from roc.render import plural


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_list_arguments(parser, "topic", "topics")
    parser.add_argument("-v", "--verbose", action="store_true", help="list publishers and subscribers with counts")


def run(args: argparse.Namespace) -> int:
    if args.count or not args.verbose:
        return run_list(args, "topics")
    topics = visible(snapshot(args, "topics"), args)
    lines = ["Published topics:"]
    lines += [f" * {t['name']} [{', '.join(t['types'])}] {plural(t['publishers'], 'publisher')}"
              for t in topics if t["publishers"]]
    lines += ["", "Subscribed topics:"]
    lines += [f" * {t['name']} [{', '.join(t['types'])}] {plural(t['subscribers'], 'subscriber')}"
              for t in topics if t["subscribers"]]
    render_listing(args, topics, lines + [""])
    return 0
