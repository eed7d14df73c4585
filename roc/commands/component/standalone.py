"""roc component standalone: run a component in a container node of its own (like ros2 component
standalone): rclcpp_components' component_container is started, the component loaded into it, and the
container runs until it exits or Ctrl+C stops it."""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import uuid
from pathlib import Path

from roc.ament_index import resources
from roc.cli.options import add_discovery_arguments
from roc.commands.component.containers import add_component_arguments, load
from roc.commands.node_services import session
from roc.errors import RocError
from roc.render import print_lines

CONTAINER_PACKAGE = "rclcpp_components"
START_TIMEOUT = 15.0  # seconds for the new container to serve load_node


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_component_arguments(parser)
    parser.add_argument("-c", "--container-node-name", default=f"standalone_container_{uuid.uuid4().hex[:12]}",
                        help="name of the standalone container node (default: standalone_container_ and a "
                             "random suffix)")
    add_discovery_arguments(parser)


def container_executable() -> Path:
    """rclcpp_components' component_container, from the ament index."""
    prefix = resources("packages").get(CONTAINER_PACKAGE)
    if prefix is None:
        raise RocError(f"Package '{CONTAINER_PACKAGE}' not found")
    directory = prefix / "lib" / CONTAINER_PACKAGE
    found = sorted(p for p in directory.glob("*component_container*") if p.is_file() and os.access(p, os.X_OK))
    exact = directory / "component_container"
    if not found:
        raise RocError("No component container node found!")
    return exact if exact in found else found[0]


def _stop_with_roc(process: subprocess.Popen) -> None:
    """Ctrl+C, SIGTERM and a closed terminal stop the container (with SIGINT, as its own Ctrl+C);
    roc then waits for it to exit."""
    def forward(*_: object) -> None:
        if process.poll() is None:
            process.send_signal(signal.SIGINT)

    for number in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(number, forward)


def run(args: argparse.Namespace) -> int:
    """The container's exit code."""
    name = args.container_node_name.lstrip("/")
    process = subprocess.Popen([str(container_executable()), "--ros-args", "-r", f"__node:={name}"])
    _stop_with_roc(process)
    try:
        with session(args) as opened:
            load(opened, f"/{name}", args, START_TIMEOUT)
    except RocError as error:
        print_lines([f"{error}, interrupting container node"], sys.stderr)
        process.send_signal(signal.SIGINT)
    except BaseException:
        process.send_signal(signal.SIGINT)
        process.wait()
        raise
    return process.wait()
