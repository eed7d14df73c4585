"""roc topic echo: print the messages of a topic (like ros2 topic echo), counting lost ones."""

from __future__ import annotations

import argparse
import base64
import sys

from roc.cli.options import (
    add_content_filter_arguments,
    add_graph_arguments,
    add_message_display_arguments,
    add_qos_arguments,
    content_filter_options,
    qos_options,
)
from roc.commands.graph_query import publisher_wait
from roc.errors import RocError, UsageError
from roc.render import json_line, print_text
from roc.ros.client import stream
from roc.ros.messages import echo_text, field_names, get_field, value_to_data
from roc.ros.types import message_class

INFO_FIELDS = ("source_timestamp", "received_timestamp", "publication_sequence_number", "reception_sequence_number")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("topic_name", help="name of the topic to listen to, e.g. /chatter")
    parser.add_argument("message_type", nargs="?", help="type of the messages, e.g. std_msgs/msg/String "
                                                        "(default: the type the graph gives the topic)")
    add_qos_arguments(parser, "sensor_data", "subscribe")
    parser.add_argument("--csv", action="store_true", help="print all fields, recursively, separated by commas")
    parser.add_argument("--field", help="print one field, sub-fields separated by '.', e.g. pose.pose.position")
    add_message_display_arguments(parser)
    parser.add_argument("--no-lost-messages", action="store_true", help="do not report lost messages")
    parser.add_argument("--raw", action="store_true", help="print the serialised (CDR) bytes")
    parser.add_argument("--filter", dest="filter_expr", metavar="EXPR",
                        help="print only messages for which this Python expression of m (the message) is true")
    add_content_filter_arguments(parser)
    parser.add_argument("--once", action="store_true", help="print the first message and exit")
    parser.add_argument("--timeout", type=float, metavar="SECONDS",
                        help="exit with an error when no message has arrived within this time")
    parser.add_argument("--include-message-info", "-i", action="store_true",
                        help="print each message's info (timestamps, sequence number)")
    add_graph_arguments(parser)


def message_filter(expression: str | None):
    """A function of a message for ``--filter EXPR`` (None without it); a bad expression is a usage error."""
    if expression is None:
        return None
    try:
        code = compile(expression, "--filter", "eval")
    except SyntaxError as error:
        raise UsageError(f"--filter: invalid Python expression '{expression}' ({error.msg})") from None

    def accept(message) -> bool:
        try:
            return bool(eval(code, {}, {"m": message}))  # noqa: S307 - the user's own expression
        except Exception as error:  # noqa: BLE001 - any error of the user's expression
            raise RocError(f"--filter: '{expression}' failed on a message: {type(error).__name__}: {error}") from None
    return accept


def run(args: argparse.Namespace) -> int:
    if args.csv and args.flow_style:
        raise UsageError("--flow-style does not apply to --csv output")
    if args.message_type:
        message_class(args.message_type)  # an unknown type is an error before any waiting
    if args.field is not None:
        field_names(args.field)  # as is a field path without a name
    accept = message_filter(args.filter_expr)
    limit = None if args.full_length else args.truncate_length
    options = {"no_arr": args.no_arr, "no_str": args.no_str, "truncate_length": limit}
    params = {"topic": args.topic_name, "type": args.message_type, "qos": qos_options(args),
              # a publisher that has only just started is waited for: up to --timeout when given
              "wait": args.timeout if args.timeout is not None else publisher_wait(args),
              "timeout": args.timeout, "content_filter": content_filter_options(args)}
    lost_total = 0
    lost_unknown = False  # said once: the middleware gives no sequence numbers (Cyclone DDS)
    type_name = args.message_type
    for event in stream("echo", params, use_daemon=not args.no_daemon):
        kind = event["event"]
        if kind == "not_published":
            print_text(f"WARNING: topic [{args.topic_name}] does not appear to be published yet\n")
        elif kind == "subscribed":
            type_name = event["type"]
            note_content_filter(args.topic_name, event)
        elif kind == "timeout":
            raise RocError(f"no message on {args.topic_name} within {args.timeout:g} s (--timeout)")
        elif kind == "messages":
            texts = []  # a backlog is written at once
            for message in event["messages"]:
                if message["lost"] is None and not lost_unknown and not args.no_lost_messages:
                    lost_unknown = True
                    print_text(f"roc: lost messages on {args.topic_name} are unknown: the middleware gives no "
                               "publication sequence numbers\n", sys.stderr)
                if message["lost"] and not args.no_lost_messages:
                    lost_total += message["lost"]
                    print_text(f"A message was lost!!!\n\ttotal count change:{message['lost']}\n\ttotal count: "
                               f"{lost_total}\n", sys.stderr)
                text = _message_text(message, type_name, args, accept, options)
                if text is not None:
                    texts.append(text)
                    if args.once:
                        break
            print_text("".join(texts))
            if args.once and texts:
                return 0
    return 0


def note_content_filter(topic: str, subscribed: dict) -> None:
    """One line on stderr when roc, not the middleware, filters a topic's messages, and why."""
    filtering = subscribed.get("content_filter") or {}
    if filtering.get("by") == "roc":
        print_text(f"roc: note: {filtering['reason']}: roc filters {topic}'s messages as they arrive (all of them "
                   "still reach this subscription)\n", sys.stderr)


def _message_text(event: dict, type_name: str, args: argparse.Namespace, accept, options: dict) -> str | None:
    """One message as asked; None when --filter rejects it."""
    from roc.ros.cdr import decode

    if args.raw:
        value = base64.b64decode(event["data"])
    else:
        message = decode(type_name, event["data"])
        if accept is not None and not accept(message):
            return None
        value = get_field(message, args.field) if args.field else message
    if args.format == "json":
        data = list(value) if args.raw else value_to_data(value, **options)
        return json_line({"topic": args.topic_name, "type": type_name, "message": data, "lost": event["lost"],
                          **({"info": event["info"]} if args.include_message_info else {})})
    text = echo_text(value, csv=args.csv, flow_style=args.flow_style, **options)
    if args.include_message_info and args.csv:  # the info fields first, as ros2 prepends them
        return ",".join(str(event["info"].get(key)) for key in INFO_FIELDS) + "," + text
    if args.include_message_info:
        info = "".join(f"{key}: {value}\n" for key, value in event["info"].items())
        return f"---Got new message, message info:---\n{info}{text}"
    return text
