"""A plot: numeric fields of one or more topics against time (textual-plotext, on plotext), live. The
daemon sends only the fields asked for (its ``values`` stream with ``fields``); the streams' threads
leave the batches in an inbox that the screen empties when it draws: when something changed, at most
every DRAW_SECONDS (or as long as the window takes to move by one column), two points per column.
Space pauses the view, ``+``/``-`` zoom the time window, ``a`` adds a field, ``r`` removes the last,
``s`` writes the samples to a CSV file."""

from __future__ import annotations

import time
from collections import deque
from functools import partial
from pathlib import Path

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.screen import Screen
from textual.widgets import Footer, Static
from textual.worker import get_current_worker
from textual_plotext import PlotextPlot

from roc.errors import RocError
from roc.fsutil import write_text_atomic
from roc.tui.plotting import Series, csv_text, thinned
from roc.tui.widgets import Prompt, host

DRAW_SECONDS = 0.5  # at most twice a second
DRAW_SHARE = 0.04  # and so rarely that drawing takes at most this share of a core (plotext takes 10 to 100 ms)
BATCH_SECONDS = 0.05  # the daemon sends a fast topic's samples in batches this far apart
WINDOWS = (1, 2, 5, 10, 30, 60, 120, 300, 600)  # seconds shown, ``+``/``-`` go through them
NS = 1e-9


class TimedPlot(PlotextPlot):
    """A plotext plot that keeps how much CPU its last drawing took, in the terminal's own colours
    (plotext's ``pro`` theme: only the lines are coloured, a third of the escape codes to decode)."""

    def __init__(self, **options) -> None:
        super().__init__(**options)
        self.theme = "pro"
        self.cost = 0.0  # seconds of CPU

    def render(self):
        started = time.thread_time()
        try:
            return super().render()
        finally:
            self.cost = time.thread_time() - started


