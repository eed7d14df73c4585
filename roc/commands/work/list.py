"""``roc work list``: the packages of the workspace, like ``colcon list``."""

from __future__ import annotations

import argparse

from roc.cli.options import add_format_argument, add_selection_arguments
from roc.render import print_json, print_lines


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-t", "--topological-order", action="store_true",
                        help="order by dependencies (layer by layer, alphabetical within a layer)")
    shown = parser.add_mutually_exclusive_group()
    shown.add_argument("-n", "--names-only", action="store_true", help="print only package names")
    shown.add_argument("-p", "--paths-only", action="store_true", help="print only package paths")
    add_format_argument(parser)
    add_selection_arguments(parser)


def run(args: argparse.Namespace) -> int:
    from roc.workspace.load import load_workspace

    workspace = load_workspace(args)
    packages = workspace.selected_in_order()
    if args.format == "json":
        if not args.topological_order:
            packages.sort(key=lambda p: p.name)
        print_json([{"name": p.name, "path": p.path_text, "type": p.type} for p in packages])
        return 0
    if args.names_only:
        lines = [p.name for p in packages]
    elif args.paths_only:
        lines = [p.path_text for p in packages]
    else:
        lines = [f"{p.name}\t{p.path_text}\t({p.type})" for p in packages]
    print_lines(lines if args.topological_order else sorted(lines))
    return 0
