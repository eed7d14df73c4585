"""roc service call: call a service (like ros2 service call); the request is checked before any wait."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments, values_source
from roc.errors import UsageError
from roc.render import print_json_line, print_text
from roc.ros.client import stream
from roc.ros.messages import fill_message, parse_values, value_to_data
from roc.ros.types import service_class


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("service_name", help="name of the service, e.g. /motor_controller/enable")
    parser.add_argument("service_type", help="type of the service, e.g. std_srvs/srv/SetBool")
    source = parser.add_mutually_exclusive_group()
    source.add_argument("values", nargs="?", help="request field values in YAML, e.g. '{data: true}' "
                                                  "(default: the request's default values)")
    source.add_argument("--stdin", action="store_true", help="read the request's values (YAML) from standard input")
    parser.add_argument("-r", "--rate", type=float, metavar="N", help="call N times a second until Ctrl+C "
                                                                    "(default: once)")
    add_graph_arguments(parser)


def run(args: argparse.Namespace) -> int:
    if args.rate is not None and args.rate <= 0:
        raise UsageError(f"--rate: must be above 0 Hz, got {args.rate:g}")
    from roc.ros.cdr import decode, encode

    cls = service_class(args.service_type)
    request = fill_message(cls.Request, parse_values(*values_source(args, "values")))
    params = {"service": args.service_name, "type": args.service_type, "request": encode(request),
              "rate": args.rate}
    for event in stream("call", params, use_daemon=not args.no_daemon):
        kind = event["event"]
        response = decode(cls.Response, event["data"]) if kind == "response" else None
        if args.format == "json":
            if kind == "response":
                print_json_line({"service": args.service_name, "request": value_to_data(request),
                                 "response": value_to_data(response)})
        elif kind == "waiting":
            print_text("waiting for service to become available...\n")
        elif kind == "request":
            print_text(f"requester: making request: {request!r}\n\n")
        elif kind == "response":
            print_text(f"response:\n{response!r}\n\n")
    return 0
