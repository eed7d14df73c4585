"""``roc work create``: new packages from templates (being written)."""

from __future__ import annotations

import argparse

from roc.errors import RocError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("name", help="package name")


def run(args: argparse.Namespace) -> int:
    raise RocError("roc work create is not implemented yet")
