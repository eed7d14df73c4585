"""The array, scan and grid views (rosight's 1-D array plot, ros2_diag_tui's LiDAR and map views) and
the nodes list's pid column and sorting: offline on messages given as data, and once live with an rclpy
publisher of a LaserScan and an OccupancyGrid."""

from __future__ import annotations

import asyncio
import math
import subprocess
import sys

import pytest
from helpers.graph import graph_env
from helpers.tui import DataFeed, live_graph, screen_name, table, text_of, until

from roc.tui.app import RocApp
from roc.tui.model import Row, cell_number, node_rows, sorted_rows
from roc.tui.plotting import array_at, scan_points, square_limits
from roc.tui.processes import Usage

SCAN = {"header": {"frame_id": "laser"}, "angle_min": -math.pi / 2, "angle_max": math.pi / 2,
        "angle_increment": math.pi / 2, "range_min": 0.1, "range_max": 10.0,
        "ranges": [2.0, float("inf"), 4.0], "intensities": []}
GRID = {"header": {"frame_id": "map"}, "info": {"width": 4, "height": 2, "resolution": 0.5},
        "data": [0, 0, 100, -1, 0, 0, 0, 0]}
SNAPSHOT = {"nodes": [{"name": "lidar", "namespace": "/", "full_name": "/lidar"}],
            "topics": [{"name": "/scan", "types": ["sensor_msgs/msg/LaserScan"], "publishers": 1, "subscribers": 0},
                       {"name": "/map", "types": ["nav_msgs/msg/OccupancyGrid"], "publishers": 2, "subscribers": 1}],
            "services": [], "actions": []}


class EchoFeed(DataFeed):
    """The echo stream of each topic: its type, then its message, again and again."""

    def stream(self, method, params, stop):
        if method != "echo":
            return
        value, type_name = {"/scan": (SCAN, "sensor_msgs/msg/LaserScan"), "/map": (GRID, "nav_msgs/msg/OccupancyGrid")}[
            params["topic"]]
        yield {"event": "subscribed", "type": type_name}
        while not stop():
            yield {"event": "messages", "messages": [{"data": "", "value": value}]}
            import time
            time.sleep(0.1)


def test_arrays_scans_cells_and_sorting_as_plain_data() -> None:
    assert array_at(SCAN, "ranges") == [2.0, math.inf, 4.0] and array_at(SCAN, "angle_min") is None
    xs, ys = scan_points(SCAN)  # the inf is no return; -90 degrees is to the right (y < 0)
    assert [round(x, 6) for x in xs] == [0.0, 0.0] and [round(y, 6) for y in ys] == [-2.0, 4.0]
    assert square_limits(1.0, 40, 10) == (2.0, 1.0)  # 80 dots across, 40 up: twice as wide
    assert [cell_number(t) for t in ("12%", "45M", "1.2 kHz", "1.50 KB/s", "remote", "", "4242")] == [
        12.0, 45e6, 1200.0, 1500.0, None, None, 4242.0]
    rows = [Row("a", ("/a", "3%", "")), Row("b", ("/b", "remote", "")), Row("c", ("/c", "40%", "")),
            Row("d", ("/d", "", ""))]
    assert [r.key for r in sorted_rows(rows, 1, descending=True)] == ["c", "a", "b", "d"]  # top's order
    assert [r.key for r in sorted_rows(rows, 1, descending=False)] == ["a", "c", "b", "d"]
    usage = {"/lidar": Usage(pid=4242, cpu=3.0, rss=45_000_000)}
    assert node_rows(SNAPSHOT, usage=usage)[0].cells == ("/lidar", "3%", "45M", "4242")  # pid after mem


