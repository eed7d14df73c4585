"""The diagnostics kept by the app on a graph given as data (no daemon, no ROS): the detail of a status
follows it, its history outlives the view, and a status in ERROR is a problem on the first screen."""

from __future__ import annotations

import asyncio

import pytest
from helpers.tui import DataFeed, screen_name, table, until

from roc.tui.app import RocApp

SNAPSHOT = {"nodes": [{"name": "driver", "namespace": "/", "full_name": "/driver"}],
            "topics": [{"name": "/diagnostics", "types": ["diagnostic_msgs/msg/DiagnosticArray"], "publishers": 1,
                        "subscribers": 0}],
            "services": [], "actions": []}
KEY = "bms-7\tpower: battery"


def message(seconds: int, level: int, text: str) -> dict:
    return {"time": seconds * 10**9, "value": {"status": [
        {"hardware_id": "bms-7", "name": "power: battery", "level": chr(level), "message": text,
         "values": [{"key": "percent", "value": str(50 - seconds)}]}]}}


@pytest.mark.slow  # a few seconds: the detail is drawn again each second
def test_a_status_detail_is_live_its_history_kept_and_an_error_a_problem() -> None:
    """Issue 51: the detail kept showing WARN 14 s after the list moved to ERROR, the history was lost
    when the view was left, and the first screen's problems line did not count a diagnostic ERROR."""
    async def test() -> None:
        app = RocApp(DataFeed(SNAPSHOT))
        async with app.run_test(size=(100, 30)) as pilot:
            await until(pilot, lambda: app.graph_screen is not None and app.graph_screen.snapshot is not None,
                        what="the first snapshot")
            app.diagnostics.take([message(1, 1, "low")])
            app.open("diagnostics")
            await until(pilot, lambda: screen_name(app) == "DiagnosticsScreen" and bool(app.screen.query("#statuses"))
                        and KEY in table(app, "#statuses").rows_by_key, what="the status")
            await pilot.press("enter")
            await until(pilot, lambda: screen_name(app) == "TextViewer", what="the status's detail")
            viewer = app.screen.query_one("#viewer")
            assert "level WARN: low" in viewer.text
            app.diagnostics.take([message(2, 2, "empty")])
            await until(pilot, lambda: "level ERROR: empty" in viewer.text and "percent: 48" in viewer.text,
                        timeout=5, what="the detail following the status")
            await pilot.press("escape")
            await pilot.press("escape")
            await until(pilot, lambda: app.screen is app.graph_screen, what="the first screen")
            await until(pilot, lambda: "ERROR empty" in str(app.graph_screen.query_one("#problems").render()),
                        timeout=5, what="the error on the problems line")
            assert str(app.graph_screen.query_one("#problems").render()).startswith("1 problem")
            app.open("diagnostics")
            await until(pilot, lambda: screen_name(app) == "DiagnosticsScreen" and bool(app.screen.query("#statuses"))
                        and KEY in table(app, "#statuses").rows_by_key, what="the status again")
            history = app.screen.statuses[KEY].details().split("history")[1]
            assert "WARN   low" in history and "ERROR  empty" in history, history
    asyncio.run(test())
