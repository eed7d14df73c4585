"""roc frame list: every tf frame with its parent, static or dynamic, rate, the age of its latest
transform and the node(s) that sent it, after listening --duration seconds."""

from __future__ import annotations

import argparse
import time

from roc.cli.options import add_discovery_arguments, add_format_argument
from roc.render import render, table_lines


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--duration", type=float, default=2.0, metavar="SECONDS",
                        help="how long to listen to /tf and /tf_static first (default: 2)")
    add_format_argument(parser)
    add_discovery_arguments(parser)


def frame_rows(listener) -> list[dict]:
    """One dict per frame (roots too, with no parent)."""
    now = time.time_ns()
    rows = []
    for frame in listener.buffer.frames():
        link = listener.buffer.links.get(frame)
        if link is None:
            rows.append({"frame": frame, "parent": None, "static": None, "rate": None, "age": None, "publishers": []})
            continue
        age = None if link.static else (now - link.stamps[-1]) * 1e-9
        rows.append({"frame": frame, "parent": link.parent, "static": link.static,
                     "rate": None if link.static else link.rate(), "age": age,
                     "publishers": sorted(listener.publishers.get(frame, ()))})
    return rows


def heard_frames(args: argparse.Namespace) -> list[dict]:
    """The rows of every frame heard in ``args.duration`` seconds (frame list, frame tree)."""
    from roc.frames.listen import Listener

    listener = Listener(use_daemon=not args.no_daemon)
    try:
        listener.listen(seconds=args.duration)
    finally:
        listener.close()
    return frame_rows(listener)


def run(args: argparse.Namespace) -> int:
    rows = heard_frames(args)
    def kind(static: bool | None) -> str:
        return "-" if static is None else "static" if static else "dynamic"

    table = [[r["frame"], r["parent"] or "-", kind(r["static"]), f"{r['rate']:.1f} Hz" if r["rate"] else "-",
              f"{r['age']:.3f} s" if r["age"] is not None else "-", ", ".join(r["publishers"]) or "-"] for r in rows]
    text = (table_lines(table, header=["frame", "parent", "kind", "rate", "age", "publishers"]) if rows
            else ["no tf frames heard"])
    render(rows, args.format, text)
    return 0
