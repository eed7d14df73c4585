"""What the TUI tests share: the app's size, a live graph for it (graph_node.py's nodes with a QoS mismatch,
a subscriber nobody publishes to, a managed node, a node that dies on demand; tui_nodes.py's logger,
diagnostics and pose publisher), the app driven by Textual's pilot, the screen's text, the manual's
pictures, and a small workspace to build from the TUI."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from helpers.build import NODES, REPO
from helpers.graph import read_line, start_nodes, stop_all, stop_daemon
from roc.tui.feed import Feed
from roc.tui.widgets import ListTable

SIZE = (80, 24)


@contextmanager
def live_graph(env: dict[str, str], specs: list) -> Iterator[dict[str, str]]:
    """The nodes of ``specs`` running in ``env``, applied to this process too (the app runs in it);
    then the nodes and roc's daemon stopped and the environment restored."""
    saved = dict(os.environ)
    os.environ.update(env)
    processes = start_nodes(specs, env)
    try:
        yield env
    finally:
        stop_all(processes)
        stop_daemon(env)
        os.environ.clear()
        os.environ.update(saved)


async def until(pilot, condition: Callable[[], bool], timeout: float = 30.0, what: str = "") -> None:
    """Let the app run until ``condition()`` holds (fails after ``timeout`` seconds)."""
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, f"timed out waiting for {what or condition}"
        await pilot.pause(0.1)


def table(app, selector: str) -> ListTable:
    return app.screen.query_one(selector, ListTable)


async def open_row(app, pilot, tab: str, name: str) -> None:
    """Filter the list of ``tab`` down to ``name`` and press Enter on it. Each key waits for what the one
    before did (the pilot's keys do not wait on a loaded machine): typed before the filter had the focus,
    the name's letters were the list's keys (``p`` next problem, ``f`` tf frames, ``c``)."""
    from textual.widgets import Input

    keys = {"nodes": "1", "topics": "2", "services": "3", "actions": "4"}
    await pilot.press(keys[tab])
    rows = table(app, f"#{tab}-table")
    if rows.filter:  # one kept from before
        await until(pilot, lambda: app.focused is rows, what=f"the {tab}")
        await pilot.press("escape")
    await until(pilot, lambda: name in rows.rows_by_key and app.focused is rows, what=f"{name} in the {tab}")
    await pilot.press("slash")
    box = app.screen.query_one("#filter", Input)
    await until(pilot, lambda: app.focused is box, what="the filter's input")
    await pilot.press(*name)
    try:
        await until(pilot, lambda: rows.filter == name and rows.selected_key() == name, what=f"{name} alone")
    except AssertionError as error:
        raise AssertionError(f"{error} (focused: {app.focused}); the screen:\n" + "\n".join(screen_lines(app))) from None
    await pilot.press("enter")  # the filter kept, the list focused
    await until(pilot, lambda: app.focused is rows, what="the filtered list")
    await pilot.press("enter")


async def palette_command(app, pilot, command: str, entry: str | None = None) -> None:
    """Type ``command`` into the command palette (``:``) and run its ``entry`` (the command itself
    unless given) once the palette highlights it."""
    from textual.command import CommandInput, CommandList, CommandPalette

    await pilot.press("colon")
    await until(pilot, lambda: isinstance(app.screen, CommandPalette) and isinstance(app.focused, CommandInput),
                what="the command palette")
    await pilot.press(*command)
    palette, entry = app.screen, entry or command

    def highlighted() -> str:
        found = palette.query_one(CommandList)
        if found.highlighted is None or palette.query_one(CommandInput).value != command:
            return ""
        return str(found.get_option_at_index(found.highlighted).hit.text)
    await until(pilot, lambda: highlighted() == entry, what=f"the palette's entry {entry!r}")
    await pilot.press("enter")
    await until(pilot, lambda: app.screen is not palette, what=f"{entry} run")


CMAKE = "cmake_minimum_required(VERSION 3.10)\nproject({name} NONE)\n{extra}"


MANIFEST = """<?xml version="1.0"?>
<package format="3"><name>{name}</name><version>0.0.0</version><description>d</description>
<maintainer email="a@b.c">a</maintainer><license>Apache-2.0</license>{depends}
<export><build_type>cmake</build_type></export></package>
"""


def make_workspace(root: Path) -> Path:
    """``good`` builds; ``broken`` fails at configure with a message on stderr; ``after`` needs it."""
    for name, extra, depends in (("good", "", ""), ("broken", 'message(FATAL_ERROR "broken on purpose")\n', ""),
                                 ("after", "", "<depend>broken</depend>")):
        package = root / "src" / name
        package.mkdir(parents=True)
        (package / "CMakeLists.txt").write_text(CMAKE.format(name=name, extra=extra))
        (package / "package.xml").write_text(MANIFEST.format(name=name, depends=depends))
    return root


