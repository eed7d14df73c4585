"""roc tui's views on one live graph (Textual's pilot, the real daemon, real rclpy nodes): the first
screen (nodes with their process's CPU and memory beside the topics with their rates, at 100x30 and
80x24; a problems line that counts only real problems, never /rosout or /parameter_events without a
subscriber; ``p`` goes to each), the logs, a plot and its CSV, the diagnostics, a lifecycle transition,
the publish form, the palette."""

from __future__ import annotations

import asyncio
import csv
import os
import subprocess
import time

import psutil
import pytest
from helpers.build import BIN
from helpers.graph import graph_env, read_line, roc, start_nodes, stop_all
from helpers.tui import (
    GRAPH,
    live_graph,
    palette_command,
    picture,
    screen_lines,
    screen_name,
    start_mortal,
    start_tui_nodes,
    table,
    until,
    until_screen,
)

from roc.check.expectations import load_checks
from roc.tui.app import RocApp

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def graph(tmp_path_factory):
    runtime = tmp_path_factory.mktemp("runtime")
    with live_graph(graph_env(44, runtime), []) as env:
        processes = start_nodes(GRAPH, env)
        processes.append(start_tui_nodes(env))
        try:
            yield env, processes
        finally:
            stop_all(processes)


def test_nodes_and_topics_side_by_side_with_cpu_rates_and_only_real_problems(graph, tmp_path) -> None:
    env, processes = graph
    (tmp_path / "roc.toml").write_text('[check]\nnodes = ["/talker"]\n\n[[check.topic]]\nname = "/chatter"\n'
                                       'min-rate = 50.0\n\n[[check.topic]]\nname = "/pose"\nmin-rate = 1.0\n')
    mortal = start_mortal(env)

    async def test() -> None:
        app = RocApp(checks=load_checks(tmp_path / "roc.toml"))
        async with app.run_test(size=(120, 35)) as pilot:
            nodes, topics = (lambda: table(app, "#nodes-table").rows_by_key), (lambda: table(app, "#topics-table").rows_by_key)
            await until(pilot, lambda: {"/talker", "/mortal", "/poser", "/managed"} <= set(nodes())
                        and topics().get("/chatter") and topics()["/chatter"].cells[3].endswith("Hz")
                        and nodes()["/talker"].cells[2].endswith("M"), what="nodes, rates, memory")
            screen = "\n".join(screen_lines(app))
            assert "/talker" in screen and "/chatter" in screen  # both lists on the first screen
            talker_pid = processes[0].pid
            usage = app.graph_screen.processes.usage["/talker"]
            assert usage.pid == talker_pid and usage.nodes == 6  # the six nodes of one process
            rss = psutil.Process(talker_pid).memory_info().rss / 1e6
            assert abs(float(nodes()["/talker"].cells[2].rstrip("M")) - rss) < max(10.0, rss * 0.2)
            assert app.graph_screen.processes.usage["/poser"].pid == processes[1].pid
            # the real problems, and none for /rosout or /parameter_events (nobody subscribes to them)
            problems = lambda: [p.text for p in app.graph_screen.problems]  # noqa: E731
            await until(pilot, lambda: any("below the 50 Hz" in p for p in problems()), what="the rate problem")
            await until(pilot, lambda: any(p.startswith("/diagnostics ") for p in problems()),
                        what="the diagnostics' ERROR")  # start_tui_nodes' battery status
            texts = problems()
            assert any(p.startswith("/odd: QoS incompatible (reliability)") for p in texts), texts
            assert "/cmd_vel: no publisher" in texts
            assert not any(p.startswith(("/rosout", "/parameter_events", "/pose", "/talker")) for p in texts), texts
            assert "/diagnostics power: battery: ERROR empty (:diagnostics)" in texts
            assert len(texts) == 4, texts
            assert "4 problems" in str(app.screen.query_one("#problems").render())
            picture(app, "system")
            # a node that dies is a problem, and p goes to it
            stop_all([mortal])
            await until(pilot, lambda: any(p.startswith("/mortal: gone since") for p in problems()), what="/mortal gone")
            assert nodes()["/mortal"].cells[1] == "gone"
            for _ in range(len(problems())):
                await pilot.press("p")
                if table(app, "#nodes-table").selected_key() == "/mortal" and app.focused.id == "nodes-table":
                    break
            else:
                raise AssertionError("p never went to /mortal")
            assert "/mortal: gone since" in str(app.screen.query_one("#problems").render())
            await pilot.press("c")  # forget the nodes gone
            await until(pilot, lambda: "/mortal" not in nodes(), what="/mortal forgotten")
            await pilot.press("p")
            assert app.focused.id in ("topics-table", "nodes-table")
        app = RocApp()
        async with app.run_test(size=(80, 24)) as pilot:
            await until_screen(app, pilot, lambda s: "/chatter" in s and "/chatty_logger" in s, "both lists at 80x24")
            lines = screen_lines(app)
            assert len(lines) <= 24 and max(len(line) for line in lines) <= 80
    try:
        asyncio.run(test())
    finally:
        stop_all([mortal])  # a failing test leaves no node behind (stopped in the test already: a no-op)
    assert os.environ.get("ROS_DOMAIN_ID")  # the app ran in the graph's environment


