"""roc interface show: an interface definition with nested types expanded (like ros2 interface show); a
message type that is not installed here is asked of the nodes on the graph that use it (their type
description service) when roc's daemon is running or with ``--no-daemon``, or, with ``--bag``, read from
the definitions a bag holds."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from roc.cli.options import add_discovery_arguments, add_format_argument
from roc.errors import RocError, UsageError
from roc.render import render
from roc.ros.interfaces import definition_path, installed_definition, show_lines


def add_arguments(parser: argparse.ArgumentParser) -> None:
    comments = parser.add_mutually_exclusive_group()
    comments.add_argument("--all-comments", action="store_true", help="show the comments of nested types too")
    comments.add_argument("--no-comments", action="store_true", help="show no comments or blank lines")
    parser.add_argument("type", help="interface type, e.g. std_msgs/msg/String; '-' reads it from stdin")
    parser.add_argument("--bag", type=Path, metavar="BAG",
                        help="show the definition a bag recorded (a bag directory or an .mcap/.db3 file), "
                             "for a message type that is not installed here")
    add_format_argument(parser)
    add_discovery_arguments(parser)


def _remote(args: argparse.Namespace, type_name: str, missing: RocError) -> dict[str, Any]:
    """The type's definition from a node on the graph: asked of roc's daemon when one is running, or of
    a participant of this process with ``--no-daemon`` (no daemon is started for it: a type installed
    nowhere is answered at once); ``missing`` (the local lookup's error) when the type is no message
    type or nothing describes it."""
    from roc.ros.client import query, query_running_daemon

    if type_name.count("/") != 2 or type_name.split("/")[1] != "msg":
        raise missing
    params = {"type": type_name}
    try:
        if args.no_daemon:
            found = query("type_description", params, use_daemon=False, spin_time=args.spin_time)
        else:
            found = query_running_daemon("type_description", params)
    except RocError:
        raise missing from None
    if found is None:
        raise missing
    sources = found["sources"]

    def read(name: str) -> str:
        source = sources.get(name)
        return source["text"] if source and source["encoding"] == "msg" else installed_definition(name)

    lines = show_lines(type_name, comments=not args.no_comments, nested_comments=args.all_comments, read=read)
    return {"type": type_name, "file": None, "node": found["node"], "lines": lines}


def _from_bag(args: argparse.Namespace, type_name: str) -> dict[str, Any]:
    """The type's definition as the bag recorded it (with its topics' full definitions), nested types the
    bag lacks from the ament index."""
    from roc.bag.definitions import message_sections
    from roc.bag.reader import Bag

    with Bag(args.bag) as bag:
        sections: dict[str, str] = {}
        for definition in bag.definitions().values():
            for name, text in message_sections(definition).items():
                sections.setdefault(name, text)
    if type_name not in sections:
        held = ", ".join(sorted(sections)) or "none"
        raise RocError(f"{args.bag}: the bag holds no definition of {type_name} (it holds: {held})")

    def read(name: str) -> str:
        return sections[name] if name in sections else installed_definition(name)

    lines = show_lines(type_name, comments=not args.no_comments, nested_comments=args.all_comments, read=read)
    return {"type": type_name, "file": None, "bag": str(args.bag), "lines": lines}


def run(args: argparse.Namespace) -> int:
    type_name = args.type
    if type_name == "-":
        type_name = sys.stdin.readline().strip()
        if not type_name:
            raise UsageError("no interface type on stdin")
    if args.bag is not None:
        shown = _from_bag(args, type_name)
    else:
        try:
            path = definition_path(type_name)
        except RocError as missing:
            shown = _remote(args, type_name, missing)
        else:
            shown = {"type": type_name, "file": str(path), "lines": show_lines(
                type_name, comments=not args.no_comments, nested_comments=args.all_comments)}
    lines = shown.pop("lines")
    render({**shown, "text": "\n".join(lines)}, args.format, lines)
    return 0
