"""roc tui's lists driven by Textual's pilot on data (no daemon, no ROS): the keys that move in a list, and
a key that acts on a row acting on the row the cursor is on."""

from __future__ import annotations

import asyncio
import re

import pytest
from helpers.tui import DataFeed, launch_rows, screen_lines, screen_name, table, text_of, until

from roc.tui.app import RocApp
from roc.tui.model import Row
from roc.tui.widgets import ListTable

EMPTY = {"nodes": [], "topics": [], "services": [], "actions": []}

def test_home_and_end_go_to_the_first_and_the_last_row() -> None:
    """Not sideways: DataTable's Home and End scroll a row cursor's table to its first or last column."""
    from textual.app import App, ComposeResult

    class OneTable(App):
        def compose(self) -> ComposeResult:
            yield ListTable(("name", "wide"))

    async def test() -> None:
        app = OneTable()
        async with app.run_test(size=(40, 12)) as pilot:
            rows = app.query_one(ListTable)
            rows.show([Row(f"k{i}", (f"k{i}", "x" * 80)) for i in range(30)])
            rows.focus()
            await until(pilot, lambda: rows.row_count == 30, what="every row")
            await pilot.press("end")
            assert rows.selected_key() == "k29" and rows.scroll_x == 0
            await pilot.press("home")
            assert rows.selected_key() == "k0"
            await pilot.press("right")  # sideways with the arrows
            assert rows.scroll_x > 0 and rows.selected_key() == "k0"
    asyncio.run(test())

class Run:
    """A ``roc launch`` run as roc.launch.status.runs gives it: its status, and the requests sent to it."""

    def __init__(self) -> None:
        self.requests: list[tuple[str, str]] = []

    def request(self, method: str, process: str) -> None:
        self.requests.append((method, process))

    def answer(self) -> dict:
        return {"title": "roc launch pair", "pid": 4242, "restartable": True, "processes": [
            {"name": name, "host": "", "pid": pid, "state": "running", "detail": "", "restarts": 0,
             "last_line": "x" * 120} for name, pid in (("listener", 11), ("talker", 12))]}

def test_end_then_restart_restarts_the_last_process(monkeypatch) -> None:
    """The user's case: End, then R in the launches view restarted the first row, not the last one shown
    selected."""
    run = Run()
    monkeypatch.setattr("roc.launch.status.runs", lambda: [(run, run.answer())])

    async def test() -> None:
        app = RocApp(feed=DataFeed(EMPTY), workspace=None)
        async with app.run_test(size=(120, 35)) as pilot:
            app.open("launch")
            await until(pilot, lambda: screen_name(app) == "LaunchScreen" and bool(app.screen.query("#processes"))
                        and {"listener", "talker"} <= set(launch_rows(app)), what="the launch view")
            assert table(app, "#processes").selected_key() == "4242:listener"
            await pilot.press("end", "R")
            await until(pilot, lambda: bool(run.requests), what="the restart asked")
            assert run.requests == [("restart", "talker")]
    asyncio.run(test())


async def palette_entries(app, pilot, typed: str) -> list[str]:
    """The palette's entries once ``typed`` is in it."""
    from textual.command import CommandInput, CommandList, CommandPalette

    await pilot.press("colon")
    await until(pilot, lambda: isinstance(app.screen, CommandPalette) and isinstance(app.focused, CommandInput),
                what="the command palette")
    await pilot.press(*typed)
    palette = app.screen
    await until(pilot, lambda: palette.query_one(CommandInput).value == typed
                and palette.query_one(CommandList).option_count > 0, what="the palette's entries")
    await pilot.pause(0.5)  # the search's last entries
    entries = palette.query_one(CommandList)
    return [str(entries.get_option_at_index(i).prompt).split("\n")[0] for i in range(entries.option_count)]


def test_the_palette_lists_a_command_without_unrelated_names() -> None:
    """Typing ``logs`` gave the command, then services whose names hold the letters l, o, g, s in order."""
    services = [{"name": f"/{node}/{service}", "types": ["rcl_interfaces/srv/X"]}
                for node in ("talker", "listener") for service in ("get_logger_levels", "set_logger_levels",
                                                                    "list_parameters", "get_parameters")]
    snapshot = {**EMPTY, "nodes": [{"name": "logs_keeper", "namespace": "/", "full_name": "/logs_keeper"}],
                "services": services}

    async def test() -> None:
        app = RocApp(feed=DataFeed(snapshot))
        async with app.run_test(size=(120, 35)) as pilot:
            await until(pilot, lambda: app.graph_screen.snapshot is not None, what="the graph")
            assert await palette_entries(app, pilot, "logs") == ["logs", "node /logs_keeper"]
            await pilot.press("escape")
            await until(pilot, lambda: screen_name(app) == "GraphScreen", what="the palette closed")
            assert sorted(await palette_entries(app, pilot, "set_logger")) == [
                "service /listener/set_logger_levels", "service /talker/set_logger_levels"]
    asyncio.run(test())


