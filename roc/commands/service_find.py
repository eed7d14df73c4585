"""roc service find: the services of a given type (like ros2 service find)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments
from roc.render import render
from roc.ros.client import query
from roc.ros.present import is_hidden


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("service_type", help="type of the service, e.g. std_srvs/srv/Empty")
    parser.add_argument("-c", "--count-services", action="store_true", help="print only the number of services")
    parser.add_argument("--include-hidden-services", action="store_true", help="include hidden services too")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    services = query("snapshot", use_daemon=not args.no_daemon, spin_time=args.spin_time)["services"]
    names = [s["name"] for s in services if args.service_type in s["types"]
             and (args.include_hidden_services or not is_hidden(s["name"]))]
    if args.count_services:
        render({"count": len(names)}, args.format, [str(len(names))])
    else:
        render(names, args.format, names)
    return 0
