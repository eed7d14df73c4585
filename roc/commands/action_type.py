"""roc action type: the type of an action (like ros2 action type)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.errors import RocError
from roc.render import render
from roc.ros.client import query


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("action_name", help="name of the action, e.g. /fibonacci")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    actions = query("snapshot", use_daemon=not args.no_daemon, spin_time=args.spin_time)["actions"]
    types = next((a["types"] for a in actions if a["name"] == args.action_name), None)
    if types is None:
        raise RocError(f"Unknown action '{args.action_name}'")
    render({"name": args.action_name, "types": types}, args.format, types)
    return 0
