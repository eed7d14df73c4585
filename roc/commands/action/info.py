"""roc action info: the servers and clients of an action (like ros2 action info)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.commands.graph_query import ask
from roc.render import render


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("action_name", help="name of the action, e.g. /fibonacci")
    parser.add_argument("-t", "--show-types", action="store_true", help="show the types of the servers and clients")
    parser.add_argument("-c", "--count", action="store_true", help="print only the numbers of clients and servers")
    add_graph_arguments(parser)


def _entries(endpoints: list[dict], args: argparse.Namespace) -> list[str]:
    if args.count:
        return []
    return [f"    {e['node']} [{', '.join(e['types'])}]" if args.show_types else f"    {e['node']}" for e in endpoints]


def run(args: argparse.Namespace) -> int:
    info = ask(args, "action_info", {"action": args.action_name})
    lines = [f"Action: {args.action_name}", f"Action clients: {len(info['clients'])}", *_entries(info["clients"], args),
             f"Action servers: {len(info['servers'])}", *_entries(info["servers"], args)]
    render(info, args.format, lines)
    return 0
