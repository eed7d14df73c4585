"""roc param list: the parameter names of one node or of every node (like ros2 param list)."""

from __future__ import annotations

import argparse
import re
import sys

from roc.cli.options import add_graph_arguments
from roc.commands.graph_query import ask
from roc.commands.param.target import absolute_node_name
from roc.errors import RocError, UsageError
from roc.render import print_text, render


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("node_name", nargs="?", type=absolute_node_name,
                        help="node name (a relative one is taken from the root); every node when left out")
    parser.add_argument("--filter", dest="filter_regex", metavar="REGEX",
                        help="only parameters whose names match this regular expression (from their start)")
    parser.add_argument("--param-prefixes", nargs="+", default=[], metavar="PREFIX",
                        help="only parameters with one of these prefixes")
    parser.add_argument("--param-type", action="store_true", help="print each parameter's type")
    parser.add_argument("--include-hidden-nodes", action="store_true", help="consider hidden nodes as well")
    add_graph_arguments(parser)


def _matching(pattern: str | None):
    if pattern is None:
        return lambda _name: True
    try:
        return re.compile(pattern).match
    except re.error as error:
        raise UsageError(f"--filter: invalid pattern '{pattern}': {error}") from None


def run(args: argparse.Namespace) -> int:
    if args.node_name and args.node_name.rsplit("/", 1)[-1].startswith("_") and not args.include_hidden_nodes:
        raise RocError("Node not found")  # ros2's rule: a node whose own name starts with '_' is hidden
    matches = _matching(args.filter_regex)
    nodes = ask(args, "param_list", {"node": args.node_name, "prefixes": args.param_prefixes,
                                     "types": args.param_type, "hidden": args.include_hidden_nodes})
    left_out = [entry for entry in nodes if entry.get("left_out")]
    if left_out:  # nodes the request could crash (a mixed domain): said once, not asked
        print_text(f"roc: warning: left out {', '.join(e['node'] for e in left_out)}: "
                   f"{left_out[0]['left_out'].split(': not asked: ', 1)[-1]}\n", sys.stderr)
    for entry in nodes:
        entry["parameters"] = [p for p in entry["parameters"] if matches(p["name"])]
    if not args.node_name:  # as ros2, a node none of whose parameters is listed is left out
        nodes = [entry for entry in nodes if entry["parameters"]]
    lines = []
    for entry in nodes:
        if not args.node_name:
            lines.append(f"{entry['node']}:")
        lines += [f"  {p['name']} (type: {p['type']})" if args.param_type else f"  {p['name']}"
                  for p in entry["parameters"]]
    render(nodes, args.format, lines)
    return 0
