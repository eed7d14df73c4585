"""A bag (``roc tui --bag PATH``, ``:bag PATH``): its topics with their types, counts and rates (roc.bag,
no rclpy; the copies a split recording repeats of transient local messages are not counted); Enter
steps through a topic's messages (``n``/``b``: next, back; the daemon decodes them); ``P`` plays the
bag on the live graph with ``roc bag play`` in a child process (the player imports rclpy) whose own
keys the screen passes on: Space pauses, ``.`` plays the next message, ``>``/``<`` change the rate;
``x`` stops it."""

from __future__ import annotations

import base64
import os
import pty
import subprocess
import sys
import threading
from pathlib import Path
from typing import Any

from rich.text import Text
from textual import work
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import VerticalScroll
from textual.screen import Screen
from textual.widgets import DataTable, Footer, Static

from roc.errors import RocError, UsageError
from roc.render import plural
from roc.tui.model import Row, rate_text
from roc.tui.widgets import ListTable, host

# roc bag play's keyboard controls (roc/bag/keyboard.py), as the terminal sends them
PLAYER_KEYS = {"pause": b" ", "step": b"\x1b[C", "faster": b"\x1b[A", "slower": b"\x1b[B"}


def topic_rows(bag, copies: dict[str, int]) -> list[Row]:
    """Each topic with its messages counted and its rate, less the ``copies`` a split recording repeated
    (roc.bag.reader.repeated_copies): /tf_static recorded once is one message, at no rate."""
    seconds = bag.metadata.duration / 1e9
    counts = [(topic, count - copies.get(topic.name, 0)) for topic, count in bag.metadata.topics]
    return [Row(topic.name, (topic.name, topic.type, str(count),
                             rate_text(count / seconds if seconds > 0 and count > 1 else None)))
            for topic, count in counts]


class Playback:
    """``roc bag play PATH`` in a child process whose standard input is a pseudo-terminal, so that its
    keyboard controls work as in a terminal; its output kept line by line."""

    def __init__(self, path: Path) -> None:
        self.controller, terminal = pty.openpty()
        self.process = subprocess.Popen([sys.executable, "-m", "roc", "bag", "play", str(path)], stdin=terminal,
                                        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                        start_new_session=True)
        os.close(terminal)
        self.lines: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            self.lines.append(line.rstrip("\n"))

    def running(self) -> bool:
        return self.process.poll() is None

    def key(self, name: str) -> None:
        if self.running():
            os.write(self.controller, PLAYER_KEYS[name])

    def stop(self) -> None:
        if self.running():
            self.process.terminate()
            try:
                self.process.wait(10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        os.close(self.controller)
        self.controller = -1


class BagScreen(Screen):
    BINDINGS = [
        Binding("escape", "back", "back"),
        Binding("n", "step(1)", "next message of the topic"),
        Binding("b", "step(-1)", "previous message of the topic"),
        Binding("P", "play", "play the bag on the graph (roc bag play)"),
        Binding("space", "player('pause')", "pause/resume the playback"),
        Binding("full_stop", "player('step')", "play the next message (paused)"),
        Binding("greater_than_sign", "player('faster')", "play faster"),
        Binding("less_than_sign", "player('slower')", "play slower"),
        Binding("x", "stop", "stop the playback"),
    ]
    DEFAULT_CSS = """
    BagScreen #title { height: 1; background: $primary; }
    BagScreen ListTable { height: 1fr; max-height: 12; }
    BagScreen #message-title { height: 1; background: $boost; }
    BagScreen VerticalScroll { height: 1fr; }
    BagScreen #playback { height: 3; }
    """

    def __init__(self, path: str) -> None:
        super().__init__()
        if not path:
            raise UsageError("bag PATH: name a bag directory or file")
        self.path = Path(path).expanduser()
        self.bag: Any = None  # a roc.bag.reader.Bag once open
        self.topic: str | None = None
        self.messages: list[bytes] = []  # the topic's messages, read once
        self.index = -1
        self.playback: Playback | None = None

    def compose(self) -> ComposeResult:
        yield Static(Text(f"bag {self.path}", style="bold"), id="title")
        yield ListTable(("topic", "type", "count", "rate"), id="topics")
        yield Static("Enter: step through a topic's messages; P: play the bag on the graph", id="message-title")
        with VerticalScroll():
            yield Static("", id="message")
        yield Static("", id="playback")
        yield Footer()

    def on_mount(self) -> None:
        from roc.bag.reader import Bag, repeated_copies

        try:
            self.bag = Bag(self.path)
        except RocError as error:
            self.query_one("#title", Static).update(Text(f"bag {self.path}: {error}", style="bold red"))
            return
        metadata = self.bag.metadata
        copies = repeated_copies(self.bag)
        repeated = sum(copies.values())
        self.query_one("#title", Static).update(Text(
            f"bag {self.path}  {metadata.storage_identifier}, "
            f"{plural(sum(c for _, c in metadata.topics) - repeated, 'message')}, {metadata.duration / 1e9:.1f} s"
            + (f" ({repeated} repeated at the start of split files not counted)" if repeated else ""), style="bold"))
        self.query_one("#topics", ListTable).show(topic_rows(self.bag, copies))
        self.query_one("#topics").focus()
        self.set_interval(0.5, self.draw_playback)

    def on_data_table_row_selected(self, event: DataTable.RowSelected) -> None:
        from roc.bag.reader import RepeatedCopies

        if self.bag is not None and event.row_key.value:
            self.topic = event.row_key.value
            is_copy = RepeatedCopies(self.bag)
            self.messages = [m.data for m in self.bag.messages([self.topic]) if not is_copy(m)]
            self.index = -1
            self.action_step(1)

    def action_step(self, step: int) -> None:
        if not self.messages:
            return
        self.index = max(0, min(len(self.messages) - 1, self.index + step))
        self.show_message(self.index)

    @work(thread=True, exclusive=True, group="decode")
    def show_message(self, index: int) -> None:
        from roc.ros.messages import dict_to_yaml

        assert self.bag is not None and self.topic is not None
        topic = self.bag.metadata.topic(self.topic)
        params = {"type": topic.type if topic else "", "messages": [base64.b64encode(self.messages[index]).decode()],
                  "truncate_length": 128}
        try:
            event = next(e for e in host(self).feed.stream("decode", params, lambda: False) if e["event"] == "values")
            text = dict_to_yaml(event["messages"][0]["value"])
        except (RocError, StopIteration) as error:
            text = f"cannot decode it: {error}"
        title = f"{self.topic}: message {index + 1} of {len(self.messages)} (n: next, b: back)"
        self.app.call_from_thread(self.query_one("#message-title", Static).update, Text(title, style="bold"))
        self.app.call_from_thread(self.query_one("#message", Static).update, Text(text))

    def action_play(self) -> None:
        if self.playback is not None and self.playback.running():
            self.notify("the bag is playing (x: stop)", severity="warning")
            return
        self.playback = Playback(self.path)

    def action_player(self, key: str) -> None:
        if self.playback is None or not self.playback.running():
            self.notify("not playing (P: play)", severity="warning")
            return
        self.playback.key(key)

    def action_stop(self) -> None:
        if self.playback is not None:
            self.playback.stop()

    def draw_playback(self) -> None:
        if self.playback is None:
            return
        state = "playing" if self.playback.running() else f"ended ({self.playback.process.returncode})"
        lines = "\n".join(self.playback.lines[-2:])
        self.query_one("#playback", Static).update(Text(f"roc bag play: {state}\n{lines}"))

    def action_back(self) -> None:
        self.action_stop()
        if self.bag is not None:
            self.bag.close()
        self.app.pop_screen()
