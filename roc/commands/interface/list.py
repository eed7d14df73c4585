"""roc interface list: every message, service and action type installed (like ros2 interface list)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_format_argument
from roc.render import render
from roc.ros.interfaces import package_interfaces

TITLES = {"msg": "Messages:", "srv": "Services:", "action": "Actions:"}


def add_interface_filters(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-m", "--only-msgs", action="store_true", help="only message types")
    parser.add_argument("-s", "--only-srvs", action="store_true", help="only service types")
    parser.add_argument("-a", "--only-actions", action="store_true", help="only action types")


def selected_kinds(args: argparse.Namespace) -> list[str]:
    chosen = [kind for kind, flag in (("msg", args.only_msgs), ("srv", args.only_srvs),
                                      ("action", args.only_actions)) if flag]
    return chosen or ["msg", "srv", "action"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_interface_filters(parser)
    add_format_argument(parser)


def run(args: argparse.Namespace) -> int:
    interfaces = package_interfaces()
    data = {kind: [f"{pkg}/{kind}/{name}" for pkg, kinds in interfaces.items() for name in kinds[kind]]
            for kind in selected_kinds(args)}
    lines = [line for kind, names in data.items() for line in [TITLES[kind], *(f"    {n}" for n in names)]]
    render(data, args.format, lines)
    return 0
