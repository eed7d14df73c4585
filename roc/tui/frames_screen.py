"""The tf tree, live: each frame under its parent with its rate (static or Hz) and the node(s) that
publish it, redrawn every second from roc.frames' listener (the daemon's ``frames`` stream)."""

from __future__ import annotations

from rich.text import Text
from textual import work
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import VerticalScroll
from textual.screen import Screen
from textual.widgets import Footer, Static
from textual.worker import get_current_worker

from roc.errors import RocError

REDRAW_SECONDS = 1.0


class FramesScreen(Screen):
    BINDINGS = [Binding("escape", "app.pop_screen", "back")]
    DEFAULT_CSS = """
    FramesScreen #title { height: 1; background: $primary; }
    FramesScreen VerticalScroll { height: 1fr; }
    """

    def compose(self) -> ComposeResult:
        yield Static(Text("tf frames (from /tf and /tf_static)", style="bold"), id="title")
        with VerticalScroll():
            yield Static("listening...", id="tree")
        yield Footer()

    def on_mount(self) -> None:
        self.listen()

    @work(thread=True, exclusive=True, group="frames")
    def listen(self) -> None:
        from roc.commands.frame.list import frame_rows
        from roc.commands.frame.tree import tree_lines
        from roc.frames.listen import Listener

        worker = get_current_worker()
        try:
            listener = Listener(early=True)
        except RocError as error:
            self.app.call_from_thread(self.show, f"error: {error}")
            return
        try:
            while not worker.is_cancelled:
                listener.listen(lambda: worker.is_cancelled, seconds=REDRAW_SECONDS)
                lines = tree_lines(frame_rows(listener))
                self.app.call_from_thread(self.show, "\n".join(lines) or "no tf frames heard yet")
        except RocError as error:
            self.app.call_from_thread(self.show, f"error: {error}")
        finally:
            listener.close()

    def show(self, text: str) -> None:
        self.query_one("#tree", Static).update(Text(text))
