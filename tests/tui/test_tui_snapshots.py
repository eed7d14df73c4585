"""Snapshots of roc tui's main screens at 80x24: the real app on a live graph, exported as SVG by
Textual and compared with tests/data/tui/*.svg. The screens are drawn from the daemon's answers
without its streams (no live rates or echo), so that they do not change from one run to the next.

ROC_UPDATE_SNAPSHOTS=1 rewrites the stored snapshots and the manual's pictures (docs/images/tui-*.svg),
which also get a topic screen with its live echo and rates."""

from __future__ import annotations

import asyncio
import os
import re
import time

import pytest
from helpers.build import DATA
from helpers.graph import DEMO_GRAPH, REPO, graph_env
from helpers.tui import SIZE, live_graph, open_row, table, until
from textual.widgets.data_table import ColumnKey

from roc.engine.events import (
    CommandStarted,
    RunFinished,
    TaskFailed,
    TaskFinished,
    TaskOutput,
    TaskQueued,
    TaskStarted,
)
from roc.tui.app import RocApp
from roc.tui.feed import Feed
from roc.tui.processes import Processes, Usage

pytestmark = pytest.mark.slow
SNAPSHOTS = DATA / "tui"
IMAGES = REPO / "docs" / "images"
UPDATE = os.environ.get("ROC_UPDATE_SNAPSHOTS") == "1"
SETTLE_SECONDS = 5.0
EXTRA = [[{"name": "camera", "namespace": "/robot1",
           "publishers": [{"topic": "image", "type": "sensor_msgs/msg/Image", "reliability": "best_effort",
                           "values": {"height": 2, "width": 2, "encoding": "mono8", "step": 2,
                                      "data": [1, 2, 3, 4]}, "rate_hz": 30}]},
          {"name": "viewer", "namespace": "/robot1",
           "subscribers": [{"topic": "image", "type": "sensor_msgs/msg/Image", "reliability": "reliable"}]},
          {"name": "odom_logger", "subscribers": [{"topic": "/robot1/odom", "type": "nav_msgs/msg/Odometry",
                                                   "reliability": "best_effort"}]}]]


class StillFeed(Feed):
    """The daemon's answers without its streams: the screens stay the same from run to run."""

    def stream(self, method, params, stop):
        return iter(())


class StillProcesses(Processes):
    """The nodes' processes found, their pid, CPU and memory shown as the same numbers in every run."""

    def update(self, snapshot):
        self.usage = {node: Usage(4242, 1.0, 50_000_000, found.nodes) if found.pid is not None else found
                      for node, found in super().update(snapshot).items()}
        return self.usage


@pytest.fixture(scope="module")
def graph(tmp_path_factory):
    with live_graph(graph_env(39, tmp_path_factory.mktemp("runtime")), [*DEMO_GRAPH, *EXTRA]) as env:
        yield env


async def check(app, pilot, name: str) -> None:
    """Compare the screen with the stored snapshot (or store it, with ROC_UPDATE_SNAPSHOTS=1). A
    loaded machine may draw a table's new column widths a moment after their rows, so the screen is
    taken again, for up to SETTLE_SECONDS, until it matches."""
    stored = SNAPSHOTS / f"{name}.svg"
    deadline = time.monotonic() + SETTLE_SECONDS
    svg = app.export_screenshot(title="roc tui")
    while not UPDATE and stored.is_file() and svg != stored.read_text() and time.monotonic() < deadline:
        await pilot.pause(0.2)
        svg = app.export_screenshot(title="roc tui")
    if UPDATE:
        stored.parent.mkdir(parents=True, exist_ok=True)
        stored.write_text(svg)
        (IMAGES / f"tui-{name}.svg").write_text(svg)
    assert stored.is_file(), f"no snapshot {stored}: run with ROC_UPDATE_SNAPSHOTS=1 and check it"
    assert screen_text(svg) == screen_text(stored.read_text()), f"{name}: the screen differs from {stored}"
    assert svg == stored.read_text(), f"{name}: the screen's styles differ from {stored}"


def screen_text(svg: str) -> list[str]:
    """The text of an exported screen, line by line (for a readable failure)."""
    lines: dict[str, list[str]] = {}
    for line, text in re.findall(r'<text [^>]*?y="([0-9.]+)"[^>]*>([^<]*)</text>', svg):
        lines.setdefault(line, []).append(text.replace("&#160;", " "))
    return ["".join(parts).rstrip() for _, parts in sorted(lines.items(), key=lambda item: float(item[0]))]


