"""roc topic pub: publish messages on a topic (like ros2 topic pub). The values are checked, field by
field, before anything waits or is published."""

from __future__ import annotations

import argparse
import re
import sys
import time
from pathlib import Path
from typing import Any

from roc.cli.options import add_graph_arguments, add_qos_arguments, qos_options
from roc.errors import UsageError
from roc.render import print_json_line, print_text
from roc.ros.client import stream
from roc.ros.messages import fill_message, parse_values, value_to_data
from roc.ros.protocol import task_node_name
from roc.ros.types import message_class

WAITING_LINES = 5  # ros2's waiting line, once a second, before roc says once how to stop waiting


def waiting_text(count: int, wanted: int) -> str:
    """What the ``count``-th waiting event (one a second, from 1) prints: ros2's line, then instead of
    repeating it for ever, once how to stop waiting."""
    if count < WAITING_LINES:
        return f"Waiting for at least {wanted} matching subscription(s)...\n"
    if count == WAITING_LINES:
        return (f"Still waiting for {wanted} matching subscription(s) after {count - 1} s, until they appear: "
                "Ctrl+C stops, '-w 0' publishes without waiting, '--max-wait-time-secs SECONDS' gives up\n")
    return ""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("topic_name", help="name of the topic to publish to, e.g. /chatter")
    parser.add_argument("message_type", help="type of the messages, e.g. std_msgs/msg/String")
    parser.add_argument("values", nargs="?", help="field values in YAML, e.g. 'data: Hello World' "
                                                  "(default: the type's default values)")
    source = parser.add_mutually_exclusive_group()
    source.add_argument("--stdin", action="store_true", help="read the values from standard input")
    source.add_argument("--values-file", type=Path, metavar="FILE", help="roc: read the values from a YAML file")
    parser.add_argument("-r", "--rate", type=float, default=1.0, metavar="N", help="publishing rate in Hz (default: 1)")
    parser.add_argument("-p", "--print", type=int, default=1, metavar="N", dest="print_every",
                        help="print only every N-th published message (default: 1)")
    times = parser.add_mutually_exclusive_group()
    times.add_argument("-1", "--once", action="store_true", help="publish one message and exit")
    times.add_argument("-t", "--times", type=int, default=0, metavar="TIMES",
                       help="publish this number of times and then exit")
    parser.add_argument("-w", "--wait-matching-subscriptions", type=int, metavar="N",
                        help="wait for N matching subscriptions first (default: 1 with --once/--times, else 0)")
    parser.add_argument("--max-wait-time-secs", type=float, metavar="SECONDS",
                        help="fail when the subscriptions have not matched within this time (default: wait)")
    parser.add_argument("--keep-alive", type=float, default=0.1, metavar="SECONDS",
                        help="keep the publisher this long after the last message (default: 0.1)")
    parser.add_argument("-n", "--node-name", help="publish from a node of this name (default: roc_topic_pub_<pid>)")
    add_qos_arguments(parser, "default", "publish")
    add_graph_arguments(parser)


def _values_text(args: argparse.Namespace) -> tuple[str | None, str]:
    if args.stdin:
        return sys.stdin.read(), "standard input"
    if args.values_file is not None:
        try:
            return args.values_file.read_text(), str(args.values_file)
        except OSError as error:
            raise UsageError(f"--values-file: cannot read {args.values_file}: {error.strerror}") from None
    return args.values, "values"


def run(args: argparse.Namespace) -> int:
    if args.rate <= 0:
        raise UsageError(f"--rate: must be above 0 Hz, got {args.rate:g}")
    if args.node_name is not None and not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", args.node_name):
        raise UsageError(f"--node-name: {args.node_name!r} is not a node name (letters, digits and '_', "
                         "not starting with a digit)")
    if args.print_every < 0 or args.times < 0:
        raise UsageError("--print and --times take a number of 0 or more")
    from roc.ros.cdr import encode

    text, source = _values_text(args)
    stamps: list = []
    message = fill_message(message_class(args.message_type), parse_values(text, source), stamps=stamps)
    times = 1 if args.once else args.times
    wait = args.wait_matching_subscriptions
    params = {"topic": args.topic_name, "type": args.message_type, "data": encode(message),
              "qos": qos_options(args), "rate": args.rate, "times": times,
              "wait": wait if wait is not None else 1 if times else 0,
              "max_wait": args.max_wait_time_secs, "keep_alive": args.keep_alive,
              "node": args.node_name or task_node_name("topic_pub")}
    local: dict[str, Any] = {}
    if stamps:  # header: auto / stamp: now, set anew before each message: published from this process
        local["prepare"] = lambda: _restamp(message, stamps)
    waited = 0
    for event in stream("publish", params, use_daemon=not args.no_daemon and not local, **local):
        kind = event["event"]
        if args.format == "json":
            print_json_line({"topic": args.topic_name, **event,
                             **({"message": value_to_data(message)} if kind == "published" else {})})
        elif kind == "waiting":
            waited += 1
            print_text(waiting_text(waited, event["subscriptions"]))
        elif kind == "started":
            print_text("publisher: beginning loop\n")
        elif kind == "published" and args.print_every and event["count"] % args.print_every == 0:
            print_text(f"publishing #{event['count']}: {message!r}\n\n")
    return 0


def _restamp(message, stamps: list) -> bytes:
    from builtin_interfaces.msg import Time

    from roc.ros.cdr import serialize

    now = time.time_ns()
    for setter in stamps:
        setter(Time(sec=now // 1_000_000_000, nanosec=now % 1_000_000_000))
    return serialize(message)
