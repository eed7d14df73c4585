"""roc tui driven headless by Textual's pilot (App.run_test) at 80x24 on a live graph: real rclpy
nodes in subprocesses, the real roc daemon. Lists, counts, problems, filter, drill-down, parameter
edit and dump, service call, echo with pause and field, action goal with feedback and cancel, the tf
tree, help, quit."""

from __future__ import annotations

import asyncio
import os
import re
import sys
from pathlib import Path

import pytest
import yaml
from helpers.graph import DEMO_GRAPH, graph_env, roc
from helpers.tui import SIZE, live_graph, open_row, palette_command, table, text_of, until

from roc.tui.app import RocApp

pytestmark = pytest.mark.slow

NODES = [
    *DEMO_GRAPH,
    [{"name": "chatty", "publishers": [{"topic": "news", "type": "std_msgs/msg/String", "values": {"data": "hello"},
                                        "rate_hz": 10}]},
     {"name": "picky", "subscribers": [{"topic": "odd", "type": "std_msgs/msg/String", "reliability": "reliable"}]},
     {"name": "_helper"},  # a hidden node: listed only after H
     {"name": "sloppy", "publishers": [{"topic": "odd", "type": "std_msgs/msg/String",
                                        "reliability": "best_effort"}]},
     {"name": "echoer", "services": [{"name": "echo_types", "type": "test_msgs/srv/BasicTypes", "echo": True}]},
     {"name": "slow_server", "actions": [{"name": "slow_fibonacci", "step_seconds": 0.3}]}],
]


@pytest.fixture(scope="module")
def graph(tmp_path_factory):
    with live_graph(graph_env(36, tmp_path_factory.mktemp("runtime")), NODES) as env:
        yield env


@pytest.fixture(autouse=True)
def loads_no_rclpy_when_asked():
    """With ROC_TUI_ASSERT_NO_RCLPY=1 (tests/tui/test_tui_no_rclpy.py runs these tests in a fresh process so),
    each test ends by checking that the app loaded no rclpy module."""
    yield
    if os.environ.get("ROC_TUI_ASSERT_NO_RCLPY") == "1":
        loaded = sorted(name for name in sys.modules if name.split(".")[0] == "rclpy")
        assert not loaded, f"roc tui loaded rclpy: {loaded[:5]}"


def drive(test) -> None:
    asyncio.run(test())


@pytest.mark.distro
def test_lists_counts_rates_problems_and_filter(graph) -> None:
    async def test() -> None:
        app = RocApp()
        async with app.run_test(size=SIZE) as pilot:
            topics = lambda: table(app, "#topics-table").rows_by_key  # noqa: E731
            await until(pilot, lambda: "/news" in topics() and "/odd" in topics(), what="the topics")
            news = topics()["/news"]
            assert (news.cells[1:3], news.cells[5]) == (("1", "0"), "std_msgs/msg/String")
            assert news.problems == []  # nobody listening is no problem
            problems = topics()["/odd"].problems
            assert any(p.startswith("QoS incompatible (reliability): /sloppy -> /picky") for p in problems)
            await until(pilot, lambda: topics()["/news"].cells[3].endswith("Hz"), what="the rate of /news")
            rate = float(topics()["/news"].cells[3].split()[0])
            assert 5.0 <= rate <= 11.0  # 10 Hz asked; an rclpy timer on a loaded machine publishes fewer
            assert topics()["/news"].cells[4].endswith("B/s")
            header = text_of(app, "#header")
            assert "topics" in header and "problem" in text_of(app, "#problems")
            await pilot.press("1")
            await until(pilot, lambda: "/motor_controller" in table(app, "#nodes-table").rows_by_key)
            nodes = set(table(app, "#nodes-table").rows_by_key)
            assert {"/talker", "/listener", "/robot1/odom_pub", "/echoer"} <= nodes
            assert f"{len(table(app, '#nodes-table').rows_by_key)} nodes" in text_of(app, "#header")
            await pilot.press("2", "slash", *"news")
            await until(pilot, lambda: list(topics()) == ["/news"], what="the filter")
            await pilot.press("enter", "escape")
            await until(pilot, lambda: len(topics()) > 1, what="the filter cleared")
    drive(test)


