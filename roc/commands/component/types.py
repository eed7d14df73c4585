"""roc component types: the component types the ament index registers, by package (like ros2 component
types)."""

from __future__ import annotations

import argparse

from roc.ament_index import resources
from roc.cli.options import add_format_argument
from roc.commands.component.containers import component_types, packages_with_components
from roc.errors import RocError
from roc.render import render


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("package_name", nargs="?", help="only the component types of this package")
    add_format_argument(parser)


def run(args: argparse.Namespace) -> int:
    if args.package_name is not None:
        if args.package_name not in resources("packages"):
            raise RocError(f"Unable to find package '{args.package_name}'")
        types = component_types(args.package_name)
        render(types, args.format, ["\n".join(types)])  # ros2 prints an empty line for none
        return 0
    registered = {package: component_types(package) for package in packages_with_components()}
    lines = []
    for package, types in registered.items():
        lines += [package, *(f"  {name}" for name in types)]
    render(registered, args.format, lines)
    return 0
