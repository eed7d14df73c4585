"""roc tui: the terminal user interface for a running ROS 2 system, and for the workspace it runs in
(its packages, and builds started from it)."""

from __future__ import annotations

import argparse
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--no-workspace", action="store_true",
                        help="do not show the packages of the workspace around the current directory")
    parser.add_argument("--bag", metavar="PATH",
                        help="open this bag (a directory or file): its topics, messages, and playback on the graph")


def run(args: argparse.Namespace) -> int:
    from roc.tui import require_terminal
    from roc.tui.feed import Feed

    require_terminal("roc tui")
    feed = Feed()
    feed.prefetch()  # answered while the rest loads
    from roc.commands.work.build import build_runner
    from roc.tui.app import RocApp
    from roc.tui.packages import WorkspaceView
    from roc.tui.problems import find_expectations
    from roc.workspace.root import find_workspace_root

    root = None if args.no_workspace else find_workspace_root(Path.cwd())
    workspace = WorkspaceView(root) if root is not None and (root / "src").is_dir() else None
    app = RocApp(feed=feed, workspace=workspace, new_build=build_runner, checks=find_expectations(Path.cwd()),
                 bag=args.bag)
    try:
        return app.run() or 0
    finally:
        if app.build is not None:
            app.build.finish()
