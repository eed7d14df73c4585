"""roc tui's lists driven by Textual's pilot on data (no daemon, no ROS): the keys that move in a list, and
a key that acts on a row acting on the row the cursor is on."""

from __future__ import annotations

import asyncio

from helpers.tui import DataFeed, launch_rows, screen_name, table, until

from roc.tui.app import RocApp
from roc.tui.model import Row
from roc.tui.widgets import ListTable

EMPTY = {"nodes": [], "topics": [], "services": [], "actions": []}

def test_home_and_end_go_to_the_first_and_the_last_row() -> None:
    """Not sideways: DataTable's Home and End scroll a row cursor's table to its first or last column."""
    from textual.app import App, ComposeResult

    class OneTable(App):
        def compose(self) -> ComposeResult:
            yield ListTable(("name", "wide"))

    async def test() -> None:
        app = OneTable()
        async with app.run_test(size=(40, 12)) as pilot:
            rows = app.query_one(ListTable)
            rows.show([Row(f"k{i}", (f"k{i}", "x" * 80)) for i in range(30)])
            rows.focus()
            await until(pilot, lambda: rows.row_count == 30, what="every row")
            await pilot.press("end")
            assert rows.selected_key() == "k29" and rows.scroll_x == 0
            await pilot.press("home")
            assert rows.selected_key() == "k0"
            await pilot.press("right")  # sideways with the arrows
            assert rows.scroll_x > 0 and rows.selected_key() == "k0"
    asyncio.run(test())

class Run:
    """A ``roc launch`` run as roc.launch.status.runs gives it: its status, and the requests sent to it."""

    def __init__(self) -> None:
        self.requests: list[tuple[str, str]] = []

    def request(self, method: str, process: str) -> None:
        self.requests.append((method, process))

    def answer(self) -> dict:
        return {"title": "roc launch pair", "pid": 4242, "restartable": True, "processes": [
            {"name": name, "host": "", "pid": pid, "state": "running", "detail": "", "restarts": 0,
             "last_line": "x" * 120} for name, pid in (("listener", 11), ("talker", 12))]}

def test_end_then_restart_restarts_the_last_process(monkeypatch) -> None:
    """The user's case: End, then R in the launches view restarted the first row, not the last one shown
    selected."""
    run = Run()
    monkeypatch.setattr("roc.launch.status.runs", lambda: [(run, run.answer())])

    async def test() -> None:
        app = RocApp(feed=DataFeed(EMPTY), workspace=None)
        async with app.run_test(size=(120, 35)) as pilot:
            app.open("launch")
            await until(pilot, lambda: screen_name(app) == "LaunchScreen" and bool(app.screen.query("#processes"))
                        and {"listener", "talker"} <= set(launch_rows(app)), what="the launch view")
            assert table(app, "#processes").selected_key() == "4242:listener"
            await pilot.press("end", "R")
            await until(pilot, lambda: bool(run.requests), what="the restart asked")
            assert run.requests == [("restart", "talker")]
    asyncio.run(test())
