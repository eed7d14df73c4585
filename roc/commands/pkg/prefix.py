"""roc pkg prefix: the install prefix of a package, or with --share its share directory (like ros2 pkg
prefix)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_format_argument
from roc.render import render


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("package_name", metavar="PKG", help="the package name")
    parser.add_argument("--share", action="store_true", help="print the package's share directory")
    add_format_argument(parser)


def run(args: argparse.Namespace) -> int:
    from roc.ament_index import package_prefix, share_directory

    path = share_directory(args.package_name) if args.share else package_prefix(args.package_name)
    render({"package": args.package_name, "share" if args.share else "prefix": str(path)}, args.format, [str(path)])
    return 0
