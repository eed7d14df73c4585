"""roc daemon stop: stop this environment's roc daemon, or with --all every roc daemon of this user."""

from __future__ import annotations

import argparse

from roc.cli.options import add_format_argument
from roc.render import plural, render
from roc.ros.client import stop_all_daemons, stop_daemon


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--all", action="store_true",
                        help="stop every roc daemon of this user (one runs per discovery environment)")
    add_format_argument(parser)


def run(args: argparse.Namespace) -> int:
    if args.all:
        count = stop_all_daemons()
        render({"stopped": count > 0, "count": count}, args.format,
               [f"Stopped {plural(count, 'daemon')}" if count else "No daemon is running"])
        return 0
    stopped = stop_daemon()
    render({"stopped": stopped}, args.format,
           ["The daemon has been stopped" if stopped else "The daemon is not running"])
    return 0
