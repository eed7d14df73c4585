"""What the TUI tests of tests/tui/ share: one live graph of real rclpy nodes (tui_nodes.py's logger,
diagnostics and pose publisher; tests/graph_node.py's nodes with a QoS mismatch, a subscriber nobody
publishes to, a managed node, a node that dies on demand), the app driven by Textual's pilot, and the
screen's text."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

from graph_helpers import read_line, start_nodes
from test_tui import live_graph, table, text_of, until  # noqa: F401 - shared with the TUI tests' modules

HERE = Path(__file__).resolve().parent
TUI_NODES = HERE / "tui_nodes.py"

GRAPH = [
    [{"name": "talker", "publishers": [{"topic": "chatter", "type": "std_msgs/msg/String", "values": {"data": "hi"},
                                        "rate_hz": 5}]},
     {"name": "listener", "subscribers": [{"topic": "chatter", "type": "std_msgs/msg/String"}]},
     {"name": "picky", "subscribers": [{"topic": "odd", "type": "std_msgs/msg/String", "reliability": "reliable"}]},
     {"name": "sloppy", "publishers": [{"topic": "odd", "type": "std_msgs/msg/String", "reliability": "best_effort"}]},
     {"name": "waiter", "subscribers": [{"topic": "cmd_vel", "type": "geometry_msgs/msg/Twist"}]},
     {"name": "managed", "lifecycle": {}}],
]
MORTAL = [{"name": "mortal", "publishers": [{"topic": "heartbeat", "type": "std_msgs/msg/String",
                                             "values": {"data": "beat"}, "rate_hz": 2}]}]


def start_tui_nodes(env: dict[str, str], pose_hz: float = 50.0) -> subprocess.Popen:
    process = subprocess.Popen([sys.executable, str(TUI_NODES), "--pose-hz", str(pose_hz)], env=env,
                               stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    assert read_line(process, 60) == "ready\n"
    return process


def start_mortal(env: dict[str, str]) -> subprocess.Popen:
    return start_nodes([MORTAL], env)[0]


def screen_lines(app) -> list[str]:
    """The screen as text lines (Textual's SVG export read back)."""
    svg = app.export_screenshot()
    lines: dict[str, list[str]] = {}
    for attributes, line, text in re.findall(r'<text ([^>]*?)y="([0-9.]+)"[^>]*>([^<]*)</text>', svg):
        if "-title" in attributes:  # the window's title, not a line of the screen
            continue
        lines.setdefault(line, []).append(text.replace("&#160;", " ").replace("&amp;", "&").replace("&lt;", "<")
                                          .replace("&gt;", ">").replace("&#x27;", "'").replace("&quot;", '"'))
    return ["".join(parts).rstrip() for _, parts in sorted(lines.items(), key=lambda item: float(item[0]))]


async def until_screen(app, pilot, condition: Callable[[str], bool], what: str, timeout: float = 30.0) -> str:
    """The screen's text once ``condition`` holds for it."""
    deadline = time.monotonic() + timeout
    while True:
        screen = "\n".join(screen_lines(app))
        if condition(screen):
            return screen
        assert time.monotonic() < deadline, f"timed out waiting for {what}; the screen:\n{screen}"
        await pilot.pause(0.2)


def screen_name(app) -> str:
    return type(app.screen).__name__


IMAGES = HERE.parents[1] / "docs" / "images"


def picture(app, name: str) -> None:
    """With ROC_UPDATE_SNAPSHOTS=1, the screen as the manual's picture docs/images/tui-NAME.svg."""
    if os.environ.get("ROC_UPDATE_SNAPSHOTS") == "1":
        (IMAGES / f"tui-{name}.svg").write_text(app.export_screenshot(title="roc tui"))
