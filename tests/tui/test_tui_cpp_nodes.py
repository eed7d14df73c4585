"""roc tui's nodes list with real C++ nodes (the C++ stack built by roc, tests/helpers/cpp.py): each
node's process, CPU and memory, found from its participant as for rclpy nodes; and a C++ managed node
(the lifecycle demo's lc_talker) walked through its states from the node screen."""

from __future__ import annotations

import asyncio
import subprocess

import psutil
import pytest
from helpers.build import stop_process
from helpers.cpp import require_stack, sourced
from helpers.graph import graph_env, roc
from helpers.tui import live_graph, screen_name, table, until

from roc.tui.app import RocApp

pytestmark = [pytest.mark.slow, pytest.mark.cpp]

SLOT = 42


@pytest.fixture(scope="module")
def graph(tmp_path_factory):
    install = require_stack()
    env = sourced(graph_env(SLOT, tmp_path_factory.mktemp("runtime")))
    with live_graph(env, []) as env:
        programs = [install / "demo_nodes_cpp" / "lib" / "demo_nodes_cpp" / "talker",
                    install / "lifecycle" / "lib" / "lifecycle" / "lifecycle_talker"]
        processes = [subprocess.Popen([str(program)], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                     for program in programs]
        try:
            yield env, processes
        finally:
            for process in processes:
                stop_process(process)


def test_the_nodes_list_shows_each_cpp_node_s_process_cpu_and_memory(graph) -> None:
    env, processes = graph

    async def test() -> None:
        app = RocApp()
        async with app.run_test(size=(120, 35)) as pilot:
            nodes = lambda: table(app, "#nodes-table").rows_by_key  # noqa: E731
            await until(pilot, lambda: {"/talker", "/lc_talker"} <= set(nodes())
                        and nodes()["/talker"].cells[2].endswith("M") and nodes()["/lc_talker"].cells[2].endswith("M"),
                        what="the C++ nodes with their memory")
            for name, process in (("/talker", processes[0]), ("/lc_talker", processes[1])):
                usage = app.graph_screen.processes.usage[name]
                assert usage.pid == process.pid and usage.nodes == 1
                assert nodes()[name].cells[1].endswith("%")
                rss = psutil.Process(process.pid).memory_info().rss / 1e6
                assert abs(float(nodes()[name].cells[2].rstrip("M")) - rss) < max(10.0, rss * 0.2)
    asyncio.run(test())


def test_a_cpp_managed_node_is_configured_and_activated_from_the_node_screen(graph) -> None:
    env, _ = graph
    assert roc("lifecycle", "get", "/lc_talker", env=env).stdout == "unconfigured [1]\n"

    async def test() -> None:
        app = RocApp()
        async with app.run_test(size=(100, 30)) as pilot:
            await pilot.press("1")
            await until(pilot, lambda: "/lc_talker" in table(app, "#nodes-table").rows_by_key, what="/lc_talker")
            table(app, "#nodes-table").select("/lc_talker")
            await pilot.press("enter")
            await until(pilot, lambda: screen_name(app) == "NodeScreen", what="the node screen")
            lifecycle = lambda: str(app.screen.query_one("#lifecycle").render())  # noqa: E731
            await until(pilot, lambda: "unconfigured [1]" in lifecycle(), what="the state")
            for transition, state in (("configure", "inactive [2]"), ("activate", "active [3]")):
                await pilot.press("t")
                await until(pilot, lambda: screen_name(app) == "Prompt")
                app.screen.query_one("#prompt").value = transition
                await pilot.press("enter")
                await until(pilot, lambda state=state: state in lifecycle(), what=state)
    asyncio.run(test())
    assert roc("lifecycle", "get", "/lc_talker", env=env).stdout == "active [3]\n"
    # the C++ node publishes once active, as the demo does
    echo = roc("topic", "echo", "/lifecycle_chatter", "--once", env=env, timeout=30)
    assert echo.stdout.startswith("data: 'Lifecycle HelloWorld #"), echo.stderr
    deactivated = roc("lifecycle", "set", "/lc_talker", "deactivate", env=env)
    assert deactivated.stdout == "Transitioning successful\n", deactivated.stderr
    assert roc("lifecycle", "get", "/lc_talker", env=env).stdout == "inactive [2]\n"
