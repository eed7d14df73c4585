"""The newest message of a topic drawn in the terminal, twice a second (the daemon sends only that: echo's
``latest_every``): an image (sensor_msgs/Image or CompressedImage) or an occupancy grid
(nav_msgs/OccupancyGrid) in half blocks (roc.tui.images), a LaserScan's returns around the sensor and
a numeric array against its index in plotext (textual-plotext); Space pauses."""

from __future__ import annotations

import base64
from typing import Any

from rich.text import Text
from textual import work
from textual.app import ComposeResult
from textual.binding import Binding
from textual.screen import Screen
from textual.widgets import Footer, Static
from textual.worker import get_current_worker

from roc.errors import RocError
from roc.tui.images import GRID, TYPES, grid_image, half_blocks, picture
from roc.tui.plotting import array_at, finite_points, scan_points, square_limits
from roc.tui.widgets import host

FRAME_SECONDS = 0.5


class ImageScreen(Screen):
    BINDINGS = [
        Binding("escape", "app.pop_screen", "back"),
        Binding("space", "pause", "pause/resume the image"),
    ]
    DEFAULT_CSS = """
    ImageScreen #title { height: 1; background: $primary; }
    ImageScreen #image { height: 1fr; content-align: center middle; }
    """

    def __init__(self, topic: str, type_name: str = "") -> None:
        """``type_name``: the topic's, else the one its echo says."""
        super().__init__()
        self.topic, self.type_name = topic, type_name
        self.frames = 0  # drawn
        self.received = 0  # images the daemon sent (paused or not)
        self.paused = False
        self.description = "waiting for an image..."

    def compose(self) -> ComposeResult:
        yield Static("", id="title")
        yield Static("", id="image")
        yield Footer()

    def on_mount(self) -> None:
        self.draw_title()
        self.read()

    def draw_title(self) -> None:
        state = "paused (Space: resume)" if self.paused else "live (Space: pause)"
        self.query_one("#title", Static).update(Text(f"image {self.topic}  {self.description}  frame {self.frames}, "
                                                     f"{state}", style="bold"))

    @work(thread=True, exclusive=True, group="image")
    def read(self) -> None:
        """The newest frame, decoded and scaled here, off the app's thread."""
        worker = get_current_worker()
        params = {"topic": self.topic, "wait": 0, "latest_every": FRAME_SECONDS}
        try:
            for event in host(self).feed.stream("echo", params, lambda: worker.is_cancelled):
                if event["event"] == "subscribed":
                    self.type_name = event["type"]
                    if self.type_name not in TYPES:
                        self.app.call_from_thread(self.show, [], f"{self.type_name} is no image ({', '.join(TYPES)})")
                        return
                if event["event"] != "messages":
                    continue
                self.received += 1
                if self.paused:
                    continue
                try:
                    found = picture(self.type_name, base64.b64decode(event["messages"][-1]["data"]))
                except RocError as error:
                    self.app.call_from_thread(self.show, [], str(error))
                    continue
                size = self.query_one("#image").size
                self.app.call_from_thread(self.show, half_blocks(found.image, size.width, size.height),
                                          found.description)
        except RocError as error:
            self.app.call_from_thread(self.show, [], f"echo: {error}")

    def show(self, lines: list[Text], description: str) -> None:
        if lines:
            self.frames += 1
            self.query_one("#image", Static).update(Text("\n").join(lines))
        self.description = description
        self.draw_title()

    def action_pause(self) -> None:
        self.paused = not self.paused
        self.draw_title()


SCAN = "sensor_msgs/msg/LaserScan"
# view -> the type it draws (None: any with the array asked for)
VIEWS = {"array": None, "scan": SCAN, "grid": GRID}