class PlotScreen(Screen):
    BINDINGS = [
        Binding("escape", "app.pop_screen", "back"),
        Binding("space", "pause", "pause/resume the plot"),
        Binding("plus,equals_sign", "zoom(-1)", "zoom in (a shorter window)"),
        Binding("minus", "zoom(1)", "zoom out (a longer window)"),
        Binding("a", "add", "add a field (TOPIC FIELD, or FIELD of the last topic)"),
        Binding("r", "remove", "remove the last field"),
        Binding("s", "save", "save the samples as CSV"),
    ]
    DEFAULT_CSS = """
    PlotScreen #title { height: 1; background: $primary; }
    PlotScreen TimedPlot { height: 1fr; }
    """

    def __init__(self, fields: list[tuple[str, str]]) -> None:
        """``fields``: (topic, dotted field path) pairs."""
        super().__init__()
        self.series = [Series(topic, path) for topic, path in fields]
        self.window = 10
        self.paused_at: float | None = None  # the latest time shown while paused
        self.latest = 0.0  # the newest sample's time
        self.received = 0
        self.lost: int | None = 0
        self.errors: dict[str, str] = {}
        self.inbox: deque[tuple[str, dict]] = deque()  # (topic, samples event), from the streams' threads
        self.changed = True  # something to draw
        self.drawn_at = 0.0  # time.monotonic() of the last drawing

    def compose(self) -> ComposeResult:
        yield Static("", id="title")
        yield TimedPlot(id="plot")
        yield Footer()

    def on_mount(self) -> None:
        for topic in self.topics():
            self.subscribe(topic)
        self.set_interval(DRAW_SECONDS, self.tick)
        self.draw()

    def topics(self) -> list[str]:
        return list(dict.fromkeys(one.topic for one in self.series))

    def subscribe(self, topic: str) -> None:
        """(Re)start the stream of ``topic`` with every field of it plotted."""
        paths = [one.path for one in self.series if one.topic == topic]
        self.run_worker(partial(self.read, topic, paths), thread=True, exclusive=True, group=f"plot {topic}")

    def read(self, topic: str, paths: list[str]) -> None:
        worker = get_current_worker()
        if not paths:
            return
        try:
            params = {"topic": topic, "fields": paths, "period": BATCH_SECONDS}
            for event in host(self).feed.stream("values", params, lambda: worker.is_cancelled):
                if event["event"] == "samples":
                    self.inbox.append((topic, event))
        except RocError as error:
            self.errors[topic] = str(error)
            self.changed = True

    def tick(self) -> None:
        """Take what arrived; draw when it changes what is shown and the window has moved by a column."""
        arrived = bool(self.inbox)
        while self.inbox:
            self.take(*self.inbox.popleft())
        plot = self.query_one(TimedPlot)
        columns = max(10, plot.size.width - 12)
        due = self.drawn_at + max(DRAW_SECONDS, self.window / columns, plot.cost / DRAW_SHARE) * 0.9
        if self.changed and time.monotonic() >= due:
            self.draw()
        elif arrived:
            self.draw_title()

    def take(self, topic: str, event: dict) -> None:
        times = [t * NS for t in event["time"]]
        for one in self.series:
            if one.topic == topic and one.path in event["values"]:
                one.add(times, event["values"][one.path])
        self.received += len(times)
        lost = event.get("lost", 0)
        self.lost = None if lost is None or self.lost is None else self.lost + lost  # None: unknown (Cyclone DDS)
        if times:
            self.latest = max(self.latest, times[-1])
            self.changed = self.changed or self.paused_at is None

    def draw_title(self) -> None:
        state = "paused (Space: resume)" if self.paused_at is not None else "live (Space: pause)"
        errors = "  ".join(f"{topic}: {error}" for topic, error in self.errors.items())
        self.query_one("#title", Static).update(Text(
            f"plot, last {self.window} s, {state}  {self.received} samples, "
            f"{'unknown' if self.lost is None else self.lost} lost  {errors}", style="bold"))

    def draw(self) -> None:
        self.changed, self.drawn_at = False, time.monotonic()
        end = self.paused_at if self.paused_at is not None else self.latest
        start = end - self.window
        self.draw_title()
        widget = self.query_one(TimedPlot)
        plt = widget.plt
        plt.clear_data()
        plt.clear_figure()
        columns = max(10, widget.size.width - 12)
        for one in self.series:
            times, values = thinned(*one.window(start, end), columns)
            if times:
                plt.plot([t - end for t in times], values, label=one.label, marker="braille")
        plt.xlim(-self.window, 0)
        plt.xlabel("seconds")
        widget.refresh()

    def action_pause(self) -> None:
        self.paused_at = None if self.paused_at is not None else self.latest
        self.draw()

    def action_zoom(self, step: int) -> None:
        index = WINDOWS.index(self.window) if self.window in WINDOWS else 3
        self.window = WINDOWS[max(0, min(len(WINDOWS) - 1, index + step))]
        self.draw()

    def action_add(self) -> None:
        last = self.series[-1].topic if self.series else ""

        def done(text: str | None) -> None:
            words = (text or "").split()
            if not words:
                return
            topic, path = (words[0], words[1]) if len(words) > 1 else (last, words[0])
            if not topic:
                self.notify("name the topic too: TOPIC FIELD", severity="warning")
                return
            self.series.append(Series(topic, path))
            self.subscribe(topic)
        self.app.push_screen(Prompt(f"field to plot: TOPIC FIELD, or FIELD of {last or 'a topic'}", ""), done)

    def action_remove(self) -> None:
        if self.series:
            removed = self.series.pop()
            self.subscribe(removed.topic)
            self.draw()

    def action_save(self) -> None:
        def done(path: str | None) -> None:
            if path:
                self.save(Path(path).expanduser())
        self.app.push_screen(Prompt("write the samples kept to the CSV file", "plot.csv"), done)

    def save(self, path: Path) -> None:
        try:
            write_text_atomic(path, csv_text(self.series))
        except OSError as error:
            self.notify(f"cannot write {path}: {error.strerror}", severity="error")
            return
        self.notify(f"wrote {path}")
