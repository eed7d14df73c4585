"""roc frame monitor: per dynamic frame, the rate, the delay (reception minus stamp) and the node(s)
that sent it, every second (like tf2_monitor); with SOURCE TARGET, only the frames between them."""

from __future__ import annotations

import argparse
import statistics
import time

from roc.cli.options import add_discovery_arguments, add_format_argument
from roc.errors import UsageError
from roc.frames.buffer import TransformUnavailable
from roc.render import json_line, print_text, table_lines


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("frames", nargs="*", metavar="FRAME", help="SOURCE TARGET: only the frames between them")
    parser.add_argument("--duration", type=float, metavar="SECONDS", help="stop after this long (default: Ctrl+C)")
    add_format_argument(parser)
    add_discovery_arguments(parser)


def _between(buffer, source: str, target: str) -> set[str] | None:
    """The child frames of the links between two frames, or None while they are not connected."""
    try:
        buffer.lookup(source, target)
    except TransformUnavailable:
        return None
    up_source, up_target = buffer.chain(source.lstrip("/")), buffer.chain(target.lstrip("/"))
    common = next(frame for frame in up_source if frame in up_target)
    return {*up_source[:up_source.index(common)], *up_target[:up_target.index(common)]}


def report(listener, only: set[str] | None) -> list[dict]:
    rows = []
    for frame, link in sorted(listener.buffer.links.items()):
        if link.static or (only is not None and frame not in only):
            continue
        delays = listener.delays.get(frame, [])[-100:]
        rows.append({"frame": frame, "parent": link.parent, "rate": link.rate(),
                     "delay_average": statistics.fmean(delays) if delays else None,
                     "delay_max": max(delays) if delays else None,
                     "publishers": sorted(listener.publishers.get(frame, ()))})
    return rows


def run(args: argparse.Namespace) -> int:
    from roc.frames.listen import Listener

    if len(args.frames) not in (0, 2):
        raise UsageError("give no frame, or SOURCE TARGET")
    listener = Listener(use_daemon=not args.no_daemon)
    deadline = time.monotonic() + args.duration if args.duration is not None else None
    try:
        while deadline is None or time.monotonic() < deadline:
            listener.listen(seconds=1.0)
            only = _between(listener.buffer, *args.frames) if args.frames else None
            rows = report(listener, only)
            if args.format == "json":
                print_text("".join(json_line(row) for row in rows))
                continue
            def seconds(value):
                return f"{value:.4f} s" if value is not None else "-"
            table = [[r["frame"], r["parent"], f"{r['rate']:.1f} Hz" if r["rate"] else "-", seconds(r["delay_average"]),
                      seconds(r["delay_max"]), ", ".join(r["publishers"]) or "-"] for r in rows]
            lines = table_lines(table, header=["frame", "parent", "rate", "delay avg", "delay max", "publishers"])
            if args.frames and only is None:
                lines = [f"waiting for {args.frames[0]} and {args.frames[1]} to be connected"]
            print_text("\n".join([*lines, ""]) + "\n")
    finally:
        listener.close()
    return 0
