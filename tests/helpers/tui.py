"""What the TUI tests share: the app's size, a live graph for it, waiting in a pilot for a condition,
the tables of a screen, and a small workspace to build from the TUI."""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from helpers.graph import start_nodes, stop_all, stop_daemon
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
    """Filter the list of ``tab`` down to ``name`` and press Enter on it."""
    keys = {"nodes": "1", "topics": "2", "services": "3", "actions": "4"}
    await pilot.press(keys[tab])
    await until(pilot, lambda: name in table(app, f"#{tab}-table").rows_by_key, what=name)
    await pilot.press("slash", *name, "enter")
    rows = table(app, f"#{tab}-table")
    await until(pilot, lambda: rows.selected_key() == name, what=f"{name} alone")
    await pilot.press("enter")


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
