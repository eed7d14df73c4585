"""roc frame tree: the tf tree as text, or as Graphviz DOT, SVG, PNG or PDF (--output FILE, by its
extension; pictures need Graphviz's ``dot`` or graphviz-pure), each edge with its rate and publishers."""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
from pathlib import Path

from roc.cli.options import add_discovery_arguments
from roc.commands.frame.list import heard_frames
from roc.errors import RocError, UsageError
from roc.fsutil import write_text_atomic
from roc.render import print_lines

PICTURES = (".svg", ".png", ".pdf")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--duration", type=float, default=2.0, metavar="SECONDS",
                        help="how long to listen to /tf and /tf_static first (default: 2)")
    parser.add_argument("--output", type=Path, metavar="FILE",
                        help="write the tree to FILE: .dot or .gv (Graphviz DOT), .svg, .png or .pdf")
    add_discovery_arguments(parser)


def _edge_label(row: dict) -> str:
    kind = "static" if row["static"] else f"{row['rate']:.1f} Hz" if row["rate"] else "dynamic"
    return f"{kind}, {', '.join(row['publishers'])}" if row["publishers"] else kind


def tree_lines(rows: list[dict]) -> list[str]:
    """Each tree from its root, children indented under their parent."""
    by_parent: dict[str | None, list[dict]] = {}
    for row in rows:
        by_parent.setdefault(row["parent"], []).append(row)
    lines: list[str] = []

    def walk(frame: str, prefix: str) -> None:
        children = by_parent.get(frame, [])
        for index, row in enumerate(children):
            last = index == len(children) - 1
            lines.append(f"{prefix}{'└── ' if last else '├── '}{row['frame']} [{_edge_label(row)}]")
            walk(row["frame"], prefix + ("    " if last else "│   "))

    for root in by_parent.get(None, []):
        lines.append(root["frame"])
        walk(root["frame"], "")
    return lines


def dot_text(rows: list[dict]) -> str:
    def quoted(text: str) -> str:
        return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'
    lines = ["digraph tf {", "  node [shape=box];"]
    lines += [f"  {quoted(row['frame'])};" for row in rows]
    lines += [f"  {quoted(row['parent'])} -> {quoted(row['frame'])} [label={quoted(_edge_label(row))}];"
              for row in rows if row["parent"]]
    return "\n".join([*lines, "}"]) + "\n"


def graphviz(path: Path) -> str:
    """The program that draws ``path``: Graphviz's ``dot``, else graphviz-pure (its pure-Rust port, a
    pip package, so also looked for next to this Python: a venv's bin is not always on PATH), which
    writes no PDF."""
    here = str(Path(sys.executable).parent)
    for name in ("dot", "graphviz-pure"):
        program = shutil.which(name) or shutil.which(name, path=here)
        if program and not (name == "graphviz-pure" and path.suffix.lower() == ".pdf"):
            return program
    raise RocError(f"--output {path}: Graphviz's 'dot' program is not installed (apt install graphviz; or "
                   "pip install graphviz-pure, which draws .svg and .png); or write a .dot file")


def write_picture(program: str, path: Path, dot: str) -> None:
    """Render DOT with ``program`` into ``path`` (atomically)."""
    temporary = path.with_name(f".{path.name}.tmp")
    done = subprocess.run([program, f"-T{path.suffix[1:].lower()}", "-o", str(temporary)], input=dot, text=True,
                          capture_output=True)
    if done.returncode != 0:
        temporary.unlink(missing_ok=True)
        raise RocError(f"--output {path}: {Path(program).name} failed: {done.stderr.strip()}")
    temporary.replace(path)


def run(args: argparse.Namespace) -> int:
    suffix = args.output.suffix.lower() if args.output else ""
    if args.output and suffix not in (".dot", ".gv", *PICTURES):
        raise UsageError(f"--output {args.output}: use a .dot, .gv, .svg, .png or .pdf file name")
    program = graphviz(args.output) if suffix in PICTURES else None  # before listening: fail at once
    rows = heard_frames(args)
    if args.output is None:
        print_lines(tree_lines(rows) or ["no tf frames heard"])
    elif program:
        write_picture(program, args.output, dot_text(rows))
    else:
        write_text_atomic(args.output, dot_text(rows))
    return 0
