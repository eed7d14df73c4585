"""The first screen driven by Textual's pilot on a graph given as data (no daemon, no ROS): fast checks
of its keys and focus."""

from __future__ import annotations

import asyncio
from typing import Any

from helpers.tui import SIZE, table, until
from textual.widgets import TabbedContent

from roc.tui.app import RocApp
from roc.tui.feed import Feed


def still_snapshot(topics: int = 3) -> dict[str, Any]:
    names = [f"/t{i:03d}" for i in range(topics)]
    return {"nodes": [{"name": "talker", "namespace": "/", "full_name": "/talker"}],
            "topics": [{"name": name, "types": ["std_msgs/msg/String"], "publishers": 1, "subscribers": 0}
                       for name in names],
            "services": [{"name": "/talker/get_parameters", "types": ["rcl_interfaces/srv/GetParameters"]}],
            "actions": []}


class DataFeed(Feed):
    """The daemon's answers given as data: a snapshot, no streams."""

    def __init__(self, snapshot: dict[str, Any]) -> None:
        super().__init__()
        self.data = snapshot

    def snapshot(self) -> dict[str, Any]:
        return self.data

    def stream(self, method, params, stop):
        return iter(())


def test_a_tab_chosen_keeps_its_list_focused() -> None:
    """A click on a tab switches it without the key's own focus: the list that loses its tab must not
    hand the focus to its sibling (nodes beside topics), which would bring the first tab back."""
    async def test() -> None:
        app = RocApp(feed=DataFeed(still_snapshot()))
        async with app.run_test(size=SIZE) as pilot:
            await until(pilot, lambda: "/t000" in table(app, "#topics-table").rows_by_key, what="the topics")
            tabs = app.screen.query_one("#tabs", TabbedContent)
            for _ in range(2):
                assert app.focused is table(app, "#topics-table")
                tabs.active = "services"  # as a click on the tab does
                await until(pilot, lambda: app.focused is table(app, "#services-table"), what="the services")
                await pilot.pause(0.2)
                assert tabs.active == "services" and app.focused is table(app, "#services-table"), app.focused
                await pilot.press("2")
                await until(pilot, lambda: app.focused is table(app, "#topics-table"), what="the topics again")
                assert tabs.active == "system-tab"
    asyncio.run(test())
