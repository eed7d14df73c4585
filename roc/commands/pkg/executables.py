"""roc pkg executables: the executables of one package or of every package, ``PKG NAME`` per line or
full paths (like ros2 pkg executables)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_format_argument
from roc.render import render


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("package_name", nargs="?", metavar="PKG", help="the package (default: every package)")
    parser.add_argument("--full-path", action="store_true", help="print the full path of each executable")
    add_format_argument(parser)


def run(args: argparse.Namespace) -> int:
    from roc.ament_index import executables, packages

    names = [args.package_name] if args.package_name else sorted(packages())
    found = [{"package": name, "executable": path.name, "path": str(path)}
             for name in names for path in executables(name)]
    text = [entry["path"] if args.full_path else f"{entry['package']} {entry['executable']}" for entry in found]
    render(found, args.format, text)
    return 0
