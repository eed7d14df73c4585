"""roc frame echo: the transform between two frames, as tf2_echo prints it (the pose of TARGET in
SOURCE, tf2's lookupTransform(SOURCE, TARGET)), then again at --rate until Ctrl+C."""

from __future__ import annotations

import argparse

from roc.cli.options import add_discovery_arguments
from roc.commands.frame.convert import transform_data, transform_lines
from roc.errors import RocError, UsageError
from roc.frames.buffer import TransformUnavailable
from roc.render import json_line, print_text


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("source_frame", help="the frame the transform is expressed in, e.g. map")
    parser.add_argument("target_frame", help="the frame whose pose is printed, e.g. base_link")
    parser.add_argument("--once", action="store_true", help="print one transform and exit")
    parser.add_argument("-r", "--rate", type=float, default=1.0, metavar="HZ", help="prints a second (default: 1)")
    parser.add_argument("--timeout", type=float, metavar="SECONDS",
                        help="exit with an error when the transform is not available within this time (default: wait)")
    parser.add_argument("-p", "--precision", type=int, default=3, metavar="N", help="decimals printed (default: 3)")
    parser.add_argument("--format", choices=("text", "json"), default="text", help="output format (default: text)")
    add_discovery_arguments(parser)


def run(args: argparse.Namespace) -> int:
    from roc.frames.listen import Listener

    if args.rate <= 0:
        raise UsageError(f"--rate: must be above 0 Hz, got {args.rate:g}")
    listener = Listener(use_daemon=not args.no_daemon, early=True)
    last_error: list[str] = []

    def available() -> bool:
        try:
            listener.buffer.lookup(args.source_frame, args.target_frame)
            return True
        except TransformUnavailable as error:
            last_error[:] = [str(error)]
            return False

    try:
        if not listener.listen(available, args.timeout):
            reason = last_error[0] if last_error else "no transforms heard"
            raise RocError(f"no transform from {args.source_frame} to {args.target_frame} within {args.timeout:g} s: "
                           f"{reason}")
        while True:
            transform, stamp = listener.buffer.lookup(args.source_frame, args.target_frame)
            if args.format == "json":
                print_text(json_line({"source": args.source_frame, "target": args.target_frame, "stamp": stamp * 1e-9,
                                      **transform_data(transform)}))
            else:
                lines = [f"At time {stamp * 1e-9:.9f}", *transform_lines(transform, args.precision)]
                print_text("\n".join(lines) + "\n")
            if args.once:
                return 0
            listener.listen(seconds=1.0 / args.rate)  # returns at the first batch or heartbeat after that
    finally:
        listener.close()
