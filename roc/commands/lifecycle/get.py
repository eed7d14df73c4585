"""roc lifecycle get: the lifecycle state of one managed node or of every one (like ros2 lifecycle get)."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from roc.commands.lifecycle.managed import add_node_arguments, managed_node, managed_nodes, state
from roc.commands.node_services import session
from roc.errors import RocError
from roc.render import print_lines, render


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_node_arguments(parser, optional=True)


def run(args: argparse.Namespace) -> int:
    states: list[dict[str, Any]] = []
    failed: list[str] = []
    with session(args) as opened:
        nodes = [managed_node(opened, args)] if args.node_name else managed_nodes(opened, args.include_hidden_nodes)
        for node in nodes:
            try:
                states.append({"node": node, "state": state(opened, node)})
            except RocError as error:
                if args.node_name:
                    raise
                failed.append(f"Exception while calling service of node '{node}': {error}")
    prefix = "" if args.node_name else "{node}: "
    render(states, args.format, [prefix.format(node=s["node"]) + f"{s['state']['label']} [{s['state']['id']}]"
                                 for s in states])
    print_lines(failed, sys.stderr)
    return 0