async def open_node(app, pilot, name: str) -> None:
    await pilot.press("1")
    await until(pilot, lambda: name in table(app, "#nodes-table").rows_by_key, what=name)
    table(app, "#nodes-table").select(name)
    await pilot.press("enter")
    await until(pilot, lambda: screen_name(app) == "NodeScreen", what="the node screen")


def test_logs_of_a_node_filtered_by_level_and_text_paused_and_followed(graph) -> None:
    async def test() -> None:
        app = RocApp()
        async with app.run_test(size=(100, 30)) as pilot:
            await open_node(app, pilot, "/chatty_logger")
            await pilot.press("l")
            await until(pilot, lambda: screen_name(app) == "LogsScreen", what="the logs")
            logs = app.screen
            await until(pilot, lambda: len(logs.visible_lines()) >= 10, what="log lines")
            lines = logs.visible_lines()
            assert all("[chatty_logger]" in line for line in lines), lines[:5]
            assert {"DEBUG", "INFO", "WARN", "ERROR", "FATAL"} <= {line.split()[1] for line in lines}
            picture(app, "logs")
            await pilot.press("l", "l", "l")  # debug -> info -> warn -> error
            assert {line.split()[1] for line in logs.visible_lines()} == {"ERROR", "FATAL"}
            assert "level >= error" in str(app.screen.query_one("#title").render())
            await pilot.press("space")  # pause: lines keep coming, none is written
            written = len(app.screen.query_one("#log").lines)
            count = len(logs.entries)
            await until(pilot, lambda: len(logs.entries) > count + 5, what="more lines while paused")
            assert len(app.screen.query_one("#log").lines) == written and "paused" in str(
                app.screen.query_one("#title").render())
            await pilot.press("space")
            await until(pilot, lambda: len(app.screen.query_one("#log").lines) > written, what="following again")
            await pilot.press("slash")
            await until(pilot, lambda: screen_name(app) == "Prompt")
            number = logs.visible_lines()[-1].split()[-1]
            await pilot.press(*f"fatal {number}", "enter")
            await until(pilot, lambda: logs.visible_lines() and all(f"fatal {number}" in line
                                                                    for line in logs.visible_lines()), what="the text filter")
            assert len(logs.visible_lines()) == 1
            await pilot.press("x")  # filters cleared: every node's lines, the daemon's own none
            await until(pilot, lambda: any("[poser]" in line or "[talker]" in line or "[chatty_logger]" in line
                                           for line in logs.visible_lines()), what="all lines")
    asyncio.run(test())


def test_a_plot_of_two_fields_zoomed_paused_and_saved_as_csv(graph, tmp_path) -> None:
    saved = tmp_path / "pose.csv"

    async def test() -> None:
        app = RocApp()
        async with app.run_test(size=(100, 30)) as pilot:
            await until(pilot, lambda: app.graph_screen.snapshot is not None, what="the graph")
            await palette_command(app, pilot, "plot /pose pose.position.x pose.position.y")
            await until(pilot, lambda: screen_name(app) == "PlotScreen", what="the plot")
            plot = app.screen
            await until(pilot, lambda: all(len(s.times) >= 50 for s in plot.series), what="samples")
            x, y = plot.series
            assert [y.values[i] for i in range(10)] == [2 * v for v in x.values[:10]]  # one message, both fields
            assert x.values[1:11] == [v + 1 for v in x.values[:10]]  # every message: x counts them
            assert plot.lost == 0
            picture(app, "plot")
            await pilot.press("plus")
            assert plot.window == 5
            await pilot.press("minus", "minus")
            assert plot.window == 30
            await pilot.press("space")
            frozen = plot.paused_at
            await until(pilot, lambda: plot.latest > frozen + 0.5, what="samples while paused")
            assert plot.paused_at == frozen and "paused" in str(app.screen.query_one("#title").render())
            await pilot.press("s")
            await until(pilot, lambda: screen_name(app) == "Prompt")
            app.screen.query_one("#prompt").value = str(saved)
            await pilot.press("enter")
            await until(pilot, saved.exists, what="the CSV file")
    asyncio.run(test())
    rows = list(csv.reader(saved.open()))
    assert rows[0] == ["time", "/pose pose.position.x", "/pose pose.position.y"]
    assert len(rows) > 50 and all(float(r[2]) == 2 * float(r[1]) for r in rows[1:])
    times = [float(r[0]) for r in rows[1:]]
    assert times == sorted(times) and abs(times[-1] - time.time()) < 120


