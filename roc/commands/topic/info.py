"""roc topic info: a topic's type and endpoints; with -v every endpoint's QoS, and roc's checks for
QoS-incompatible pairs and type mismatches (like ros2 topic info)."""

from __future__ import annotations

import argparse
import sys

from roc.cli.options import add_graph_arguments
from roc.commands.graph_query import ask
from roc.render import print_lines, render
from roc.ros.present import endpoint_lines, problem_line, topic_problems


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("topic_name", help="name of the topic, e.g. /chatter")
    parser.add_argument("-v", "--verbose", action="store_true",
                        help="print every endpoint with its QoS, and check publisher/subscriber compatibility")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    info = ask(args, "topic_endpoints", {"topic": args.topic_name})
    problems = topic_problems(info)
    type_line = f"Type: {', '.join(info['types'])}"
    if args.verbose:
        lines = [type_line, "", f"Publisher count: {len(info['publishers'])}", ""]
        for endpoint in info["publishers"]:
            lines += endpoint_lines(endpoint) + [""]
        lines += [f"Subscription count: {len(info['subscribers'])}", ""]
        for endpoint in info["subscribers"]:
            lines += endpoint_lines(endpoint) + [""]
    else:
        lines = [type_line, f"Publisher count: {len(info['publishers'])}",
                 f"Subscription count: {len(info['subscribers'])}"]
    render({**info, "problems": problems}, args.format, lines)
    if problems and args.format == "text" and args.verbose:
        print_lines((f"roc: warning: {problem_line(p)}" for p in problems), sys.stderr)
    return 0
