"""roc service echo: print a service's introspection events (like ros2 service echo): the requests and
responses its clients and servers publish on ``NAME/_service_event`` when introspection is enabled."""

from __future__ import annotations

import argparse

from roc.cli.options import add_graph_arguments, add_message_display_arguments
from roc.commands.graph_query import publisher_wait, snapshot
from roc.errors import RocError
from roc.render import print_json_line, print_text
from roc.ros.client import stream
from roc.ros.messages import dict_to_yaml, message_to_csv, message_to_dict
from roc.ros.types import service_class

EVENT_TOPIC_SUFFIX = "/_service_event"  # rcl's name for a service's event topic
EVENT_QOS = {"profile": "services_default", "reliability": "reliable", "durability": "volatile"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("service_name", help="name of the service, e.g. /motor_controller/enable")
    parser.add_argument("service_type", nargs="?", help="type of the service, e.g. std_srvs/srv/SetBool "
                                                        "(default: the type the graph gives the service)")
    parser.add_argument("--csv", action="store_true", help="print all fields, recursively, separated by commas")
    add_message_display_arguments(parser)
    add_graph_arguments(parser)


def _service_type(args: argparse.Namespace) -> str:
    if args.service_type:
        service_class(args.service_type)  # an unknown type is an error before any waiting
        return args.service_type
    types = next((s["types"] for s in snapshot(args, "services") if s["name"] == args.service_name), None)
    if not types:
        raise RocError(f"The service name '{args.service_name}' is invalid")
    return types[0]


def event_names() -> dict[int, str]:
    """service_msgs/msg/ServiceEventInfo's event types by number (REQUEST_SENT, ...)."""
    from service_msgs.msg import ServiceEventInfo

    return {getattr(ServiceEventInfo, name): name for name in dir(ServiceEventInfo)
            if name.isupper() and isinstance(getattr(ServiceEventInfo, name), int)}


def run(args: argparse.Namespace) -> int:
    if args.csv and args.flow_style:
        raise RocError("--flow-style does not apply to --csv output")
    from roc.ros.cdr import decode

    event_type = f"{_service_type(args)}_Event"
    topic = args.service_name + EVENT_TOPIC_SUFFIX
    options = {"no_arr": args.no_arr, "no_str": args.no_str,
               "truncate_length": None if args.full_length else args.truncate_length}
    names = event_names()
    params = {"topic": topic, "type": event_type, "qos": EVENT_QOS, "wait": publisher_wait(args)}
    for event in stream("echo", params, use_daemon=not args.no_daemon):
        if event["event"] == "not_published" and args.format == "text":
            print_text(f"No publishers on topic '{topic}'; is service introspection on the client or server "
                       "enabled?\n")
        if event["event"] != "messages":
            continue
        for message in event["messages"]:
            value = decode(event_type, message["data"])
            if args.csv and args.format != "json":
                print_text(message_to_csv(value, **options) + "\n")
                continue
            data = message_to_dict(value, **options)
            data["info"]["event_type"] = names.get(data["info"]["event_type"], data["info"]["event_type"])
            if args.format == "json":
                print_json_line({"service": args.service_name, "event": data})
            else:
                print_text(dict_to_yaml(data, flow_style=args.flow_style) + "---\n")
    return 0
