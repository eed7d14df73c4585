"""Output helpers shared by listing commands (``--format text|json``)."""

from __future__ import annotations

import argparse
import json
import sys


def add_format_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--format", choices=("text", "json"), default="text",
                        help="output format (default: text); json is stable for scripts")


def print_json(data) -> None:
    json.dump(data, sys.stdout, indent=2, sort_keys=False)
    sys.stdout.write("\n")


def print_lines(lines) -> None:
    sys.stdout.write("".join(f"{line}\n" for line in lines))