def test_node_parameters_edit_and_dump(graph, tmp_path: Path) -> None:
    dump = tmp_path / "motor.yaml"

    async def test() -> None:
        app = RocApp()
        async with app.run_test(size=SIZE) as pilot:
            await open_row(app, pilot, "nodes", "/motor_controller")
            await until(pilot, lambda: "max_speed" in table(app, "#parameters").rows_by_key, what="the parameters")
            interfaces = {row.cells[1] for row in table(app, "#interfaces").rows_by_key.values()}
            assert {"/motor_controller/enable", "/motor_controller/reset"} <= interfaces
            assert table(app, "#parameters").rows_by_key["max_speed"].cells[1:] == ("double", "1.5")
            parameters = table(app, "#parameters")
            parameters.focus()
            parameters.move_cursor(row=list(parameters.rows_by_key).index("max_speed"))
            await pilot.press("e")
            await until(pilot, lambda: type(app.screen).__name__ == "Prompt")
            await pilot.press(*["backspace"] * 5, "3", "enter")  # an integer, kept a double
            await until(pilot, lambda: parameters.rows_by_key["max_speed"].cells[2] == "3.0", what="the new value")
            await pilot.press("d")
            await until(pilot, lambda: type(app.screen).__name__ == "Prompt")
            prompt = app.screen.query_one("#prompt")
            prompt.value = str(dump)
            await pilot.press("enter")
            await until(pilot, dump.exists, what="the dump file")
    drive(test)
    got = roc("param", "get", "/motor_controller", "max_speed", env=graph)
    assert got.stdout.strip() == "Double value is: 3.0"
    assert yaml.safe_load(dump.read_text())["/motor_controller"]["ros__parameters"]["max_speed"] == 3.0


def test_topic_echo_pause_field_and_rate(graph) -> None:
    async def test() -> None:
        app = RocApp()
        async with app.run_test(size=SIZE) as pilot:
            await open_row(app, pilot, "topics", "/news")
            screen = app.screen
            await until(pilot, lambda: screen.drawn > 0, what="a message")
            assert "data: hello" in text_of(app, "#echo")
            assert "/chatty" in {row.cells[0] for row in table(app, "#endpoints").rows_by_key.values()}
            await pilot.press("p")
            frozen = screen.drawn
            await until(pilot, lambda: screen.count >= frozen + 3, what="more messages while paused")
            assert screen.drawn == frozen and "paused" in text_of(app, "#echo-title")
            await pilot.press("p")
            await until(pilot, lambda: screen.drawn > frozen, what="the echo to resume")
            await pilot.press("f")
            await until(pilot, lambda: type(app.screen).__name__ == "Prompt")
            await pilot.press(*"data", "enter")
            await until(pilot, lambda: text_of(app, "#echo").startswith("hello"), what="the field")
            rate = lambda: re.match(r"rate ([0-9.]+) Hz", text_of(app, "#stats"))  # noqa: E731
            await until(pilot, lambda: rate() is not None, what="the rate")
            assert 5.0 <= float(rate().group(1)) <= 11.0  # 10 Hz asked (see the first test)
    drive(test)


def test_service_call_with_a_yaml_request(graph) -> None:
    async def test() -> None:
        app = RocApp()
        async with app.run_test(size=SIZE) as pilot:
            await open_row(app, pilot, "services", "/echo_types")
            await until(pilot, lambda: type(app.screen).__name__ == "ServiceScreen")
            editor = app.screen.query_one("#editor")
            assert "int32_value: 0" in editor.text  # the request's prototype
            editor.text = "int32_value: 7\nstring_value: across\n"
            await pilot.press("ctrl+s")
            await until(pilot, lambda: "response:" in text_of(app, "#output"), what="the response")
            output = text_of(app, "#output")
            assert "int32_value: 7" in output and "string_value: across" in output
            editor.text = "int32_value: nope\n"
            await pilot.press("ctrl+s")
            await until(pilot, lambda: "error:" in text_of(app, "#output"))
            assert "int32_value" in text_of(app, "#output")
    drive(test)