class SensorScreen(Screen):
    """``array``: a numeric array field (``ranges``) of the newest message against its index (rosight's
    1-D array plot); ``scan``: a LaserScan's returns as points around the sensor, a metre as long across as
    up, forward to the right; ``grid``: an OccupancyGrid, north up (ros2_diag_tui's LiDAR and map views)."""

    BINDINGS = [
        Binding("escape", "app.pop_screen", "back"),
        Binding("space", "pause", "pause/resume the view"),
    ]
    DEFAULT_CSS = """
    SensorScreen #title { height: 1; background: $primary; }
    SensorScreen #picture { height: 1fr; content-align: center middle; }
    SensorScreen TimedPlot { height: 1fr; }
    """

    def __init__(self, view: str, topic: str, field: str = "") -> None:
        super().__init__()
        self.view, self.topic, self.field = view, topic, field
        self.frames = 0  # drawn
        self.paused = False
        self.description = "waiting for a message..."

    def compose(self) -> ComposeResult:
        from roc.tui.plot_screen import TimedPlot

        yield Static("", id="title")
        yield Static("", id="picture") if self.view == "grid" else TimedPlot(id="plot")
        yield Footer()

    def on_mount(self) -> None:
        self.draw_title()
        self.read()

    def draw_title(self) -> None:
        what = f"{self.topic} {self.field}" if self.view == "array" else self.topic
        state = "paused (Space: resume)" if self.paused else "live (Space: pause)"
        self.query_one("#title", Static).update(Text(f"{self.view} {what}  {self.description}  frame {self.frames}, "
                                                     f"{state}", style="bold"))

    @work(thread=True, exclusive=True, group="sensor")
    def read(self) -> None:
        worker = get_current_worker()
        params = {"topic": self.topic, "wait": 0, "latest_every": FRAME_SECONDS, "latest_value": True}
        try:
            for event in host(self).feed.stream("echo", params, lambda: worker.is_cancelled):
                wanted = VIEWS[self.view]
                if event["event"] == "subscribed" and wanted is not None and event["type"] != wanted:
                    self.app.call_from_thread(self.said, f"{event['type']} is no {wanted}")
                    return
                if event["event"] == "messages" and not self.paused:
                    self.app.call_from_thread(self.draw, event["messages"][-1]["value"])
        except RocError as error:
            self.app.call_from_thread(self.said, f"echo: {error}")

    def said(self, description: str) -> None:
        if not self.query("#title"):  # the screen was left while the message came
            return
        self.description = description
        self.draw_title()

    def draw(self, message: dict[str, Any]) -> None:
        """The newest message drawn (grids scaled here: a map of 4000 x 4000 cells takes a moment)."""
        if not self.query("#title"):  # the screen was left while the message came
            return
        try:
            self.description = self.drawn(message)
        except RocError as error:
            self.description = str(error)
        else:
            self.frames += 1
        self.draw_title()

    def drawn(self, message: dict[str, Any]) -> str:
        if self.view == "grid":
            box = self.query_one("#picture", Static)
            image = grid_image(message, box.size.width, box.size.height)
            box.update(Text("\n").join(half_blocks(image, box.size.width, box.size.height)))
            info = message["info"]
            return (f"{info['width']} x {info['height']} cells of {info['resolution']:g} m, frame "
                    f"{message['header']['frame_id'] or '-'}")
        from roc.tui.plot_screen import TimedPlot

        widget = self.query_one("#plot", TimedPlot)
        plot = widget.plt
        plot.clear_data()
        if self.view == "scan":
            xs, ys = scan_points(message)
            reach = max((max(abs(x), abs(y)) for x, y in zip(xs, ys)), default=1.0) or 1.0
            across, up = square_limits(reach * 1.05, widget.size.width, widget.size.height)
            plot.xlim(-across, across)
            plot.ylim(-up, up)
            plot.scatter(xs, ys, marker="braille")
            plot.scatter([0.0], [0.0], marker="+")  # the sensor
            description = f"{len(xs)} returns of {len(message['ranges'])}, out to {reach:.2f} m"
        else:
            values = array_at(message, self.field)
            if values is None:
                raise RocError(f"{self.field}: no array of numbers in {self.topic}'s messages")
            indices, finite = finite_points(values)
            plot.xlim(0, max(1, len(values) - 1))
            plot.plot(indices, finite, marker="braille")
            description = (f"{len(values)} values, {min(finite):g} to {max(finite):g}" if finite
                           else f"{len(values)} values, none finite")
        widget.refresh()
        return description

    def action_pause(self) -> None:
        self.paused = not self.paused
        self.draw_title()
