"""What the bag verbs share: the bag argument and the notes about a bag read from its files."""

from __future__ import annotations

import argparse
import sys

from roc.bag.reader import STORAGES, Bag
from roc.render import print_text


def add_bag_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("bag_path", metavar="BAG", help="a bag directory, or a .mcap or .db3 file")
    parser.add_argument("-s", "--storage", choices=sorted(STORAGES),
                        help="storage of the bag (default: found from its files)")


def notes(bag: Bag) -> list[str]:
    """What a user should know about how the bag was read."""
    found = []
    if bag.metadata_missing:
        found.append(f"{bag.path} has no metadata.yaml (was its recording interrupted?): read from its files; "
                     f"'roc bag reindex {bag.path}' writes one")
    for path in bag.incomplete_files:
        found.append(f"{path} was not closed: read up to its last whole chunk")
    return found


def print_notes(found: list[str]) -> None:
    for note in found:
        print_text(f"roc: note: {note}\n", sys.stderr)
