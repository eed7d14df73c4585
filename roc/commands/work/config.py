"""``roc work config [VERB]``: the effective options of a verb and where each value comes from."""

from __future__ import annotations

import argparse
import sys

from roc.cli.options import add_format_argument
from roc.config import VERBS
from roc.render import print_json


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("verb", nargs="?", default="build", choices=[v for v in VERBS if v != "create"],
                        help="the verb whose options to show (default: build)")
    parser.add_argument("--profile", metavar="NAME", help="with [profile.NAME] of roc.toml")
    add_format_argument(parser)


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from roc.cli.commands import build_parser
    from roc.config import apply_configuration, load_configuration
    from roc.workspace.root import find_workspace_root

    root = find_workspace_root(Path.cwd()) or Path.cwd()
    config = load_configuration(root, args.verb, args.profile)
    verb_parser = build_parser(["work", args.verb]).leaves[("work", args.verb)]
    applied = apply_configuration(verb_parser, config)
    rows = []
    for action in verb_parser._actions:
        if not action.option_strings or action.dest in ("help", "profile") or action.help == argparse.SUPPRESS:
            continue
        setting = applied.get(action.dest)
        source = "default"
        if setting is not None:
            where = f"{setting.path}:{setting.line}" if setting.line else f"{setting.path}"
            source = f"{setting.source} ({where})"
        rows.append({"option": max(action.option_strings, key=len), "value": verb_parser.get_default(action.dest),
                     "source": source})
    packages = {name: {key: {"value": s.value, "source": s.source} for key, s in settings.items()}
                for name, settings in sorted(config.packages.items())}
    if args.format == "json":
        print_json({"workspace": str(root), "verb": args.verb, "options": rows, "packages": packages})
        return 0
    out = sys.stdout
    out.write(f"# roc work {args.verb} in {root}\n")
    width = max(len(r["option"]) for r in rows)
    for row in rows:
        out.write(f"{row['option']:<{width}}  {row['value']!r:<30}  {row['source']}\n")
    for name, settings in packages.items():
        for key, item in settings.items():
            out.write(f"package {name}: {key} = {item['value']!r}  ({item['source']})\n")
    return 0
