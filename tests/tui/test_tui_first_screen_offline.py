"""The first screen driven by Textual's pilot on a graph given as data (no daemon, no ROS): fast checks
of its keys and focus."""

from __future__ import annotations

import asyncio
from typing import Any

import pytest
from helpers.tui import SIZE, DataFeed, table, until
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


@pytest.mark.slow  # a few seconds (the quick loop stays under 45 s)
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


def test_the_first_screen_shows_the_snapshot_asked_for_before_the_app_loaded() -> None:
    """Feed.prefetch asks at once (roc tui does so before it imports Textual); the first snapshot taken is
    that answer, the next ones are asked for again."""
    asked = []

    class CountingFeed(DataFeed):
        def query(self, method, params=None):
            asked.append(method)
            return {**self.data, "asked": len(asked)}

        snapshot = Feed.snapshot

    feed = CountingFeed({"nodes": [], "topics": [{"name": "/t", "types": ["std_msgs/msg/String"], "publishers": 0,
                                                  "subscribers": 0, "endpoints": {"publishers": [], "subscribers": []}}],
                         "services": [], "actions": []})
    feed.prefetch()
    assert feed.snapshot()["asked"] == 1 and feed.snapshot()["asked"] == 2


def test_a_long_list_draws_first_the_rows_a_screen_shows_then_the_others() -> None:
    """The first fill adds only as many rows as the terminal has lines (measuring 200 rows made the first
    paint slow), the others right after that paint; rows appended later are added without drawing
    the others again."""
    from textual.app import App, ComposeResult

    from roc.tui.model import Row
    from roc.tui.widgets import ListTable

    class OneTable(App):
        def compose(self) -> ComposeResult:
            yield ListTable(("name", "value"))

    rows = [Row(f"k{i:03d}", (f"k{i:03d}", str(i))) for i in range(200)]

    async def test() -> None:
        app = OneTable()
        async with app.run_test(size=(40, 12)) as pilot:
            table = app.query_one(ListTable)
            table.show(rows)
            assert table.row_count == 12 and table.shown_count == 12
            await until(pilot, lambda: table.row_count == 200, what="the other rows")
            table.show([*rows, Row("z", ("z", "new"))])
            assert table.row_count == 201
            assert list(table.rows_by_key)[-1] == "z" and table.get_row("z")[1].plain == "new"
            table.show([Row("k000", ("k000", "changed")), *rows[1:], Row("z", ("z", "new"))])
            assert table.get_row("k000")[1].plain == "changed" and table.row_count == 201
            table.show(rows[5:])  # rows gone from the top: drawn again
            assert table.row_count == 195 and list(table.rows_by_key)[0] == "k005"
    asyncio.run(test())


def test_rates_are_measured_again_only_for_the_topics_in_view() -> None:
    from roc.tui.model import Rates

    rates = Rates()

    def batch(topic: str, start: int) -> dict:
        return {"topics": {topic: {"sequence": [start, start + 1], "source": [start * 10**9, (start + 1) * 10**9],
                                   "received": [start * 10**9, (start + 1) * 10**9], "size": [10, 10],
                                   "stamp": [None, None]}}}

    rates.add(batch("/a", 0))
    rates.add(batch("/b", 0))
    assert rates.texts("/a")[0] == rates.texts("/b")[0] == "1.0 Hz"
    rates.in_view = {"/a"}
    for topic in ("/a", "/b"):  # now twice as fast
        rates.add({"topics": {topic: {"sequence": [2, 3, 4, 5], "source": [15 * 10**8, 2 * 10**9, 25 * 10**8, 3 * 10**9],
                                      "received": [15 * 10**8, 2 * 10**9, 25 * 10**8, 3 * 10**9], "size": [10] * 4,
                                      "stamp": [None] * 4}}})
    assert rates.texts("/a")[0] == "1.7 Hz" and rates.texts("/b")[0] == "1.0 Hz"  # /b: as last shown
    rates.in_view = None
    assert rates.texts("/b")[0] == "1.7 Hz"


@pytest.mark.slow  # over a second (the quick loop stays under 45 s)
def test_the_lists_under_another_screen_are_drawn_when_it_is_back() -> None:
    """The first screen's lists are not drawn while another screen covers them (a plot's CPU went to
    them), and are drawn from the latest snapshot when it is back."""
    feed = DataFeed(still_snapshot(3))

    async def test() -> None:
        app = RocApp(feed=feed)
        async with app.run_test(size=SIZE) as pilot:
            topics = table(app, "#topics-table")
            await until(pilot, lambda: "/t002" in topics.rows_by_key, what="the topics")
            await pilot.press("question_mark")
            await until(pilot, lambda: type(app.screen).__name__ == "TextViewer", what="the help")
            feed.data = still_snapshot(5)
            await until(pilot, lambda: app.graph_screen.snapshot == feed.data, what="a new snapshot")
            assert "/t004" not in topics.rows_by_key
            await pilot.press("escape")
            await until(pilot, lambda: "/t004" in topics.rows_by_key, what="the new topics")
    asyncio.run(test())


