"""roc tui's views in a real terminal (tmux at 120x35 and 80x24), keys typed and the screen read: the
first screen (nodes beside the topics, or above them when narrow; every column in sight), the help (``?``), the palette
(``:``), the logs, a plot and the diagnostics, each within the terminal's lines and columns."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from helpers.build import BIN
from helpers.graph import graph_env, start_nodes, stop_all
from helpers.tui import GRAPH, Terminal, live_graph, require_tmux, start_tui_nodes

from roc.tui.graph_screen import NARROW

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("tui_terminal_views")]
require_tmux()
LOG_LINE = re.compile(r"\d\d:\d\d:\d\d\.\d{3} (DEBUG|INFO|WARN|ERROR|FATAL) ")
BRAILLE = re.compile("[\u2801-\u28ff]")


@pytest.fixture(scope="module")
def graph(tmp_path_factory):
    runtime = tmp_path_factory.mktemp("runtime")
    with live_graph(graph_env(65, runtime, TERM="xterm-256color"), []) as env:
        processes = start_nodes(GRAPH, env)
        processes.append(start_tui_nodes(env))
        try:
            yield env
        finally:
            stop_all(processes)


def fits(screen: str, size: tuple[int, int]) -> bool:
    lines = screen.splitlines()
    return len(lines) <= size[1] and all(len(line) <= size[0] for line in lines)


def run_command(terminal: Terminal, command: str, shown: str) -> str:
    """Open the palette, type ``command``, wait for its entry (its help text ``shown``) and run it."""
    terminal.keys(":")
    terminal.wait(lambda s: "the topics (and nodes) of the graph" in s, "the palette")
    terminal.keys(command, literal=True)
    terminal.wait(lambda s: shown in s and command in s, f"the palette's entry for {command}")
    terminal.keys("Enter")
    return terminal.wait(lambda s: shown not in s, f"{command} run")


def back(terminal: Terminal) -> None:
    """Esc, then the first screen again (a key typed at once after Esc would read as Alt+key)."""
    terminal.keys("Escape")
    terminal.wait(lambda s: "System" in s and "Services" in s, "the first screen again")


@pytest.mark.parametrize("size", [(120, 35), (80, 24)], ids=["120x35", "80x24"])
def test_the_views_typed_and_read_in_a_real_terminal(graph, tmp_path: Path, size: tuple[int, int]) -> None:
    terminal = Terminal(tmp_path, [str(BIN / "roc"), "tui", "--no-workspace"], graph, tmp_path, size=size)
    try:
        screen = terminal.wait(lambda s: "/chatty_logger" in s and "/chatter" in s and "Hz" in s
                               and "problems" in s, "both lists, rates and the problems line")
        assert fits(screen, size), screen
        lines = screen.splitlines()
        assert re.search(r"\b9 nodes\b.*\btopics\b", lines[0]), lines[0]
        side_by_side = any(re.search(r"/chatty_logger\s.*\s/chatter\s", line) for line in lines)
        assert side_by_side == (size[0] >= NARROW), screen  # below 120 columns, the nodes above the topics
        for column in ("node", "cpu", "mem", "topic", "pub", "sub", "rate", "bandwidth", "type"):
            assert re.search(rf"\b{column}\b", screen), (column, screen)
        assert re.search(r"/chatter\s.*\sstd_msgs/(msg/)?String\b", screen), screen

        terminal.keys("?")
        screen = terminal.wait(lambda s: "keys (Esc: back)" in s, "the help")
        assert "filter" in screen and "next problem" in screen and fits(screen, size), screen
        back(terminal)

        run_command(terminal, "logs", "/rosout live, filtered")
        screen = terminal.wait(lambda s: "logs: /rosout" in s and "[chatty_logger]" in s
                               and {"DEBUG", "INFO", "FATAL"} <= set(LOG_LINE.findall(s)), "the logs, every level")
        assert fits(screen, size), screen
        terminal.keys("l", "l", "l")  # the least level shown: debug -> info -> warn -> error
        screen = terminal.wait(lambda s: "level >= error" in s, "the level filter")
        screen = terminal.wait(lambda s: set(LOG_LINE.findall(s)) == {"ERROR", "FATAL"},
                               "only errors and fatal lines (the older lines scrolled away)", timeout=30)
        back(terminal)

        run_command(terminal, "plot /pose pose.position.x", "numeric fields against time")
        screen = terminal.wait(lambda s: "plot, last 10 s" in s and BRAILLE.search(s) is not None
                               and re.search(r"[1-9]\d* samples, 0 lost", s) is not None, "the plot drawn")
        assert "/pose pose.position.x" in screen and "seconds" in screen and fits(screen, size), screen
        back(terminal)

        run_command(terminal, "diagnostics", "/diagnostics by hardware id")

        def worst_first(screen: str) -> bool:
            order = [hardware for line in screen.splitlines() for hardware in ("bms-7", "lidar-2", "motor-1")
                     if hardware in line]
            return order == ["bms-7", "lidar-2", "motor-1"] and re.search(r"ERROR\s+bms-7", screen) is not None
        screen = terminal.wait(worst_first, "the battery's error first, then the stale lidar, then the motor")
        assert re.search(r"STALE\s+lidar-2\s+lidar: scan\s+no data", screen), screen
        assert fits(screen, size), screen
        back(terminal)

        terminal.keys("q")
        assert terminal.exit_code() == 0
    finally:
        terminal.close()
