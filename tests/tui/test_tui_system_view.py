"""roc tui's first screen on a live graph (Textual's pilot, the real daemon): nodes with their process's
CPU and memory beside the topics with their rates, at 100x30 and 80x24; a problems line that counts only
real problems (a QoS mismatch, a subscriber nobody publishes to, a node that died, a rate below roc.toml's
expectation), never /rosout or /parameter_events without a subscriber; ``p`` goes to each."""

from __future__ import annotations

import asyncio
import os

import psutil
import pytest
from graph_helpers import graph_env, start_nodes, stop_all
from tui_helpers import GRAPH, live_graph, screen_lines, start_mortal, start_tui_nodes, table, until, until_screen

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
        async with app.run_test(size=(100, 30)) as pilot:
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
            texts = problems()
            assert any(p.startswith("/odd: QoS incompatible (reliability)") for p in texts), texts
            assert "/cmd_vel: no publisher" in texts
            assert not any(p.startswith(("/rosout", "/parameter_events", "/pose", "/talker")) for p in texts), texts
            assert len(texts) == 3, texts
            assert "3 problems" in str(app.screen.query_one("#problems").render())
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
    asyncio.run(test())
    assert os.environ.get("ROS_DOMAIN_ID")  # the app ran in the graph's environment
