"""What ``topic hz``, ``topic bw`` and ``topic delay`` share: one ``stats`` stream (roc.ros.dataplane)
over the topics, a window per topic (roc.ros.rates), a report per topic every second."""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable

from roc.cli.options import add_content_filter_arguments, add_graph_arguments, content_filter_options
from roc.commands.graph_query import publisher_wait
from roc.commands.topic.echo import note_content_filter
from roc.errors import UsageError
from roc.render import print_json_line, print_text
from roc.ros.client import stream
from roc.ros.rates import Window, samples

Measure = Callable[[Window], dict | None]
Text = Callable[[dict[str, dict]], list[str]]  # the lines for this second's results, by topic


def add_stats_arguments(parser: argparse.ArgumentParser, window: int, several: bool = False) -> None:
    parser.add_argument("topic_name", nargs="+" if several else None,
                        help="name of the topic" + ("s" if several else "") + " to measure, e.g. /chatter")
    parser.add_argument("-w", "--window", type=int, default=window, metavar="WINDOW",
                        help=f"measure over the last WINDOW messages (default: {window})")
    add_content_filter_arguments(parser)
    add_graph_arguments(parser)


def watch(args: argparse.Namespace, measure: Measure, text: Text, *, stamps: bool = False,
          subscribed: Callable[[str], list[str]] | None = None, accept=None) -> int:
    """Every second until Ctrl+C, print ``text`` of ``measure(window)`` by topic (``--format json``: one
    object per topic and second); messages lost by the subscription are reported on stderr.
    With ``accept`` (``--filter``), messages are deserialised and only accepted ones count."""
    topics = args.topic_name if isinstance(args.topic_name, list) else [args.topic_name]
    if args.window < 2:
        raise UsageError(f"--window: must be at least 2, got {args.window}")
    windows = {topic: Window(args.window) for topic in topics}
    wait = publisher_wait(args)
    content_filter = content_filter_options(args)
    events = _filtered(args, topics[0], accept, wait, content_filter) if accept else stream(
        "stats", {"topics": topics, "wait": wait, "stamps": stamps, "content_filter": content_filter},
        use_daemon=not args.no_daemon)
    reported_lost = dict.fromkeys(topics, 0)
    for event in events:
        kind = event["event"]
        if kind == "not_published":
            print_text(f"WARNING: topic [{event['topic']}] does not appear to be published yet\n")
        elif kind == "subscribed":
            note_content_filter(event["topic"], event)
            if subscribed is not None and args.format != "json":
                print_lines_of(subscribed(event["topic"]))
        elif kind == "batch":
            results = {}
            for topic, columns in event["topics"].items():
                windows[topic].add(samples(columns))
                result = measure(windows[topic])
                if result is None:
                    continue
                results[topic] = result
                if args.format == "json":
                    print_json_line({"topic": topic, **result, "lost": windows[topic].known_lost()})
                if windows[topic].lost > reported_lost[topic]:
                    print_text(f"roc: {windows[topic].lost - reported_lost[topic]} message(s) lost on {topic} "
                               "(publisher sequence numbers)\n", sys.stderr)
                    reported_lost[topic] = windows[topic].lost
            if results and args.format != "json":
                print_lines_of(text(results))
    return 0


def print_lines_of(lines: list[str]) -> None:
    print_text("".join(f"{line}\n" for line in lines))


def _filtered(args: argparse.Namespace, topic: str, accept, wait: float, content_filter: dict | None):
    """``batch`` events from the ``echo`` stream, with only the messages ``accept`` takes. Without their
    sequence numbers: the messages left out are not lost, and the rate is of those that pass (each
    publisher's counted over their source timestamps), not the publishers'."""
    import base64

    from roc.ros.cdr import decode

    columns = ("sequence", "source", "received", "size", "stamp", "publisher")
    batch: dict[str, list] = {column: [] for column in columns}
    type_name, due = "", time.monotonic() + 1.0
    for event in stream("echo", {"topic": topic, "wait": wait, "content_filter": content_filter},
                        use_daemon=not args.no_daemon):
        if event["event"] == "not_published":
            yield {"event": "not_published", "topic": topic}
        elif event["event"] == "subscribed":
            type_name = event["type"]
            yield {**event, "topic": topic}
        elif event["event"] == "messages":
            for message in event["messages"]:
                if accept(decode(type_name, message["data"])):  # "subscribed" came first
                    info = message["info"]
                    for column, value in zip(columns, (
                            None, info.get("source_timestamp"),
                            info.get("received_timestamp"), len(base64.b64decode(message["data"])), None,
                            message.get("publisher"))):
                        batch[column].append(value)
        if time.monotonic() >= due:
            yield {"event": "batch", "topics": {topic: batch}}
            batch, due = {column: [] for column in columns}, due + 1.0
