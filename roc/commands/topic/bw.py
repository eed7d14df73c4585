"""roc topic bw: the bandwidth a topic uses (like ros2 topic bw), from the true serialised sizes."""

from __future__ import annotations

import argparse

from roc.commands.topic.stats import add_stats_arguments, watch
from roc.ros.rates import size_text


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_stats_arguments(parser, window=100)


def _text(results: dict[str, dict]) -> list[str]:
    bandwidth = next(iter(results.values()))
    return [f"{size_text(bandwidth['bytes_per_second'])}/s from {bandwidth['messages']} messages",
            f"\tMessage size mean: {size_text(bandwidth['mean'])} min: {size_text(bandwidth['min'])} "
            f"max: {size_text(bandwidth['max'])}"]


def run(args: argparse.Namespace) -> int:
    return watch(args, lambda window: window.bandwidth(), _text,
                 subscribed=lambda topic: [f"Subscribed to [{topic}]"])
