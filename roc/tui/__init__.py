"""``roc tui``: the terminal user interface for a running ROS 2 system and for builds (Textual).

It asks the roc daemon for everything (roc.tui.feed) and never imports rclpy to start; screens:
the graph (graph_screen), a node (node_screen), a topic (topic_screen), a service or an action
(call_screens), the tf tree (frames_screen), a live build (build_screen, fed by
roc.handlers.board). ``model`` holds what they show as plain data.
"""

import sys

from roc.errors import UsageError


def require_terminal(what: str) -> None:
    """A usage error unless roc runs in a terminal (checked before Textual loads)."""
    if not (sys.stdin.isatty() and sys.stdout.isatty()):
        raise UsageError(f"{what} needs a terminal (stdin and stdout are not both one)")
