"""roc interface show: an interface definition with nested types expanded (like ros2 interface show)."""

from __future__ import annotations

import argparse
import sys

from roc.cli.options import add_format_argument
from roc.errors import UsageError
from roc.render import render
from roc.ros.interfaces import definition_path, show_lines


def add_arguments(parser: argparse.ArgumentParser) -> None:
    comments = parser.add_mutually_exclusive_group()
    comments.add_argument("--all-comments", action="store_true", help="show the comments of nested types too")
    comments.add_argument("--no-comments", action="store_true", help="show no comments or blank lines")
    parser.add_argument("type", help="interface type, e.g. std_msgs/msg/String; '-' reads it from stdin")
    add_format_argument(parser)


def run(args: argparse.Namespace) -> int:
    type_name = args.type
    if type_name == "-":
        type_name = sys.stdin.readline().strip()
        if not type_name:
            raise UsageError("no interface type on stdin")
    lines = show_lines(type_name, comments=not args.no_comments, nested_comments=args.all_comments)
    render({"type": type_name, "file": str(definition_path(type_name)), "text": "\n".join(lines)},
           args.format, lines)
    return 0
