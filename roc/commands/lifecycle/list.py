"""roc lifecycle list: the transitions a managed node can take now, or with --all all of its
transitions (like ros2 lifecycle list)."""

from __future__ import annotations

import argparse

from roc.commands.lifecycle.managed import add_node_arguments, managed_node, transitions
from roc.commands.node_services import session
from roc.render import render


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_node_arguments(parser)
    parser.add_argument("-a", "--all", action="store_true", help="display all existing transitions")


def run(args: argparse.Namespace) -> int:
    with session(args) as opened:
        found = transitions(opened, managed_node(opened, args), every=args.all)
    lines = []
    for t in found:
        lines += [f"- {t['transition']['label']} [{t['transition']['id']}]", f"\tStart: {t['start']['label']}",
                  f"\tGoal: {t['goal']['label']}"]
    render(found, args.format, lines)
    return 0
