"""A topic: its endpoints with their QoS (the one under the cursor's in full, as ros2 topic info -v) and
the problems between them, its rate and bandwidth (as ``roc topic hz`` and ``bw`` measure them), and a
live echo of its latest message: ``p`` pauses it, ``f`` shows one field, ``i`` draws an image, a
LaserScan or an OccupancyGrid."""

from __future__ import annotations

import time
from typing import Any

from rich.text import Text
from textual import work
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import VerticalScroll
from textual.screen import Screen
from textual.widgets import DataTable, Footer, Static
from textual.worker import get_current_worker

from roc.cli.options import DEFAULT_TRUNCATE_LENGTH
from roc.errors import RocError
from roc.ros.rates import Sample, Window
from roc.tui.model import (
    TOPIC_WINDOW,
    Row,
    bandwidth_text,
    endpoint_cells,
    endpoint_detail,
    rate_text,
    shown_endpoints,
)
from roc.tui.problems import topic_diagnoses
from roc.tui.widgets import ListTable, Prompt, host

ECHO_SECONDS = 0.25  # the echo pane shows the latest message at most this often


def cdr_size(data: str) -> int:
    """The size of base64 CDR once decoded."""
    return len(data) * 3 // 4 - data[-2:].count("=")


def stats_text(window: Window) -> str:
    rate, bandwidth = window.rate(), window.bandwidth()
    if rate is None or bandwidth is None:
        return "rate: waiting for messages"
    return (f"rate {rate_text(rate['rate'])} (min {rate['min']:.3f} s, max {rate['max']:.3f} s, std dev "
            f"{rate['std_dev']:.5f} s, window {rate['window']})  "
            f"bandwidth {bandwidth_text(bandwidth['bytes_per_second'])}  "
            f"lost {'unknown' if window.known_lost() is None else window.lost}")


