"""roc daemon stop: stop this environment's roc daemon."""

from __future__ import annotations

import argparse

from roc.cli.options import add_format_argument
from roc.render import render
from roc.ros.client import stop_daemon


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_format_argument(parser)


def run(args: argparse.Namespace) -> int:
    stopped = stop_daemon()
    render({"stopped": stopped}, args.format,
           ["The daemon has been stopped" if stopped else "The daemon is not running"])
    return 0
