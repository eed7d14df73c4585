"""roc component load: load a component into a container node (like ros2 component load)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.commands.component.containers import add_component_arguments, container, load
from roc.commands.node_services import session
from roc.render import render


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("container_node_name", help="container node to load the component into")
    add_component_arguments(parser)
    parser.add_argument("-q", "--quiet", action="store_true", help="only print the component's unique id and name")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    with session(args) as opened:
        loaded = load(opened, container(opened, args.container_node_name), args)
    text = f"{loaded['uid']}  {loaded['name']}" if args.quiet else \
        f"Loaded component {loaded['uid']} into '{args.container_node_name}' container node as '{loaded['name']}'"
    render({"container": args.container_node_name, **loaded}, args.format, [text])
    return 0
