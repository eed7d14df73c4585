"""roc daemon status: whether this environment's roc daemon runs (pid, version, environment, socket)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_format_argument
from roc.render import render
from roc.ros.client import daemon_status


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_format_argument(parser)


def run(args: argparse.Namespace) -> int:
    status = daemon_status()
    render({"running": status is not None, **(status or {})}, args.format,
           ["The daemon is running" if status else "The daemon is not running"])
    return 0