class DataFeed(Feed):
    """The daemon's answers given as data (no daemon, no ROS): ``data`` is the snapshot, ``answers`` the
    answers to other queries by method; no streams."""

    def __init__(self, snapshot: dict, answers: dict | None = None) -> None:
        super().__init__()
        self.data, self.answers = snapshot, answers or {}

    def snapshot(self) -> dict:
        return self.data

    def query(self, method, params=None):
        return self.answers[method]

    def stream(self, method, params, stop):
        return iter(())


def text_of(app, selector: str) -> str:
    return str(app.screen.query_one(selector).render())


TUI_NODES = NODES / "tui_nodes.py"

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


def launch_rows(app) -> dict[str, object]:
    """The launches view's rows by process name."""
    return {row.cells[0]: row for row in table(app, "#processes").rows_by_key.values()}


async def open_launches(app, pilot, processes: set[str]) -> None:
    """The launches view, once it shows ``processes`` running."""
    app.open("launch")
    await until(pilot, lambda: screen_name(app) == "LaunchScreen" and bool(app.screen.query("#processes")),
                what="the launch view")
    await until(pilot, lambda: processes <= set(launch_rows(app))
                and all(launch_rows(app)[p].cells[3] == "running" for p in processes), what="the run")


IMAGES = REPO / "docs" / "images"


def picture(app, name: str) -> None:
    """With ROC_UPDATE_SNAPSHOTS=1, the screen as the manual's picture docs/images/tui-NAME.svg."""
    if os.environ.get("ROC_UPDATE_SNAPSHOTS") == "1":
        (IMAGES / f"tui-{name}.svg").write_text(app.export_screenshot(title="roc tui"))


def require_tmux() -> None:
    """At a module's top: skip its tests without tmux (a test-time tool: ROC_SETUP_TEST_TOOLS=1 bash
    scripts/setup.sh installs it), except in CI, where they fail."""
    import shutil

    import pytest

    if shutil.which("tmux") is None:
        if os.environ.get("CI"):
            raise RuntimeError("tmux is missing in CI: ROC_SETUP_TEST_TOOLS=1 bash scripts/setup.sh installs it")
        pytest.skip("tmux is not installed (ROC_SETUP_TEST_TOOLS=1 bash scripts/setup.sh installs it)",
                    allow_module_level=True)


class Terminal:
    """One tmux session (on a private socket) of ``size`` running ``command``; ``screen()`` is what it
    shows, ``keys`` types."""

    def __init__(self, directory: Path, command: list[str], env: dict[str, str], cwd: Path,
                 size: tuple[int, int] = SIZE) -> None:
        self.socket = directory / "tmux.sock"
        self.status = directory / "status"
        script = directory / "run.sh"
        # never COLUMNS and LINES: pytest-xdist's workers have them (80, 24), and Textual takes them for the size
        exports = "unset COLUMNS LINES\n" + "".join(
            f"export {name}={shlex.quote(value)}\n" for name, value in env.items()
            if re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name) and name not in ("COLUMNS", "LINES"))
        script.write_text(f"{exports}cd {shlex.quote(str(cwd))}\n{shlex.join(command)}\n"
                          f"echo $? > {shlex.quote(str(self.status))}\nsleep 60\n")
        config = directory / "tmux.conf"
        config.write_text("set -g status off\n")  # every line for roc
        self.tmux("-f", str(config), "new-session", "-d", "-x", str(size[0]), "-y", str(size[1]), "-s", "roc",
                  f"bash {shlex.quote(str(script))}")

    def tmux(self, *args: str) -> str:
        return subprocess.run(["tmux", "-S", str(self.socket), *args], check=True, capture_output=True, text=True,
                              timeout=20, env={**os.environ, "TERM": "xterm-256color"}).stdout

    def screen(self, escapes: bool = False) -> str:
        return self.tmux("capture-pane", "-p", *(["-e"] if escapes else []), "-t", "roc")

    def keys(self, *keys: str, literal: bool = False) -> None:
        self.tmux("send-keys", "-t", "roc", *(["-l"] if literal else []), *keys)

    def wait(self, condition: Callable[[str], bool], what: str, timeout: float = 60.0) -> str:
        deadline = time.monotonic() + timeout
        while True:
            screen = self.screen()
            if condition(screen):
                return screen
            assert time.monotonic() < deadline, f"timed out waiting for {what}; the screen:\n{screen}"
            time.sleep(0.2)

    def exit_code(self, timeout: float = 30.0) -> int:
        deadline = time.monotonic() + timeout
        while not self.status.exists() or not self.status.read_text().strip():
            assert time.monotonic() < deadline, f"roc did not exit; the screen:\n{self.screen()}"
            time.sleep(0.2)
        return int(self.status.read_text())

    def close(self) -> None:
        subprocess.run(["tmux", "-S", str(self.socket), "kill-server"], capture_output=True, timeout=20)


# an SGR sequence that sets a foreground or background colour (39 and 49, the defaults, do not count)
COLOUR = re.compile(r"\x1b\[(?:[0-9]+;)*(?:3[0-8]|4[0-8]|9[0-7]|10[0-7])(?:;[0-9]+)*m")
