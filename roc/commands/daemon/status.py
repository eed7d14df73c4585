"""roc daemon status: whether this environment's roc daemon runs (pid, version, environment, socket);
with --all, every running roc daemon of this user and the discovery environment each serves."""

from __future__ import annotations

import argparse
import time
from typing import Any

from roc.cli.options import add_format_argument
from roc.render import render, table_lines
from roc.ros.client import all_daemon_statuses, daemon_status


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--all", action="store_true",
                        help="list every running roc daemon of this user (one runs per discovery environment)")
    add_format_argument(parser)


def environment_text(environment: dict[str, str]) -> str:
    """The discovery variables a daemon was started with, the unset ones left out."""
    return " ".join(f"{name}={value}" for name, value in environment.items() if value) or "(defaults)"


def _uptime(started: float) -> str:
    seconds = max(0, int(time.time() - started))
    return f"{seconds // 3600}h{seconds // 60 % 60:02d}m" if seconds >= 3600 else f"{seconds // 60}m{seconds % 60:02d}s"


def _listing(statuses: list[dict[str, Any]]) -> list[str]:
    if not statuses:
        return ["No daemon is running"]
    rows = [(s.get("pid"), _uptime(s.get("started", time.time())), s.get("socket"),
             environment_text(s.get("environment", {}))) for s in statuses]
    return table_lines(rows, header=("PID", "UPTIME", "SOCKET", "ENVIRONMENT"))


def run(args: argparse.Namespace) -> int:
    if args.all:
        statuses = all_daemon_statuses()
        render(statuses, args.format, _listing(statuses))
        return 0
    status = daemon_status()
    render({"running": status is not None, **(status or {})}, args.format,
           ["The daemon is running" if status else "The daemon is not running"])
    return 0
