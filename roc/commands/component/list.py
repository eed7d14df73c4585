"""roc component list: the container nodes of the graph and the components each holds (like ros2
component list)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.commands.component.containers import components, container, containers
from roc.commands.node_services import session
from roc.errors import RocError
from roc.render import render


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("container_node_name", nargs="?", help="only the components of this container node")
    parser.add_argument("--containers-only", action="store_true", help="list the container nodes only")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    lines: list[str] = []
    found: list[dict] = []
    with session(args) as opened:
        names = [container(opened, args.container_node_name)] if args.container_node_name else containers(opened)
        for name in names:
            entry: dict = {"container": name}
            found.append(entry)
            if not args.container_node_name:
                lines.append(name)
            if args.containers_only:
                continue
            try:
                entry["components"] = components(opened, name)
            except RocError as error:
                if args.container_node_name:
                    raise RocError(f"{error} when listing components in {name}") from None
                entry["error"] = str(error)
                lines.append(f"{error} when listing components")
                continue
            indent = "" if args.container_node_name else "  "
            lines += [f"{indent}{c['uid']}  {c['name']}" for c in entry["components"]]
    render(found, args.format, lines)
    return 0
