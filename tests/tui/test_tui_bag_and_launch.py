"""roc tui's bag and launch views (Textual's pilot): rosbag2's own talker bag opened with ``--bag``, its
topics counted, its messages stepped through (decoded by the daemon) and played on the live graph with
roc bag play's own controls; a ``roc launch`` of a roc.toml system found through its status socket, a
process's output shown, one process restarted and one stopped."""

from __future__ import annotations

import asyncio
import subprocess

import pytest
from helpers.build import BIN
from helpers.graph import read_line, stop_all
from helpers.launch import demo_env, roc_launch
from helpers.oracles import SHARED
from helpers.tui import launch_rows, live_graph, open_launches, picture, screen_name, table, until

from roc.tui.app import RocApp

pytestmark = pytest.mark.slow
TALKER_BAG = SHARED / "reference" / "rosbag2" / "rosbag2_py" / "test" / "resources" / "mcap" / "talker"
SYSTEM = """
[launch.pair]
[[launch.pair.process]]
package = "roc_launch_demo"
executable = "talker"
parameters = { rate = 5.0 }

[[launch.pair.process]]
package = "roc_launch_demo"
executable = "listener"
"""


def test_a_bag_opened_stepped_through_and_played_on_the_graph(tmp_path) -> None:
    if not TALKER_BAG.is_dir():
        pytest.fail(f"rosbag2's reference bags are missing at {TALKER_BAG}")
    from helpers.graph import graph_env

    with live_graph(graph_env(45, tmp_path / "runtime"), []) as env:
        (tmp_path / "runtime").mkdir(exist_ok=True)
        listener = subprocess.Popen([str(BIN / "roc"), "topic", "echo", "/topic", "std_msgs/msg/String", "--field", "data"], env=env,
                                    stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)

        async def test() -> None:
            app = RocApp(bag=str(TALKER_BAG))
            async with app.run_test(size=(100, 30)) as pilot:
                await until(pilot, lambda: screen_name(app) == "BagScreen", what="the bag")
                topics = table(app, "#topics").rows_by_key
                assert topics["/topic"].cells[1:3] == ("std_msgs/msg/String", "10")
                assert topics["/rosout"].cells[2] == "10" and topics["/topic"].cells[3].endswith("Hz")
                table(app, "#topics").select("/topic")
                await pilot.press("enter")
                message = lambda: str(app.screen.query_one("#message").render())  # noqa: E731
                await until(pilot, lambda: "data:" in message(), what="the first message")
                first = message()
                await pilot.press("n")
                await until(pilot, lambda: "data:" in message() and message() != first, what="the second message")
                assert "message 2 of 10" in str(app.screen.query_one("#message-title").render())
                picture(app, "bag")
                await pilot.press("P")
                heard = [read_line(listener, 20) for _ in range(2)]
                assert any(line and line.startswith("Hello, world!") for line in heard), heard
                await pilot.press("space")
                playback = app.screen.playback
                await until(pilot, lambda: any("Paused" in line for line in playback.lines), what="paused")
                await pilot.press("x")
                await until(pilot, lambda: not playback.running(), what="the playback stopped")
        try:
            asyncio.run(test())
        finally:
            stop_all([listener])


def test_a_launch_run_shown_restarted_and_stopped(tmp_path, launch_demo_prefix) -> None:
    (tmp_path / "runtime").mkdir()
    env = demo_env(46, tmp_path / "runtime", launch_demo_prefix)
    (tmp_path / "roc.toml").write_text(SYSTEM)
    launcher = roc_launch("pair", env=env, log=tmp_path / "launch.log")
    try:
        with live_graph(env, []):
            async def test() -> None:
                app = RocApp()
                async with app.run_test(size=(100, 30)) as pilot:
                    await open_launches(app, pilot, {"talker", "listener"})
                    talker_pid = launch_rows(app)["talker"].cells[2]
                    picture(app, "launch")
                    assert launch_rows(app)["talker"].cells[1] == f"roc launch pair [{launcher.pid}]"
                    processes = table(app, "#processes")
                    processes.select(next(k for k, r in processes.rows_by_key.items() if r.cells[0] == "listener"))
                    await pilot.press("enter")
                    await until(pilot, lambda: screen_name(app) == "LogsScreen", what="the output")
                    await until(pilot, lambda: any("heard:" in line for line in app.screen.visible_lines()),
                                what="the listener's output")
                    await pilot.press("escape")
                    processes.select(next(k for k, r in processes.rows_by_key.items() if r.cells[0] == "talker"))
                    await pilot.press("R")
                    await until(pilot, lambda: launch_rows(app)["talker"].cells[4] == "1" and launch_rows(app)["talker"].cells[2] != talker_pid
                                and launch_rows(app)["talker"].cells[3] == "running", what="the talker restarted")
                    processes.select(next(k for k, r in processes.rows_by_key.items() if r.cells[0] == "listener"))
                    await pilot.press("s")
                    await until(pilot, lambda: launch_rows(app)["listener"].cells[3] != "running", what="the listener stopped")
            asyncio.run(test())
        assert "talker: restart asked by roc tui" in launcher.output()
    finally:
        launcher.stop()
