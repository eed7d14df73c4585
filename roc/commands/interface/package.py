"""roc interface package: the interfaces of one package (like ros2 interface package; sorted)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_format_argument
from roc.commands.interface.list import add_interface_filters, selected_kinds
from roc.render import render
from roc.ros.interfaces import package_interfaces


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("package_name", help="name of the package")
    add_interface_filters(parser)
    add_format_argument(parser)


def run(args: argparse.Namespace) -> int:
    kinds = package_interfaces(args.package_name).get(args.package_name, {})
    names = [f"{args.package_name}/{kind}/{name}" for kind in selected_kinds(args) for name in kinds.get(kind, [])]
    render(names, args.format, names)
    return 0