LONG_NAMES = {
    "nodes": [{"name": name, "namespace": "/warehouse/robot_17", "full_name": f"/warehouse/robot_17/{name}"}
              for name in ("navigation_controller_server", "behavior_tree_navigator", "talker")],
    "topics": [{"name": name, "types": [type_name], "publishers": 1, "subscribers": 1}
               for name, type_name in (("/warehouse/robot_17/local_costmap/published_footprint",
                                        "geometry_msgs/msg/PolygonStamped"),
                                       ("/chatter", "std_msgs/msg/String"), ("/parameter_events",
                                                                            "rcl_interfaces/msg/ParameterEvent"))],
    "services": [], "actions": []}


@pytest.mark.parametrize("size", [(120, 35), (170, 35), (80, 24)])
def test_the_first_screen_shows_every_column_the_manual_promises(size: tuple[int, int]) -> None:
    """Long names are cut in the middle, types first without their msg/, so that the memory and type
    columns stay on the screen (mem was out of sight at 120 and 170 columns, the type cut at
    std_msgs/msg/Str)."""
    async def test() -> None:
        app = RocApp(feed=DataFeed(LONG_NAMES))
        async with app.run_test(size=size) as pilot:
            await until(pilot, lambda: len(table(app, "#topics-table").rows_by_key) == 3
                        and len(table(app, "#nodes-table").rows_by_key) == 3, what="the lists")
            await pilot.pause(0.3)
            lines = screen_lines(app)
            screen = "\n".join(lines)
            headers = [line for line in lines if " node " in line or " topic " in line]
            for column in ("node", "cpu", "mem", "topic", "pub", "sub", "rate", "bandwidth", "type"):
                assert any(re.search(rf"\b{column}\b", line) for line in headers), f"{column}:\n{screen}"
            chatter = next(line for line in lines if "/chatter" in line)
            assert re.search(r"std_msgs/(msg/)?String\b", chatter), screen
            assert "/wareh" in screen and "…" in screen  # a long name with its ends
            assert table(app, "#nodes-table").rows_by_key["/warehouse/robot_17/talker"].cells[0] \
                == "/warehouse/robot_17/talker"  # the rows keep the whole name (the filter, Enter)
    asyncio.run(test())


def test_names_are_cut_in_the_middle_and_types_first_lose_their_msg() -> None:
    from roc.tui.model import cut_widths, shorten

    assert shorten("/warehouse/robot_17/talker", 12) == "/wareh…alker"
    assert shorten("std_msgs/msg/String", 16, type_name=True) == "std_msgs/String"
    assert shorten("geometry_msgs/msg/PolygonStamped", 16, type_name=True) == "geometry…Stamped"
    assert shorten("/chatter", 12) == "/chatter"
    assert cut_widths(40, [10, 20]) is None  # they fit
    assert cut_widths(40, [10, 50]) == 30  # the narrow one kept whole
    assert cut_widths(40, [30, 50]) == 20
    assert cut_widths(10, [30, 50]) == 8  # never narrower: the list scrolls sideways then


def chatter_endpoint(node: str, side: str, history: str, depth: int) -> dict:
    return {"node_name": node, "node_namespace": "/", "topic_type": "std_msgs/msg/String", "topic_type_hash": "h",
            "endpoint_type": side, "gid": f"01.0f.{node}", "qos": {
                "reliability": "RELIABLE", "history": history, "depth": depth, "durability": "VOLATILE",
                "lifespan_ns": None, "deadline_ns": 250_000_000, "liveliness": "AUTOMATIC",
                "liveliness_lease_duration_ns": None}}


def test_the_topic_screen_shows_the_qos_as_ros2_topic_info_v_and_says_why_history_is_unknown() -> None:
    """Discovered endpoints come with history UNKNOWN and depth 0 (rmw: DDS discovery does not carry
    them); the screen showed a bare UNKNOWN, and no lifespan nor liveliness."""
    info = {"types": ["std_msgs/msg/String"],
            "publishers": [chatter_endpoint("talker", "PUBLISHER", "UNKNOWN", 0)],
            "subscribers": [chatter_endpoint("listener", "SUBSCRIPTION", "KEEP_LAST", 7)]}

    async def test() -> None:
        app = RocApp(feed=DataFeed(EMPTY, {"topic_endpoints": info}))
        async with app.run_test(size=(80, 24)) as pilot:
            app.open("topic", "/chatter")
            await until(pilot, lambda: screen_name(app) == "TopicScreen" and bool(app.screen.query("#endpoints"))
                        and len(table(app, "#endpoints").rows_by_key) == 2, what="the endpoints")
            rows = {row.cells[0]: row.cells for row in table(app, "#endpoints").rows_by_key.values()}
            assert rows["/talker"][4:] == ("UNKNOWN", "250 ms") and rows["/listener"][4] == "KEEP_LAST (7)"
            table(app, "#endpoints").select("01.0f.talker")
            await until(pilot, lambda: "not carried by DDS discovery" in text_of(app, "#qos"), what="why")
            assert "ros2 topic info -v: same" in text_of(app, "#qos")
            assert "lifespan Infinite, liveliness AUTOMATIC (lease Infinite), GID 01.0f.talker" in text_of(app, "#qos")
            table(app, "#endpoints").select("01.0f.listener")
            await until(pilot, lambda: "GID 01.0f.listener" in text_of(app, "#qos"), what="the listener's QoS")
            assert "UNKNOWN" not in text_of(app, "#qos")
    asyncio.run(test())
