"""roc tui without a graph: what the lists show (roc.tui.model), the manual's keys, and that the TUI
loads no rclpy."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from textual.binding import Binding

from roc.tui.model import Rates, counts, matches, rate_text, topic_rows, visible
from roc.tui.problems import topic_diagnoses

MANUAL = Path(__file__).resolve().parents[1] / "docs" / "commands" / "tui.md"


def endpoint(node: str, side: str, reliability: str = "RELIABLE") -> dict:
    return {"node_name": node, "node_namespace": "/", "topic_type": "std_msgs/msg/String", "topic_type_hash": "h",
            "endpoint_type": side, "gid": node, "qos": {
                "reliability": reliability, "history": "KEEP_LAST", "depth": 10, "durability": "VOLATILE",
                "lifespan_ns": None, "deadline_ns": None, "liveliness": "AUTOMATIC",
                "liveliness_lease_duration_ns": None}}


def snapshot() -> dict:
    topics = [
        {"name": "/scan", "types": ["std_msgs/msg/String"], "publishers": 1, "subscribers": 2,
         "endpoints": {"publishers": [endpoint("lidar", "PUBLISHER", "BEST_EFFORT")],
                       "subscribers": [endpoint("slam", "SUBSCRIPTION"), endpoint("_roc_12", "SUBSCRIPTION")]}},
        {"name": "/cmd", "types": ["std_msgs/msg/String"], "publishers": 0, "subscribers": 1,
         "endpoints": {"publishers": [], "subscribers": [endpoint("base", "SUBSCRIPTION")]}},
        {"name": "/_hidden", "types": ["std_msgs/msg/String"], "publishers": 1, "subscribers": 0,
         "endpoints": {"publishers": [endpoint("x", "PUBLISHER")], "subscribers": []}},
    ]
    return {"nodes": [{"name": "lidar", "namespace": "/", "full_name": "/lidar"},
                      {"name": "_roc_12", "namespace": "/", "full_name": "/_roc_12"}],
            "topics": topics, "services": [], "actions": []}


def test_topic_rows_count_no_hidden_endpoint_and_say_what_is_wrong() -> None:
    rows = {row.key: row for row in topic_rows(snapshot(), Rates())}
    assert set(rows) == {"/scan", "/cmd"}
    assert rows["/scan"].cells[:5] == ("/scan", "1", "1", "-", "-")  # the daemon's subscription left out
    assert rows["/scan"].problems[0].startswith("QoS incompatible (reliability): /lidar -> /slam")
    assert rows["/cmd"].problems == ["no publisher"]
    assert counts(snapshot()) == {"nodes": 1, "topics": 2, "services": 0, "actions": 0}
    assert len(visible(snapshot()["topics"], hidden=True)) == 3


def test_a_lone_subscriber_without_endpoints_known_still_counts() -> None:
    assert topic_diagnoses({"publishers": 0, "subscribers": 1}) == ["no publisher"]
    assert topic_diagnoses({"publishers": 1, "subscribers": 0}) == []  # nobody listening is no problem


def test_filter_and_texts() -> None:
    assert matches("odom robot", "/robot1/odom", "nav_msgs/msg/Odometry")
    assert matches("ODOM", "/robot1/odom") and not matches("odom map", "/robot1/odom")
    assert (rate_text(None), rate_text(9.96), rate_text(2500.0)) == ("-", "10.0 Hz", "2.50 kHz")


def test_the_manual_lists_every_key() -> None:
    from roc.tui.app import RocApp
    from roc.tui.build_screen import BuildScreen
    from roc.tui.call_screens import ActionScreen, ServiceScreen
    from roc.tui.frames_screen import FramesScreen
    from roc.tui.graph_screen import GraphScreen
    from roc.tui.node_screen import NodeScreen
    from roc.tui.topic_screen import TopicScreen

    manual = MANUAL.read_text()
    for screen in (RocApp, GraphScreen, NodeScreen, TopicScreen, ServiceScreen, ActionScreen, FramesScreen,
                   BuildScreen):
        for binding in screen.BINDINGS:
            assert isinstance(binding, Binding)
            assert f"| {binding.description}" in manual, (screen.__name__, binding.description)


def test_the_tui_loads_no_rclpy() -> None:
    code = ("import sys, roc.commands.tui, roc.tui.app, roc.tui.graph_screen, roc.tui.node_screen, "
            "roc.tui.topic_screen, roc.tui.call_screens, roc.tui.frames_screen, roc.tui.build_screen; "
            "print(sorted(m for m in sys.modules if m.split('.')[0] == 'rclpy'))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


def test_rows_drawn_before_their_columns_widened_are_drawn_again() -> None:
    """A table draws rows added a moment ago before it measures them; once measured, they are drawn again
    at their columns' widths, also when no Resize event follows (a screen kept header-wide columns)."""
    import asyncio

    from textual.app import App, ComposeResult
    from textual.events import Resize

    from roc.tui.model import Row
    from roc.tui.widgets import ListTable

    class TableNotResized(ListTable):
        def _on_resize(self, event: Resize) -> None:
            event.prevent_default()  # DataTable's own handler would draw every row again

    class OneTable(App):
        def compose(self) -> ComposeResult:
            yield TableNotResized(("parameter", "type"))

    async def run() -> tuple[str, str]:
        app = OneTable()
        async with app.run_test(size=(60, 5)) as pilot:
            table = app.query_one(TableNotResized)
            await pilot.pause()
            table.show([Row("p", ("start_type_description_service", "boolean"))])
            early = table.render_line(1).text  # before the table measured the new row
            await pilot.pause()
            await pilot.pause(0.2)
            return early, table.render_line(1).text

    early, settled = asyncio.run(run())
    assert "start_type_description_service" not in early
    assert "start_type_description_service  boolean" in settled
