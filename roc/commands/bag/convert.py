"""roc bag convert: rewrite bags into new ones (like ros2 bag convert): merge, split by topic or
time, change storage, split sizes or compression, as rosbag2's output-options YAML says."""

from __future__ import annotations

import argparse
from pathlib import Path

from roc.bag.convert import convert, read_output_options
from roc.bag.reader import STORAGES
from roc.errors import UsageError
from roc.render import plural, print_lines


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-i", "--input", required=True, action="append", nargs="+", metavar=("URI", "STORAGE_ID"),
                        help="an input bag (and optionally its storage); may be given more than once")
    parser.add_argument("-o", "--output-options", required=True, metavar="YAML",
                        help="rosbag2's output options: a top-level 'output_bags' list of StorageOptions and "
                             "RecordOptions (uri, storage_id, topics, all_topics, compression_mode, ...)")


def run(args: argparse.Namespace) -> int:
    inputs = []
    for given in args.input:
        if len(given) > 2:
            raise UsageError(f"--input expects 1 or 2 arguments, {len(given)} given")
        if len(given) == 2 and given[1] not in STORAGES:
            raise UsageError(f"--input {given[0]}: unknown storage '{given[1]}' (choose from {', '.join(STORAGES)})")
        inputs.append((given[0], given[1] if len(given) == 2 else None))
    outputs = read_output_options(Path(args.output_options))
    written = convert(inputs, outputs)
    print_lines(f"wrote {output.uri}: {plural(metadata.message_count, 'message')} on "
                f"{plural(len(metadata.topics), 'topic')} ({metadata.storage_identifier}, "
                f"{plural(len(metadata.relative_file_paths), 'file')})"
                for output, metadata in zip(outputs, written))
    return 0
