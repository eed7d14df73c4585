"""roc bag list: the storage and compression formats roc reads and writes (like ros2 bag list,
which lists rosbag2's installed plugins)."""

from __future__ import annotations

import argparse

from roc.bag.compression import FORMATS, MODES
from roc.bag.writer import DEFAULT_STORAGE, PRESETS
from roc.cli.options import add_format_argument
from roc.render import print_json, print_lines

KINDS = ("storage", "compressor", "decompressor")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("plugin_type", nargs="?", choices=KINDS, help="what to list (default: all)")
    parser.add_argument("-v", "--verbose", action="store_true", help="also the storages' preset profiles")
    add_format_argument(parser)


def run(args: argparse.Namespace) -> int:
    data: dict[str, list[dict]] = {
        "storage": [{"name": name, "default": name == DEFAULT_STORAGE, "presets": presets}
                    for name, presets in PRESETS.items()],
        "compressor": [{"name": name, "modes": [m for m in MODES if m != "none"]} for name in FORMATS],
        "decompressor": [{"name": name, "modes": [m for m in MODES if m != "none"]} for name in FORMATS],
    }
    kinds = [args.plugin_type] if args.plugin_type else list(KINDS)
    if args.format == "json":
        print_json({kind: data[kind] for kind in kinds})
        return 0
    lines = []
    for kind in kinds:
        if not args.plugin_type:
            lines.append(f"{kind}:")
        for entry in data[kind]:
            prefix = "  " if not args.plugin_type else ""
            default = " (default)" if entry.get("default") else ""
            modes = f" (modes: {', '.join(entry['modes'])})" if "modes" in entry else ""
            lines.append(f"{prefix}{entry['name']}{default}{modes}")
            if args.verbose and "presets" in entry:
                lines += [f"{prefix}  preset {name}: {text}" for name, text in entry["presets"].items()]
    print_lines(lines)
    return 0