class TopicScreen(Screen):
    BINDINGS = [
        Binding("escape", "app.pop_screen", "back"),
        Binding("p,space", "pause", "pause/resume echo"),
        Binding("f", "field", "field"),
        Binding("g", "plot", "plot a numeric field"),
        Binding("u", "publish", "publish on the topic"),
        Binding("i", "image", "the image, LaserScan or OccupancyGrid drawn"),
    ]
    DEFAULT_CSS = """
    TopicScreen #title { height: 1; background: $primary; }
    TopicScreen #endpoints { height: auto; max-height: 8; }
    TopicScreen #qos { height: auto; color: $text-muted; }
    TopicScreen #problems { height: auto; color: $error; }
    TopicScreen #stats { height: auto; }
    TopicScreen #echo-title { height: 1; background: $boost; }
    TopicScreen VerticalScroll { height: 1fr; }
    """

    def __init__(self, topic: str) -> None:
        super().__init__()
        self.topic = topic
        self.window = Window(TOPIC_WINDOW)
        self.type_name: str | None = None
        self.latest: dict[str, Any] | None = None  # the last message event entry
        self.count = 0
        self.shown: dict[str, Any] | None = None  # the message the echo pane shows (kept while paused)
        self.drawn = -1  # its number
        self.paused = False
        self.field = ""
        self.endpoints: dict[str, dict[str, Any]] = {}  # gid -> the endpoint (roc.ros.graph's dict)

    def compose(self) -> ComposeResult:
        yield Static(Text(f"topic {self.topic}", style="bold"), id="title")
        yield ListTable(("node", "side", "reliability", "durability", "history", "deadline"), id="endpoints",
                        cut_columns=("node",))
        yield Static("", id="qos")
        yield Static("", id="problems")
        yield Static("rate: subscribing...", id="stats")
        yield Static("", id="echo-title")
        with VerticalScroll():
            yield Static("", id="echo")
        yield Footer()

    def on_mount(self) -> None:
        self.query_one("#endpoints").focus()
        self.load_endpoints()
        self.echo()
        self.set_interval(ECHO_SECONDS, self.draw_echo)
        self.set_interval(1.0, self.draw_stats)
        self.set_interval(2.0, self.load_endpoints)

    @work(thread=True, exclusive=True, group="endpoints")
    def load_endpoints(self) -> None:
        try:
            info = host(self).feed.query("topic_endpoints", {"topic": self.topic})
        except RocError as error:
            self.app.call_from_thread(self.query_one("#problems", Static).update, str(error))
            return
        self.app.call_from_thread(self.show_endpoints, info)

    def show_endpoints(self, info: dict[str, Any]) -> None:
        info = {**info, **shown_endpoints(info)}
        self.endpoints = {endpoint["gid"]: endpoint for endpoint in info["publishers"] + info["subscribers"]}
        self.query_one("#endpoints", ListTable).show(
            [Row(gid, endpoint_cells(endpoint)) for gid, endpoint in self.endpoints.items()])
        self.show_qos()
        problems = topic_diagnoses({**info, "publishers": len(info["publishers"]),
                                    "subscribers": len(info["subscribers"]), "endpoints": info})
        self.query_one("#problems", Static).update(Text("\n".join(f"! {p}" for p in problems)))
        self.type_name = self.type_name or (info["types"][0] if info["types"] else None)
        self.query_one("#title", Static).update(Text(f"topic {self.topic}  {', '.join(info['types'])}", style="bold"))

    def show_qos(self) -> None:
        """Under the endpoints, the rest of the QoS of the one under the cursor."""
        endpoint = self.endpoints.get(self.query_one("#endpoints", ListTable).selected_key() or "")
        self.query_one("#qos", Static).update(Text(endpoint_detail(endpoint) if endpoint else ""))

    def on_data_table_row_highlighted(self, _event: DataTable.RowHighlighted) -> None:
        self.show_qos()

    @work(thread=True, exclusive=True, group="echo")
    def echo(self) -> None:
        worker = get_current_worker()
        try:
            # the daemon decodes the last message of each batch (``value``): no rclpy in this process
            params = {"topic": self.topic, "wait": 0, "latest_value": True, "truncate_length": DEFAULT_TRUNCATE_LENGTH}
            for event in host(self).feed.stream("echo", params, lambda: worker.is_cancelled):
                if event["event"] == "subscribed":
                    self.type_name = event["type"]
                elif event["event"] == "messages":
                    self.app.call_from_thread(self.take, event["messages"])
        except RocError as error:
            self.app.call_from_thread(self.query_one("#stats", Static).update, f"echo: {error}")

    def take(self, messages: list[dict[str, Any]]) -> None:
        for message in messages:
            info = message["info"]
            self.window.add([Sample(info.get("publication_sequence_number"), info.get("source_timestamp"),
                                    info.get("received_timestamp") or time.time_ns(), cdr_size(message["data"]), None,
                                    message.get("publisher"))])
        self.count += len(messages)
        self.latest = messages[-1]

    def draw_stats(self) -> None:
        self.query_one("#stats", Static).update(stats_text(self.window))

    def draw_echo(self, force: bool = False) -> None:
        state = "paused (p: resume)" if self.paused else "live (p: pause)"
        field = f", field {self.field}" if self.field else ""
        self.query_one("#echo-title", Static).update(Text(f"message {self.count}{field}: {state}", style="bold"))
        if not self.paused and self.latest is not None and self.drawn != self.count:
            self.shown, self.drawn = self.latest, self.count
        elif not force:
            return
        if self.shown is not None:
            self.query_one("#echo", Static).update(Text(self.message_text(self.shown["value"])))

    def message_text(self, value: Any) -> str:
        """The message (as the daemon decoded it) or the selected field, as ``roc topic echo`` prints it."""
        from roc.ros.messages import dict_to_yaml, field_names

        try:
            names = field_names(self.field) if self.field else []
        except RocError as error:
            return f"cannot show the message: {error}"
        for depth, name in enumerate(names):
            if not isinstance(value, dict) or name not in value:
                known = ", ".join(value) if isinstance(value, dict) else "it is no message"
                return f"cannot show the message: {'.'.join(names[:depth + 1])}: no such field ({known})"
            value = value[name]
        return dict_to_yaml(value) + "---\n" if isinstance(value, dict) else f"{value}\n---\n"

    def action_pause(self) -> None:
        self.paused = not self.paused
        self.draw_echo()

    def action_field(self) -> None:
        def done(text: str | None) -> None:
            if text is not None:
                self.field = text.strip()
                self.draw_echo(force=True)
        self.app.push_screen(Prompt("field to show, sub-fields separated by '.' (empty: the whole message)",
                                    self.field), done)

    def action_plot(self) -> None:
        """Plot the field shown (when it is a number) or one typed, the latest message's first number
        offered."""
        from roc.tui.plotting import numeric_paths

        value = self.shown["value"] if self.shown else None
        paths = numeric_paths(value) if isinstance(value, dict) else []
        offered = self.field if self.field in paths else paths[0] if paths else self.field

        def done(text: str | None) -> None:
            if text and text.strip():
                host(self).open("plot", f"{self.topic} {text.strip()}")
        choices = f" (numbers: {', '.join(paths[:6])}{', ...' if len(paths) > 6 else ''})" if paths else ""
        self.app.push_screen(Prompt(f"field(s) of {self.topic} to plot, separated by spaces{choices}", offered), done)

    def action_publish(self) -> None:
        host(self).open("publish", self.topic)

    def action_image(self) -> None:
        from roc.tui.image_screen import SCAN
        from roc.tui.images import GRID, TYPES

        if self.type_name in TYPES:
            host(self).open("image", self.topic)
        elif self.type_name in (SCAN, GRID):
            host(self).open("scan" if self.type_name == SCAN else "grid", self.topic)
        else:
            self.notify(f"{self.topic} is no image, scan or grid topic ({self.type_name or 'type unknown'})",
                        severity="warning")
