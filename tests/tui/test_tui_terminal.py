"""roc tui in a real terminal: tmux (on a private socket) runs it at 80x24, the test types keys and
reads the screen. tmux is a test-time tool (ROC_SETUP_TEST_TOOLS=1 bash scripts/setup.sh); without it these tests
are skipped, except in CI, where they fail."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.build import BIN, NODES, ros_env, stop_process
from helpers.graph import graph_env, read_line, start_nodes, stop_all, stop_daemon, with_tf2_msgs
from helpers.tui import COLOUR, Terminal, make_workspace, require_tmux

pytestmark = pytest.mark.slow
TF_NODE = NODES / "tf_node.py"

require_tmux()


@pytest.mark.parametrize("no_color", [False, True], ids=["colour", "NO_COLOR"])
def test_graph_in_a_terminal_filter_and_quit(tmp_path: Path, no_color: bool) -> None:
    env = graph_env(38, tmp_path / "runtime", TERM="xterm-256color")
    (tmp_path / "runtime").mkdir()
    if no_color:
        env["NO_COLOR"] = "1"
    nodes = start_nodes([[{"name": "talker", "publishers": [{"topic": "chatter", "type": "std_msgs/msg/String",
                                                              "values": {"data": "hi"}, "rate_hz": 5}]},
                          {"name": "listener", "subscribers": [{"topic": "chatter", "type": "std_msgs/msg/String"}]}]],
                        env)
    terminal = Terminal(tmp_path, [str(BIN / "roc"), "tui", "--no-workspace"], env, tmp_path)
    try:
        screen = terminal.wait(lambda s: "/chatter" in s and "Hz" in s, "/chatter and its rate")
        assert "nodes" in screen.splitlines()[0] and "topics" in screen.splitlines()[0]
        assert len(screen.splitlines()) <= 24 and max(len(line) for line in screen.splitlines()) <= 80
        escapes = terminal.screen(escapes=True)
        assert (not COLOUR.search(escapes)) if no_color else COLOUR.search(escapes)
        if no_color:
            assert re.search(r"\x1b\[(\d+;)*7m", escapes)  # the cursor's row, in reverse video (tmux may write 0;7)
        terminal.keys("/")
        terminal.wait(lambda s: "filter: words" in s, "the filter's input")
        terminal.keys("chat", literal=True)
        terminal.wait(lambda s: "filter 'chat'" in s, "the filter applied")
        terminal.keys("Enter")
        screen = terminal.wait(lambda s: "/rosout" not in s and "filter 'chat'" in s and "filter: words" not in s
                               and "▔" not in s, "the filter kept, its input closed")
        assert "/chatter" in screen
        terminal.keys("q")
        assert terminal.exit_code() == 0
    finally:
        terminal.close()
        stop_all(nodes)
        stop_daemon(env)


def test_work_build_tui_in_a_terminal(tmp_path: Path) -> None:
    root = make_workspace(tmp_path / "ws")
    env = {**ros_env(), "TERM": "xterm-256color"}
    terminal = Terminal(tmp_path, [str(BIN / "roc"), "work", "build", "--tui", "--continue-on-error"], env, root)
    try:
        screen = terminal.wait(lambda s: "finished [" in s, "the end of the build", timeout=120)
        assert re.search(r"broken\s+failed", screen) and re.search(r"good\s+finished", screen), screen
        assert re.search(r"after\s+skipped", screen), screen
        terminal.keys("q")
        assert terminal.exit_code() == 1
        screen = terminal.screen()
        assert "1 package failed: broken" in screen and "skipped because a dependency failed: after" in screen
    finally:
        terminal.close()


def test_the_tf_tree_in_a_terminal(tmp_path: Path) -> None:
    """The tf screen (f): each frame under its parent with its rate and publishing node, live; tf2_msgs
    built by roc from the example workspace (once per test run: helpers.graph.with_tf2_msgs) and sourced,
    the tree published by tests/nodes/tf_node.py."""
    (tmp_path / "runtime").mkdir()
    env = with_tf2_msgs(graph_env(38, tmp_path / "runtime", TERM="xterm-256color"))
    publisher = subprocess.Popen([sys.executable, str(TF_NODE), "publish"], env=env, stdout=subprocess.PIPE,
                                 stderr=subprocess.DEVNULL, text=True)
    terminal = Terminal(tmp_path, [str(BIN / "roc"), "tui", "--no-workspace"], env, tmp_path)
    try:
        assert read_line(publisher, 60) == "ready\n"
        terminal.wait(lambda s: "/tf_static" in s, "the graph")
        terminal.keys("f")
        screen = terminal.wait(lambda s: re.search(r"base_link \[(19|20)\.\d Hz, /tf_publish\]", s) is not None,
                               "the tree with its rates")
        lines = [line.strip() for line in screen.splitlines()]
        assert "map" in lines and "└── odom [static, /tf_publish]" in lines, screen
        assert "└── laser [static, /tf_publish]" in lines, screen
        terminal.keys("Escape")  # then wait: Esc and q at once read as Alt+Q
        terminal.wait(lambda s: "System" in s and "tf frames (from" not in s, "the first screen again")
        terminal.keys("q")
        assert terminal.exit_code() == 0
    finally:
        terminal.close()
        stop_process(publisher)
        stop_daemon(env)
