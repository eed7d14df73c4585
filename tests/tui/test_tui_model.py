"""roc tui without a graph: what the lists show (roc.tui.model), the manual's keys, and that the TUI
loads no rclpy."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from helpers.build import REPO
from textual.binding import Binding

from roc.tui.model import Rates, counts, matches, rate_text, topic_rows, visible
from roc.tui.problems import topic_diagnoses

MANUAL = REPO / "docs" / "commands" / "tui.md"


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


def test_the_manual_lists_every_key_and_command() -> None:
    """The manual's tables come from the screens' own bindings and the palette (roc.tui.keys, through
    docs/hooks/tui_keys.py): every screen with bindings is in them."""
    import importlib
    import inspect

    from textual.screen import Screen

    from roc.tui.keys import SCREENS, command_table, key_table
    from roc.tui.palette import VIEWS

    manual = MANUAL.read_text()
    assert "<!-- tui-keys -->" in manual and "<!-- tui-commands -->" in manual
    listed = {name for _, _, name in SCREENS}
    for module in ("app", "graph_screen", "node_screen", "topic_screen", "logs_screen", "plot_screen", "image_screen",
                   "diagnostics_screen", "call_screens", "bag_screen", "launch_screen", "frames_screen", "build_screen"):
        for name, cls in inspect.getmembers(importlib.import_module(f"roc.tui.{module}"), inspect.isclass):
            if issubclass(cls, Screen) and cls.__module__ == f"roc.tui.{module}" and "BINDINGS" in vars(cls) \
                    and name not in ("CallScreen", "ServiceScreen"):
                assert name in listed, name
    table = key_table()
    for _, module, name in SCREENS:
        for binding in getattr(importlib.import_module(module), name).BINDINGS:
            assert isinstance(binding, Binding)
            assert f"| {binding.description} |" in table, (name, binding.description)
    assert all(f"`:{view}" in command_table() for view in VIEWS)


def test_the_tui_loads_no_rclpy() -> None:
    code = ("import sys, roc.commands.tui, roc.tui.app, roc.tui.graph_screen, roc.tui.node_screen, "
            "roc.tui.topic_screen, roc.tui.call_screens, roc.tui.frames_screen, roc.tui.build_screen, "
            "roc.tui.logs_screen, roc.tui.plot_screen, roc.tui.diagnostics_screen, roc.tui.bag_screen, "
            "roc.tui.launch_screen, roc.tui.image_screen, roc.tui.images, roc.launch.status; "
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


def test_plot_points_are_thinned_keeping_spikes_and_written_as_csv() -> None:
    from roc.tui.plotting import Series, csv_text, numeric_paths, thinned

    times = [i / 1000 for i in range(10000)]
    values = [100.0 if i == 5003 else float(i % 7) for i in range(10000)]
    thin_t, thin_v = thinned(times, values, 50)
    assert len(thin_t) <= 100 and 100.0 in thin_v and thin_t == sorted(thin_t)
    x, y = Series("/pose", "x"), Series("/pose", "y")
    x.add([1.0, 2.0], [1.5, None])
    y.add([1.0, 2.0], [3.0, 4.0])
    assert csv_text([x, y]).splitlines() == ["time,/pose x,/pose y", "1.000000000,1.5,3.0", "2.000000000,,4.0"]
    assert numeric_paths({"pose": {"x": 1.0, "frame": "map"}, "ranges": [1.0, 2.0], "ok": True}) == [
        "pose.x", "ranges[0]", "ranges[1]", "ok"]


def test_a_participant_gid_names_its_process_bits_and_a_domain_port() -> None:
    from roc.ros.discovery import is_metatraffic_port
    from roc.tui.processes import participant

    found = participant("01.0f.7f.01.f3.5f.c1.23.00.00.00.00.00.00.03.03")
    assert found is not None and found.pid_bits == 0x5FF3 and found.prefix == "01.0f.7f.01.f3.5f.c1.23.00.00.00.00"
    other = participant("01.10.00.00.00.00.00.00.00.00.00.00.00.00.00.00")  # Cyclone DDS's: no process in it
    assert other is not None and other.pid_bits is None and other.prefix == "01.10.00.00.00.00.00.00.00.00.00.00"
    assert participant("01.10.00") is None  # no GUID
    assert is_metatraffic_port(8660, 5) and is_metatraffic_port(8664, 5)
    assert not is_metatraffic_port(8661, 5) and not is_metatraffic_port(7410, 5)


def test_problems_count_no_lonely_publisher_and_remember_nodes_gone() -> None:
    from roc.check.expectations import CheckFile, Expectation
    from roc.tui.problems import Watch

    topics = [{"name": "/rosout", "publishers": 3, "subscribers": 0}, {"name": "/cmd", "publishers": 0,
                                                                         "subscribers": 1},
              {"name": "/scan", "publishers": 1, "subscribers": 1}]
    checks = CheckFile(Path("roc.toml"), [Expectation("topic", "/scan", {"min-rate": 10.0}),
                                          Expectation("node", "/base")])
    watch = Watch(checks)
    first = [p.text for p in watch.problems(topics, ["/lidar"], lambda topic: 4.0)]
    assert first == ["/cmd: no publisher", "/scan: 4.0 Hz, below the 10 Hz roc.toml expects",
                     "/base: expected by roc.toml, not running"]
    later = [p.text for p in watch.problems(topics, [], lambda topic: 12.0)]
    assert any(p.startswith("/lidar: gone since") for p in later) and len(later) == 3
