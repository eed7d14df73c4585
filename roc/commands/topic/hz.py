"""roc topic hz: the publishing rate of topics (like ros2 topic hz), from the publishers' sequence
numbers and source timestamps, so a slow or lossy subscriber does not change the answer."""

from __future__ import annotations

import argparse

from roc.commands.topic.echo import message_filter
from roc.commands.topic.stats import add_stats_arguments, watch
from roc.errors import UsageError
from roc.render import table_lines


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_stats_arguments(parser, window=10000, several=True)
    parser.add_argument("--filter", dest="filter_expr", metavar="EXPR",
                        help="the rate of the messages for which this Python expression of m (the message) is "
                             "true (one topic; messages are deserialised, and losses are not counted)")
    parser.add_argument("--wall-time", action="store_true",
                        help="measure with the times messages were received, not the times they were published")


def _text(rates: dict[str, dict], several: bool) -> list[str]:
    """ros2's two lines for one topic; a table for several."""
    if not several:
        rate = next(iter(rates.values()))
        return [f"average rate: {rate['rate']:.3f}",
                f"\tmin: {rate['min']:.3f}s max: {rate['max']:.3f}s std dev: {rate['std_dev']:.5f}s "
                f"window: {rate['window']}"]
    return table_lines([[topic, f"{r['rate']:.3f}", f"{r['min']:.3f}s", f"{r['max']:.3f}s", f"{r['std_dev']:.5f}s",
                         r["window"]] for topic, r in rates.items()],
                       header=["topic", "rate", "min_delta", "max_delta", "std_dev", "window"])


def run(args: argparse.Namespace) -> int:
    accept = message_filter(args.filter_expr)
    if accept is not None and len(args.topic_name) > 1:
        raise UsageError("--filter: measures one topic at a time")
    several = len(args.topic_name) > 1
    return watch(args, lambda window: window.rate(args.wall_time),
                 lambda rates: _text(rates, several), accept=accept)
