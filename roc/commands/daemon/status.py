"""roc daemon status: whether this environment's roc daemon runs, and which one it is (pid, version,
discovery environment, socket); when none runs, the environment and the socket it would have."""

from __future__ import annotations

import argparse
from typing import Any

from roc.cli.options import add_format_argument
from roc.render import render
from roc.ros.client import daemon_status, socket_path
from roc.ros.protocol import discovery_environment


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_format_argument(parser)


def status_lines(status: dict[str, Any]) -> list[str]:
    """ros2's first line, then the daemon's pid, its discovery environment (the variables set) and socket."""
    lines = ["The daemon is running" if status["running"] else "The daemon is not running"]
    if status["running"]:
        lines.append(f"  pid: {status['pid']}")
    environment = " ".join(f"{name}={value}" for name, value in status["environment"].items() if value)
    lines.append(f"  discovery environment: {environment or 'none set (ROS defaults)'}")
    lines.append(f"  socket: {status['socket']}")
    return lines


def run(args: argparse.Namespace) -> int:
    running = daemon_status()
    status = {"running": True, **running} if running else {
        "running": False, "environment": discovery_environment(), "socket": str(socket_path())}
    render(status, args.format, status_lines(status))
    return 0
