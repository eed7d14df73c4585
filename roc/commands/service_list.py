"""roc service list: the services of the ROS graph (like ros2 service list)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.render import render
from roc.ros.client import query
from roc.ros.present import is_hidden


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-t", "--show-types", action="store_true", help="show each service's type")
    parser.add_argument("-c", "--count-services", action="store_true", help="print only the number of services")
    parser.add_argument("--include-hidden-services", action="store_true", help="include hidden services too")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    services = query("snapshot", use_daemon=not args.no_daemon, spin_time=args.spin_time)["services"]
    services = [s for s in services if args.include_hidden_services or not is_hidden(s["name"])]
    if args.count_services:
        render({"count": len(services)}, args.format, [str(len(services))])
    else:
        render(services, args.format, [f"{s['name']} [{', '.join(s['types'])}]" if args.show_types else s["name"]
                                       for s in services])
    return 0
