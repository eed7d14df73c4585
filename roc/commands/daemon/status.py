"""roc daemon status: whether this environment's roc daemon runs, and which one it is (pid, version,
discovery environment, socket; when none runs, the environment and the socket it would have); with
--all, every running roc daemon of this user and the discovery environment each serves."""

from __future__ import annotations

import argparse
import time
from typing import Any

from roc.cli.options import add_format_argument
from roc.render import render, table_lines
from roc.ros.client import all_daemon_statuses, daemon_status, socket_path
from roc.ros.protocol import discovery_environment


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--all", action="store_true",
                        help="list every running roc daemon of this user (one runs per discovery environment)")
    add_format_argument(parser)


def environment_text(environment: dict[str, str]) -> str:
    """The discovery variables a daemon was started with, the unset ones left out."""
    return " ".join(f"{name}={value}" for name, value in environment.items() if value) or "none set (ROS defaults)"


def status_lines(status: dict[str, Any]) -> list[str]:
    """ros2's first line, then the daemon's pid, its discovery environment (the variables set) and socket."""
    lines = ["The daemon is running" if status["running"] else "The daemon is not running"]
    if status["running"]:
        lines.append(f"  pid: {status['pid']}")
    lines.append(f"  discovery environment: {environment_text(status['environment'])}")
    lines.append(f"  socket: {status['socket']}")
    return lines


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
    running = daemon_status()
    status = {"running": True, **running} if running else {
        "running": False, "environment": discovery_environment(), "socket": str(socket_path())}
    render(status, args.format, status_lines(status))
    return 0