def test_endpoints_are_asked_for_again_only_when_counts_change_or_after_a_while() -> None:
    """A topic's endpoints (QoS, gids) come with every snapshot, but the daemon is asked for them only
    when a topic's counts change or ENDPOINTS_SECONDS passed."""
    endpoint = {"node_name": "talker", "node_namespace": "/", "gid": "01.0f", "qos": {}}
    graph = {"subscribers": 0}
    asked = []

    class CountingFeed(Feed):
        def query(self, method, params=None):
            asked.append(params["endpoints"])
            topic = {"name": "/chatter", "types": ["std_msgs/msg/String"], "publishers": 1,
                     "subscribers": graph["subscribers"]}
            if params["endpoints"]:
                topic["endpoints"] = {"publishers": [endpoint], "subscribers": [endpoint] * graph["subscribers"]}
            return {"nodes": [], "topics": [topic], "services": [], "actions": []}

    feed = CountingFeed()
    assert feed.snapshot()["topics"][0]["endpoints"]["publishers"] == [endpoint]
    assert feed.snapshot()["topics"][0]["endpoints"]["publishers"] == [endpoint]
    assert asked == [True, False]
    graph["subscribers"] = 1
    assert len(feed.snapshot()["topics"][0]["endpoints"]["subscribers"]) == 1
    assert asked == [True, False, False, True]
    feed._endpoints_due = 0.0  # ENDPOINTS_SECONDS later
    feed.snapshot()
    assert asked == [True, False, False, True, True]


def test_a_rate_measured_again_after_a_gap_in_its_stream_is_not_low() -> None:
    """Issue 51: the first screen read 0.7 Hz for a 2.1 Hz topic while roc topic hz said 2.0. Its rates
    stream starts again whenever the published topics change; a window kept across the gap between two
    streams counted the messages of a topic with two publishers (no one sequence) over a time that
    included the gap. Two publishers at 1.05 Hz, a first stream for 4 s, none for 6 s, a second one."""
    from roc.tui.model import Rates

    def batch(start: float, seconds: float) -> dict:
        times = sorted([int((start + i / 1.05) * 1e9) for i in range(int(seconds * 1.05))]
                       + [int((start + 0.3 + i / 1.05) * 1e9) for i in range(int(seconds * 1.05))])
        sequence = [1 + i // 2 for i in range(len(times))]  # the two publishers' numbers, interleaved
        return {"topics": {"/y": {"sequence": sequence, "source": times, "received": times,
                                  "size": [10] * len(times), "stamp": [None] * len(times)}}}

    rates = Rates()
    rates.restart()
    rates.add(batch(0.0, 4.0))
    assert abs(rates.rate("/y") - 2.1) < 0.25
    rates.restart()  # the topics changed: a new stream, 6 s later
    assert abs(rates.rate("/y") - 2.1) < 0.25  # the last stream's rate until the new one measures
    second = batch(10.0, 4.0)
    columns = second["topics"]["/y"]
    rates.add({"topics": {"/y": {name: values[:2] for name, values in columns.items()}}})
    assert abs(rates.rate("/y") - 2.1) < 0.25  # not 3.3 Hz: the two publishers' first messages, 0.3 s apart
    rates.add({"topics": {"/y": {name: values[2:] for name, values in columns.items()}}})
    assert abs(rates.rate("/y") - 2.1) < 0.25, rates.rate("/y")  # was 1.05: 8 s of messages over 14 s


def test_a_new_stream_that_cannot_measure_yet_leaves_the_last_streams_rate() -> None:
    """Two publishers at 0.4 Hz: 2.5 s into a new stream, each was heard once (no rate of its own yet);
    the list keeps the last stream's 0.8 Hz rather than showing none."""
    from roc.tui.model import Rates

    def batch(messages: list[tuple[int, int, float]]) -> dict:
        return {"topics": {"/slow": {"sequence": [m[1] for m in messages], "source": [int(m[2] * 1e9) for m in messages],
                                     "received": [int(m[2] * 1e9) for m in messages], "size": [10] * len(messages),
                                     "stamp": [None] * len(messages), "publisher": [m[0] for m in messages]}}}

    rates = Rates()
    rates.add(batch([(p, n, p + n * 2.5) for n in range(4) for p in (0, 1)]))
    assert rates.rate("/slow") == pytest.approx(0.8)
    rates.restart()
    rates.add(batch([(0, 9, 20.0), (1, 9, 22.5)]))
    assert rates.rate("/slow") == pytest.approx(0.8)