@pytest.mark.slow  # a few seconds: three views drawn
def test_scan_grid_and_array_views_and_a_sorted_list() -> None:
    async def test() -> None:
        app = RocApp(EchoFeed(SNAPSHOT))
        async with app.run_test(size=(100, 30)) as pilot:
            await until(pilot, lambda: app.graph_screen is not None and app.graph_screen.snapshot is not None,
                        what="the first snapshot")
            topics = table(app, "#topics-table")
            await until(pilot, lambda: len(topics.rows_by_key) == 2, what="the topics")
            await pilot.press("2", "s")  # by topic name, from A
            await until(pilot, lambda: list(topics.rows_by_key) == ["/map", "/scan"], what="sorted by name")
            await pilot.press("s")  # by publishers, most first
            await until(pilot, lambda: topics.sort_column == 1 and list(topics.rows_by_key) == ["/map", "/scan"],
                        what="sorted by publishers")
            await pilot.press("S")
            await until(pilot, lambda: list(topics.rows_by_key) == ["/scan", "/map"], what="the other way")
            assert str(topics.columns[topics.ordered_columns[2].key].label) == "pub ▲"
            for view, name, said in (("scan", "/scan", "2 returns of 3, out to 4.00 m"),
                                     ("grid", "/map", "4 x 2 cells of 0.5 m, frame map"),
                                     ("array", "/scan ranges", "3 values, 2 to 4")):
                app.open(view, name)
                await until(pilot, lambda said=said: screen_name(app) == "SensorScreen"
                            and bool(app.screen.query("#title")) and said in text_of(app, "#title"), timeout=10, what=f"the {view} view")
                if view == "grid":
                    lines = str(app.screen.query_one("#picture").render()).splitlines()
                    assert lines and all(set(line.strip()) <= {"▀"} for line in lines), lines
                await pilot.press("escape")
                await until(pilot, lambda: app.screen is app.graph_screen, what="back")
            app.open("scan", "/map")
            await until(pilot, lambda: bool(app.screen.query("#title")) and "nav_msgs/msg/OccupancyGrid is no "
                        "sensor_msgs/msg/LaserScan" in text_of(app, "#title"), what="the wrong type said")
    asyncio.run(test())


PUBLISHER = """
import math, sys, rclpy
from rclpy.qos import QoSProfile, DurabilityPolicy
from nav_msgs.msg import OccupancyGrid
from sensor_msgs.msg import LaserScan
rclpy.init()
node = rclpy.create_node("lidar")
scans = node.create_publisher(LaserScan, "scan", 10)
grids = node.create_publisher(OccupancyGrid, "map", QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL))
scan = LaserScan(angle_min=-math.pi, angle_max=math.pi, angle_increment=2 * math.pi / 360, range_min=0.1,
                 range_max=20.0, ranges=[3.0] * 360)
scan.header.frame_id = "laser"
grid = OccupancyGrid(data=[0] * 50 + [100] * 50)
grid.header.frame_id = "map"
grid.info.width, grid.info.height, grid.info.resolution = 10, 10, 0.25
grids.publish(grid)
node.create_timer(0.1, lambda: scans.publish(scan))
print("ready", flush=True)
rclpy.spin(node)
"""


@pytest.mark.slow  # a live graph
def test_a_live_laserscan_and_occupancy_grid_drawn(tmp_path) -> None:
    async def test(env) -> None:
        app = RocApp()
        async with app.run_test(size=(100, 30)) as pilot:
            for view, name, said in (("scan", "/scan", "360 returns of 360, out to 3.00 m"),
                                     ("grid", "/map", "10 x 10 cells of 0.25 m, frame map"),
                                     ("array", "/scan ranges", "360 values, 3 to 3")):
                app.open(view, name)
                await until(pilot, lambda said=said: screen_name(app) == "SensorScreen"
                            and bool(app.screen.query("#title")) and said in text_of(app, "#title"), timeout=30, what=f"the {view} view")
                await pilot.press("escape")
                await until(pilot, lambda: app.screen is app.graph_screen, what="back")

    with live_graph(graph_env(56, tmp_path), []) as env:
        publisher = subprocess.Popen([sys.executable, "-c", PUBLISHER], env=env, stdout=subprocess.PIPE, text=True)
        try:
            assert publisher.stdout.readline().strip() == "ready"
            asyncio.run(test(env))
        finally:
            publisher.terminate()
            publisher.wait(10)
