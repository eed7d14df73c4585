"""roc bag info: what a bag holds (like ros2 bag info), from metadata.yaml or, for a bare file or a
bag without one, from each file's summary and index (an MCAP file's messages are read only when the
file was never closed)."""

from __future__ import annotations

import argparse

from roc.bag import info
from roc.bag.reader import Bag
from roc.cli.options import add_format_argument
from roc.commands.bag.common import add_bag_argument, notes, print_notes
from roc.render import print_json, print_lines, print_text


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_bag_argument(parser)
    parser.add_argument("-t", "--topic-name", action="store_true", help="only print the topic names")
    parser.add_argument("-v", "--verbose", action="store_true",
                        help="count each service's requests and responses (reads its events)")
    add_format_argument(parser)


def run(args: argparse.Namespace) -> int:
    with Bag(args.bag_path, args.storage) as bag:
        found = notes(bag)
        counts = info.service_counts(bag) if args.verbose else None
        if args.format == "json":
            print_json(info.document(bag.metadata, str(bag.path), counts, found))
            return 0
        print_notes(found)
        if args.topic_name and not args.verbose:
            print_lines(topic.name for topic in bag.topics() if not topic.is_service_event)
        else:
            print_text(info.text(bag.metadata, counts))
    return 0