async def graph_ready(app, pilot) -> None:
    nodes = {"/talker", "/listener", "/robot1/odom_pub", "/map_server", "/motor_controller", "/fibonacci_server",
             "/robot1/camera", "/robot1/viewer", "/odom_logger"}
    await until(pilot, lambda: app.graph_screen.snapshot is not None
                and {n["full_name"] for n in app.graph_screen.snapshot["nodes"]} >= nodes
                and len(app.graph_screen.snapshot["services"]) >= 6 * len(nodes) + 2
                and all(t["publishers"] + t["subscribers"] for t in app.graph_screen.snapshot["topics"]),
                what="the whole graph")
    await pilot.pause(1.5)  # one more refresh: every count settled


def test_main_screens(graph) -> None:
    async def test() -> None:
        app = RocApp(feed=StillFeed())
        async with app.run_test(size=SIZE) as pilot:
            app.graph_screen.processes = StillProcesses()
            await graph_ready(app, pilot)
            topics = table(app, "#topics-table")
            topics.move_cursor(row=list(topics.rows_by_key).index("/robot1/image"))
            await pilot.pause(0.3)
            await check(app, pilot, "topics")
            await pilot.press("1")
            await pilot.pause(0.3)
            await check(app, pilot, "nodes")
            await pilot.press("question_mark")
            await until(pilot, lambda: type(app.screen).__name__ == "TextViewer")
            await check(app, pilot, "help")
            await pilot.press("escape")
            await open_row(app, pilot, "nodes", "/motor_controller")
            parameters = table(app, "#parameters")
            await until(pilot, lambda: len(parameters.rows_by_key) == 8, what="the parameters")
            widest = len("start_type_description_service")
            await until(pilot, lambda: parameters.columns[ColumnKey("parameter")].content_width >= widest,
                        what="the columns' widths")
            await pilot.pause(0.5)
            await check(app, pilot, "node")
    asyncio.run(test())


def run_of_four(handlers: list, _stop) -> int:
    """The events of a run of four packages, one failed, at set times (as the executor sends them)."""
    events = [TaskQueued(name, time=0.0) for name in ("core", "msgs", "driver", "app")]
    events += [TaskStarted("core", time=0.1), TaskFinished("core", duration=4.2, time=4.3),
               TaskStarted("msgs", time=4.3), CommandStarted("msgs", command=("cmake", "--build", "build/msgs")),
               TaskOutput("msgs", data=b"[ 62%] Building CXX object"), TaskFinished("msgs", duration=9.1, time=13.4),
               TaskStarted("driver", time=4.4),
               TaskOutput("driver", stream="stderr", data=b"driver.cpp:3:1: error: expected ';'\n"),
               TaskFailed("driver", duration=2.5, reason="build of 'driver' failed", time=6.9),
               RunFinished("", not_started=("app",), time=13.5)]
    for event in events:
        for handler in handlers:
            handler(event)
    return 1


def test_build_screen() -> None:
    async def test() -> None:
        app = RocApp(build=run_of_four)
        async with app.run_test(size=SIZE) as pilot:
            await until(pilot, lambda: not app.build.running() and app.build.board.finished)
            tasks = table(app, "#tasks")
            await until(pilot, lambda: len(tasks.rows_by_key) == 4)
            tasks.move_cursor(row=2)
            await pilot.pause(0.6)
            await check(app, pilot, "build")
            await pilot.press("enter")
            await until(pilot, lambda: type(app.screen).__name__ == "TextViewer")
            assert "expected ';'" in app.screen.query_one("#viewer").text
            await pilot.press("escape", "q")
        assert app.return_value == 1
    asyncio.run(test())


@pytest.mark.skipif(not UPDATE, reason="draws the manual's live pictures only with ROC_UPDATE_SNAPSHOTS=1")
def test_manual_pictures_with_live_data(graph) -> None:
    """The graph with live rates and a topic with its live echo, for docs/commands/tui.md (not compared:
    live numbers change)."""
    async def test() -> None:
        app = RocApp()
        async with app.run_test(size=SIZE) as pilot:
            await graph_ready(app, pilot)
            topics = table(app, "#topics-table")
            await until(pilot, lambda: topics.rows_by_key["/robot1/image"].cells[3].endswith("Hz"), what="rates")
            await pilot.pause(2.0)
            (IMAGES / "tui-topics-live.svg").write_text(app.export_screenshot(title="roc tui"))
            await open_row(app, pilot, "topics", "/robot1/image")
            stats = app.screen.query_one("#stats")
            await until(pilot, lambda: app.screen.drawn > 0 and "Hz" in str(stats.render()), what="the echo, the rate")
            await pilot.pause(2.0)
            (IMAGES / "tui-topic.svg").write_text(app.export_screenshot(title="roc tui"))
    asyncio.run(test())
