"""roc service info: a service's type and the number of its clients and servers (like ros2 service
info); -v adds every client's and server's endpoints (the request and reply topics of each) with QoS."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.commands.graph_query import add_hidden_argument, ask
from roc.errors import RocError
from roc.render import render
from roc.ros.present import endpoint_lines, is_hidden


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("service_name", help="name of the service, e.g. /motor_controller/enable")
    parser.add_argument("-v", "--verbose", action="store_true",
                        help="print the node name, namespace, type, type hash, GID and QoS of every client and "
                             "server endpoint")
    add_hidden_argument(parser, "services")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    if is_hidden(args.service_name) and not args.include_hidden:
        raise RocError(f"Unknown service '{args.service_name}'")
    info = ask(args, "service_info", {"service": args.service_name})
    types = info["types"]
    lines = [f"Type: {types[0] if len(types) == 1 else types}"]
    gap = [""] if args.verbose else []
    lines += [f"Clients count: {info['clients_count']}", *gap]
    if args.verbose:
        for endpoint in info["clients"]:
            lines += endpoint_lines(endpoint) + [""]
    lines += [f"Services count: {info['services_count']}", *gap]
    if args.verbose:
        for endpoint in info["servers"]:
            lines += endpoint_lines(endpoint) + [""]
    render(info, args.format, lines)
    return 0
