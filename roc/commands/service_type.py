"""roc service type: the type of a service (like ros2 service type)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.errors import RocError
from roc.render import render
from roc.ros.client import query


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("service_name", help="name of the service, e.g. /talker/list_parameters")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    services = query("snapshot", use_daemon=not args.no_daemon, spin_time=args.spin_time)["services"]
    types = next((s["types"] for s in services if s["name"] == args.service_name), None)
    if types is None:
        raise RocError(f"Unknown service '{args.service_name}'")
    render({"name": args.service_name, "types": types}, args.format, types)
    return 0
