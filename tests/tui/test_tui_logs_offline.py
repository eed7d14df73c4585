"""The logs view on /rosout entries given as data (no daemon, no ROS): the backlog in time order, kept
since the TUI started, and how far back it goes."""

from __future__ import annotations

import asyncio
import time

import pytest
from helpers.tui import DataFeed, screen_name, text_of, until

from roc.tui.app import RocApp

SNAPSHOT = {"nodes": [], "topics": [], "services": [], "actions": []}


def log(stamp: float, name: str, text: str) -> dict:
    return {"value": {"stamp": {"sec": int(stamp), "nanosec": int(stamp % 1 * 1e9)}, "level": 20, "name": name,
                      "msg": text}, "time": int(stamp * 1e9)}


@pytest.mark.slow  # a second or two (the app's start)
def test_the_logs_backlog_is_in_time_order_and_says_how_far_back_it_goes() -> None:
    """Issue 51: the backlog covered about 10 s and was not in time order. Each node's /rosout publisher
    gives a new subscriber its last 10 s (rcl's lifespan), one publisher after the other; the TUI keeps
    /rosout from its start, in the order of the stamps, and says from when."""
    async def test() -> None:
        app = RocApp(DataFeed(SNAPSHOT))
        assert app.logs.params["qos"] == {"history": "keep_all"}  # every node's history, not the last 1000
        now = time.time()
        async with app.run_test(size=(100, 30)) as pilot:
            app.logs.take([log(now - 60, "talker", "t1"), log(now - 50, "talker", "t2")])  # before the view opened
            app.logs.take([log(now - 55, "listener", "l1"), log(now - 45, "listener", "l2")])  # another's history
            app.open("logs")
            await until(pilot, lambda: screen_name(app) == "LogsScreen" and bool(app.screen.query("#title")),
                        what="the logs")
            screen = app.screen
            assert [line.split()[-1] for line in screen.visible_lines()] == ["t1", "l1", "t2", "l2"]
            first = time.strftime("%H:%M:%S", time.localtime(now - 60))
            await until(pilot, lambda: f"from {first}" in text_of(app, "#title"), what="how far back")
            assert "10 s" in text_of(app, "#title")
            app.logs.take([log(now - 52, "third", "x1")])  # older than the last line written: drawn again
            await until(pilot, lambda: [line.split()[-1] for line in screen.visible_lines()]
                        == ["t1", "l1", "x1", "t2", "l2"], what="the late entry in its place")
            lines = lambda: [str(line.text).split()[-1] for line in screen.query_one("#log").lines]  # noqa: E731
            await until(pilot, lambda: lines() == ["t1", "l1", "x1", "t2", "l2"], timeout=5, what="drawn in order")
    asyncio.run(test())
