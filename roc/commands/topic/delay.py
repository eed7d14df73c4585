"""roc topic delay: the delay between a message's header stamp and its reception (like ros2 topic
delay); the stamp is read from the serialised message (its first field must be a std_msgs/Header)."""

from __future__ import annotations

import argparse

from roc.commands.topic.stats import add_stats_arguments, watch


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_stats_arguments(parser, window=10000)


def _text(results: dict[str, dict]) -> list[str]:
    delay = next(iter(results.values()))
    return [f"average delay: {delay['delay']:.3f}",
            f"\tmin: {delay['min']:.3f}s max: {delay['max']:.3f}s std dev: {delay['std_dev']:.5f}s "
            f"window: {delay['window']}"]


def run(args: argparse.Namespace) -> int:
    return watch(args, lambda window: window.delay(), _text, stamps=True)
