"""An image topic (sensor_msgs/Image or CompressedImage) drawn in the terminal in half blocks
(roc.tui.images), the newest frame twice a second (the daemon sends only that: echo's ``latest_every``);
Space pauses."""

from __future__ import annotations

import base64

from rich.text import Text
from textual import work
from textual.app import ComposeResult
from textual.binding import Binding
from textual.screen import Screen
from textual.widgets import Footer, Static
from textual.worker import get_current_worker

from roc.errors import RocError
from roc.tui.images import TYPES, half_blocks, picture
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
