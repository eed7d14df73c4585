"""roc bag reindex: rebuild a bag directory's metadata.yaml from its files (like ros2 bag reindex),
recovering the files of a recording that was killed."""

from __future__ import annotations

import argparse

from roc.bag.reindex import reindex
from roc.commands.bag.common import add_bag_argument, print_notes
from roc.render import plural, print_text


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_bag_argument(parser)


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    metadata, repaired = reindex(Path(args.bag_path), args.storage)
    print_notes(repaired)
    print_text(f"wrote {Path(args.bag_path) / 'metadata.yaml'}: {plural(len(metadata.relative_file_paths), 'file')}, "
               f"{plural(metadata.message_count, 'message')} on {plural(len(metadata.topics), 'topic')}\n")
    return 0
