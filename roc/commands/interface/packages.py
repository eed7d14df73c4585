"""roc interface packages: the packages that define interfaces (like ros2 interface packages)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_format_argument
from roc.commands.interface.list import add_interface_filters
from roc.render import render
from roc.ros.interfaces import package_interfaces


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_interface_filters(parser)
    add_format_argument(parser)


def run(args: argparse.Namespace) -> int:
    kind = "msg" if args.only_msgs else "srv" if args.only_srvs else "action" if args.only_actions else None
    names = [pkg for pkg, kinds in package_interfaces().items() if kind is None or kinds[kind]]
    render(names, args.format, names)
    return 0