def test_action_goal_feedback_and_cancel(graph) -> None:
    async def test() -> None:
        app = RocApp()
        async with app.run_test(size=SIZE) as pilot:
            await open_row(app, pilot, "actions", "/slow_fibonacci")
            await until(pilot, lambda: type(app.screen).__name__ == "ActionScreen")
            app.screen.query_one("#editor").text = "order: 3\n"
            await pilot.press("ctrl+s")
            await until(pilot, lambda: "result (SUCCEEDED)" in text_of(app, "#output"), what="the result")
            assert "feedback: " in text_of(app, "#output")
            app.screen.query_one("#editor").text = "order: 40\n"
            await pilot.press("ctrl+s")
            await until(pilot, lambda: "feedback" in text_of(app, "#output"), what="feedback")
            await pilot.press("ctrl+g")
            await until(pilot, lambda: "result (CANCELED)" in text_of(app, "#output"), what="the cancel")
    drive(test)


def test_help_lists_every_key_and_q_quits(graph) -> None:
    async def test() -> None:
        app = RocApp()
        async with app.run_test(size=SIZE) as pilot:
            await pilot.press("question_mark")
            await until(pilot, lambda: type(app.screen).__name__ == "TextViewer")
            text = app.screen.query_one("#viewer").text
            for binding in [*type(app).BINDINGS, *app.screen_stack[-2].BINDINGS]:
                assert binding.description in text, binding
            await pilot.press("escape", "q")
            await until(pilot, lambda: not app.is_running, what="the app to quit")
        assert app.return_value == 0
    drive(test)


def test_tab_keys_and_the_command_palette(graph) -> None:
    async def test() -> None:
        app = RocApp()
        async with app.run_test(size=SIZE) as pilot:
            await until(pilot, lambda: "/motor_controller/enable" in table(app, "#services-table").rows_by_key)
            tabs = app.screen  # the list the keys act on: nodes and topics share the first tab
            assert tabs.active_tab() == "topics"
            await pilot.press("tab")
            await until(pilot, lambda: tabs.active_tab() == "services")
            await pilot.press("shift+tab", "shift+tab")
            await until(pilot, lambda: tabs.active_tab() == "nodes")
            nodes = table(app, "#nodes-table")
            assert "/_helper" not in nodes.rows_by_key
            await pilot.press("H")  # hidden names too (never roc's own participants)
            await until(pilot, lambda: "/_helper" in nodes.rows_by_key, what="hidden")
            assert not any(name.startswith("/_roc_") for name in nodes.rows_by_key)
            await palette_command(app, pilot, "node motor_con", "node /motor_controller")
            await until(pilot, lambda: type(app.screen).__name__ == "NodeScreen", what="the node, from the palette")
            assert app.screen.node == "/motor_controller"
            # Esc back, ] forward again to the screen Esc left; opening another screen forgets it
            await pilot.press("escape")
            await until(pilot, lambda: app.screen is tabs, what="back")
            await pilot.press("right_square_bracket")
            await until(pilot, lambda: type(app.screen).__name__ == "NodeScreen", what="forward")
            assert app.screen.node == "/motor_controller"
            await pilot.press("escape")
            await until(pilot, lambda: app.screen is tabs, what="back again")
            await palette_command(app, pilot, "diagnostics", "diagnostics")
            await until(pilot, lambda: type(app.screen).__name__ == "DiagnosticsScreen", what="the diagnostics")
            await pilot.press("escape")
            await until(pilot, lambda: app.screen is tabs, what="back from the diagnostics")
            await pilot.press("right_square_bracket")
            await until(pilot, lambda: type(app.screen).__name__ == "DiagnosticsScreen", what="forward to the last left")
            await pilot.press("escape")
            await until(pilot, lambda: app.screen is tabs, what="back to the lists")
            assert [kind for kind, _ in app._forward] == ["diagnostics"]  # the node was forgotten
    drive(test)
