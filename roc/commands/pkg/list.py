"""roc pkg list: the packages of the ament index, every prefix (like ros2 pkg list)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_format_argument
from roc.render import render


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_format_argument(parser)


def run(args: argparse.Namespace) -> int:
    from roc.ament_index import packages

    found = sorted(packages().items())
    render([{"name": name, "prefix": str(prefix)} for name, prefix in found], args.format, [n for n, _ in found])
    return 0
