"""roc tui's bag view on a bag written here (no daemon, no ROS): what it counts."""

from __future__ import annotations

import asyncio
from pathlib import Path

from helpers.bag import write_split_bag_with_tf_static
from helpers.tui import DataFeed, screen_name, table, text_of, until

from roc.tui.app import RocApp

EMPTY = {"nodes": [], "topics": [], "services": [], "actions": []}


def test_the_copies_a_split_recording_repeats_are_not_counted_as_traffic(tmp_path: Path) -> None:
    """/tf_static recorded once and repeated at the start of each of four files is one message at no rate
    (it showed 4 messages at 1.0 Hz), and Enter steps through that one message."""
    write_split_bag_with_tf_static(tmp_path / "bag")

    async def test() -> None:
        app = RocApp(feed=DataFeed(EMPTY), bag=str(tmp_path / "bag"))
        async with app.run_test(size=(100, 30)) as pilot:
            await until(pilot, lambda: screen_name(app) == "BagScreen" and bool(table(app, "#topics").rows_by_key),
                        what="the bag")
            rows = table(app, "#topics").rows_by_key
            assert rows["/tf_static"].cells[2:] == ("1", "-")
            assert rows["/data"].cells[2] == "40"
            assert "41 messages" in text_of(app, "#title") and "3 repeated" in text_of(app, "#title")
            table(app, "#topics").select("/tf_static")
            await pilot.press("enter")
            await until(pilot, lambda: "message 1 of 1" in text_of(app, "#message-title"), what="the message")
    asyncio.run(test())