def test_diagnostics_grouped_worst_first_with_history(graph) -> None:
    async def test() -> None:
        app = RocApp()
        async with app.run_test(size=(100, 30)) as pilot:
            await palette_command(app, pilot, "diagnostics")
            await until(pilot, lambda: screen_name(app) == "DiagnosticsScreen", what="the diagnostics")
            statuses = lambda: app.screen.query_one("#statuses").rows_by_key  # noqa: E731
            await until(pilot, lambda: len(statuses()) == 3, what="three statuses")
            screen = app.screen
            first = lambda: next(iter(statuses().values())).cells  # noqa: E731
            await until(pilot, lambda: first()[:3] == ("ERROR", "bms-7", "power: battery"), what="the battery's error")
            rows = [row.cells for row in statuses().values()]
            assert rows[0][:3] == ("ERROR", "bms-7", "power: battery"), rows
            assert [r[1] for r in rows] == ["bms-7", "lidar-2", "motor-1"]  # error, stale, ok
            picture(app, "diagnostics")
            table(app, "#statuses").select("bms-7\tpower: battery")
            await until(pilot, lambda: len(screen.statuses["bms-7\tpower: battery"].history) >= 3, what="history")
            await pilot.press("enter")
            await until(pilot, lambda: screen_name(app) == "TextViewer", what="the status's details")
            details = app.screen.query_one("#viewer").text
            assert "percent: 10" in details or "percent: 50" in details or "percent: 90" in details
            history = details.split("history")[1]
            assert "ERROR  empty" in history and "WARN   low" in history, details
    asyncio.run(test())


def test_lifecycle_transition_from_the_node_screen(graph) -> None:
    env, _ = graph

    async def test() -> None:
        app = RocApp()
        async with app.run_test(size=(100, 30)) as pilot:
            await open_node(app, pilot, "/managed")
            lifecycle = lambda: str(app.screen.query_one("#lifecycle").render())  # noqa: E731
            await until(pilot, lambda: "unconfigured [1]" in lifecycle(), what="the state")
            assert "configure" in lifecycle()
            await pilot.press("t")
            await until(pilot, lambda: screen_name(app) == "Prompt")
            app.screen.query_one("#prompt").value = "configure"
            await pilot.press("enter")
            await until(pilot, lambda: "inactive [2]" in lifecycle(), what="inactive")
            picture(app, "lifecycle")
    asyncio.run(test())
    assert roc("lifecycle", "get", "/managed", env=env).stdout.strip() == "inactive [2]"


def test_publish_once_and_at_a_rate_from_the_form(graph) -> None:
    env, _ = graph
    listener = subprocess.Popen([str(BIN / "roc"), "topic", "echo", "/cmd_vel", "--field", "linear.x"], env=env,
                                stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)

    async def test() -> None:
        app = RocApp()
        async with app.run_test(size=(100, 30)) as pilot:
            await until(pilot, lambda: app.graph_screen.snapshot is not None, what="the graph")
            await palette_command(app, pilot, "publish /cmd_vel")
            await until(pilot, lambda: screen_name(app) == "PublishScreen", what="the form")
            editor = app.screen.query_one("#editor")
            assert "linear:" in editor.text and "x: 0.0" in editor.text  # the prototype of geometry_msgs/Twist
            editor.text = "linear: {x: 1.5}\n"
            values: list[str] = []
            for _ in range(10):  # once: again until the echo, started with the test, has matched the form's publisher
                await pilot.press("ctrl+s")
                values += [line for line in (read_line(listener, 3) for _ in range(3)) if line and line[0].isdigit()]
                if values:
                    break
            assert values == ["1.5\n"]
            editor.text = "linear: {x: 2.5}\n"
            await pilot.press("ctrl+r")
            await until(pilot, lambda: screen_name(app) == "Prompt")
            app.screen.query_one("#prompt").value = "20"
            await pilot.press("enter")
            lines = [read_line(listener, 30) for _ in range(6)]
            assert lines.count("2.5\n") >= 3, lines
            await pilot.press("ctrl+t")
            await until(pilot, lambda: "stopped" in str(app.screen.query_one("#output").render()), what="stopped")
            while read_line(listener, 1.5) is not None:  # what was on its way
                pass
            assert read_line(listener, 1.5) is None  # nothing published since
    try:
        asyncio.run(test())
    finally:
        stop_all([listener])
