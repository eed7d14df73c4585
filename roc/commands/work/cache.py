"""``roc work cache key|export|import``: build results for CI caches.

``key`` prints a stable key of the workspace's sources, options and toolchain (a CI cache key);
``export PATH`` stores the up-to-date packages; ``import PATH`` restores them in this workspace (which
may be a clone in another directory), after which ``roc work build`` skips every unchanged package.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
from pathlib import Path

from roc.cli.options import add_layout_arguments, add_selection_arguments
from roc.commands.work.build import build_options


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("action", choices=("key", "export", "import"), help="what to do")
    parser.add_argument("path", nargs="?", metavar="PATH", help="the cache directory (export, import)")
    add_layout_arguments(parser)
    add_selection_arguments(parser)


def run(args: argparse.Namespace) -> int:
    from roc.builder.artefact import Places, installed_files, path_dependent_file
    from roc.builder.cache_store import check_isolated, export_cache, import_cache
    from roc.builder.uptodate import fingerprint_packages
    from roc.errors import UsageError
    from roc.workspace.load import load_workspace

    if args.action != "key" and not args.path:
        raise UsageError(f"roc work cache {args.action} needs the cache directory: roc work cache {args.action} PATH")
    workspace = load_workspace(args)
    options = build_options(args, workspace.root)
    if args.action in ("key", "export"):
        states = fingerprint_packages(workspace, options)
    if args.action == "key":
        data = json.dumps({name: state.fingerprint for name, state in sorted(states.items())})
        print(f"roc-{hashlib.sha256(data.encode()).hexdigest()[:40]}")
        return 0
    check_isolated(options.merge_install)
    cache = Path(args.path).absolute()
    places = Places(workspace.root, options.build_base, options.install_base)
    if args.action == "export":
        stored, left_out = export_cache(cache, places, workspace.selected_in_order(),
                                        {name: state.fingerprint for name, state in states.items()})
        print(f"exported {len(stored)} up-to-date package(s) to {cache}")
        for name in stored:
            fixed = path_dependent_file(installed_files(name, places, merged=False), options.install_base / name,
                                        places)
            if fixed:
                print(f"  {name}: import can restore it only into {workspace.root} ({fixed} holds that path)",
                      file=sys.stderr)
        for name, why in sorted(left_out.items()):
            print(f"  not exported: {name}: {why}", file=sys.stderr)
        return 0
    from roc.builder.layout import (
        prepare_build_base,
        prepare_install_base,
        refresh_install_scripts,
    )
    from roc.builder.lock import build_lock

    with build_lock(options.build_base):  # never replace a prefix while a build uses it
        prepare_build_base(options.build_base)
        prepare_install_base(options.install_base, merged=False)
        restored, left_out = import_cache(cache, places, {p.name: p for p in workspace.selected_in_order()})
        refresh_install_scripts(options.install_base, merged=False)
    print(f"imported {len(restored)} package(s) from {cache}")
    for name, why in sorted(left_out.items()):
        print(f"  not restored: {name}: {why} (the next build builds it if needed)", file=sys.stderr)
    return 0
