"""roc action list: the actions of the ROS graph (like ros2 action list)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.render import render
from roc.ros.client import query


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-t", "--show-types", action="store_true", help="show each action's type")
    parser.add_argument("-c", "--count-actions", action="store_true", help="print only the number of actions")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    actions = query("snapshot", use_daemon=not args.no_daemon, spin_time=args.spin_time)["actions"]
    if args.count_actions:
        render({"count": len(actions)}, args.format, [str(len(actions))])
    else:
        render(actions, args.format, [f"{a['name']} [{', '.join(a['types'])}]" if args.show_types else a["name"]
                                      for a in actions])
    return 0
