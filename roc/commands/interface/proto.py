"""roc interface proto: a YAML prototype of a message, service request or action goal, with default
values (like ros2 interface proto)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_format_argument
from roc.render import render
from roc.ros.messages import dict_to_yaml, prototype


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("type", help="interface type, e.g. geometry_msgs/msg/Twist")
    parser.add_argument("--no-quotes", action="store_true", help="print the YAML without the outer quotes")
    add_format_argument(parser)


def run(args: argparse.Namespace) -> int:
    data = prototype(args.type)
    text = dict_to_yaml(data)
    render(data, args.format, [text if args.no_quotes else f'"{text}"'])
    return 0
