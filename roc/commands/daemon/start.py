"""roc daemon start: start this environment's roc daemon (graph verbs start it on demand too)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_format_argument
from roc.render import render
from roc.ros.client import daemon_status, start_daemon


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_format_argument(parser)


def run(args: argparse.Namespace) -> int:
    running = daemon_status() is not None
    if not running:
        start_daemon().close()
    status = daemon_status()
    render(status, args.format, ["The daemon is already running" if running else "The daemon has been started"])
    return 0
