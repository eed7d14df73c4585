"""Logs: /rosout live (the daemon decodes it: its ``values`` stream), or the output of a process ``roc
launch`` started (roc.launch.status), one line per entry in the order of their times; filtered by level
(``l`` raises the least level shown), node (``n``) and text (``/``); Space pauses and resumes following.

/rosout is the app's (``Logs``, followed from the first screen's start until the TUI ends): what came
since the TUI started, and before that the history each node's /rosout publisher keeps for a new
subscriber (rcl's profile: transient local, the last 1000 entries, each for 10 s: its lifespan). The
histories come one publisher after another, so entries are kept sorted by their stamps."""

from __future__ import annotations

import bisect
import time
from collections import deque
from collections.abc import Iterable
from dataclasses import dataclass

from rich.text import Text
from textual import work
from textual.app import ComposeResult
from textual.binding import Binding
from textual.screen import Screen
from textual.widgets import Footer, RichLog, Static
from textual.worker import get_current_worker

from roc.errors import RocError
from roc.tui.widgets import Prompt, follow

KEPT = 20000  # entries kept (the filters apply to them all)
# the history rcl's /rosout publishers keep for a new subscriber (rcl_qos_profile_rosout_default)
ROSOUT_LIFESPAN = 10
ROSOUT_DEPTH = 1000
LEVELS = {10: "DEBUG", 20: "INFO", 30: "WARN", 40: "ERROR", 50: "FATAL"}
STYLES = {10: "dim", 20: "", 30: "yellow", 40: "red", 50: "bold red"}


@dataclass(frozen=True)
class Entry:
    stamp: float  # seconds
    level: int
    node: str  # the logger's name (``ns.node``) or the process's
    text: str

    def line(self) -> Text:
        when = time.strftime("%H:%M:%S", time.localtime(self.stamp)) + f".{int(self.stamp * 1000) % 1000:03d}"
        level = LEVELS.get(self.level, str(self.level))
        return Text.assemble(f"{when} ", (f"{level:<5}", STYLES.get(self.level, "")), f" [{self.node}] ", self.text)


def rosout_entry(value: dict) -> Entry:
    """A decoded rcl_interfaces/msg/Log."""
    stamp = value["stamp"]["sec"] + value["stamp"]["nanosec"] / 1e9
    return Entry(stamp, value["level"], value["name"], value["msg"])


class Logs:
    """/rosout's entries in the order of their stamps, as they came since the TUI began to follow it."""

    def __init__(self) -> None:
        # keep_all: the histories of every node come at once, more than a keep-last reader's depth holds
        self.params = {"topic": "/rosout", "qos": {"history": "keep_all"}}
        self.following = False
        self.entries: list[Entry] = []
        self.since = time.time()  # when the TUI began to follow /rosout
        self.readers: list = []  # called with each batch of entries taken (the logs screens shown)

    def take(self, messages: list[dict]) -> None:
        entries = [rosout_entry(m["value"]) for m in messages]
        for entry in entries:
            bisect.insort(self.entries, entry, key=lambda e: e.stamp)
        del self.entries[:len(self.entries) - KEPT]
        for reader in self.readers:
            reader(entries)

    def reach(self) -> str:
        """How far back the entries go, and why no further."""
        first = time.strftime("%H:%M:%S", time.localtime(self.entries[0].stamp)) if self.entries else "-"
        return (f"from {first}: since roc tui started, and before that the {ROSOUT_LIFESPAN} s (at most "
                f"{ROSOUT_DEPTH} entries) each node's /rosout keeps")


def logger_name(node: str) -> str:
    """A node's full name as its logger is named (``/ns/talker`` -> ``ns.talker``)."""
    return node.strip("/").replace("/", ".")


def level_of(text: str) -> int:
    """The level of a line a process printed (``[WARN] [...]``), INFO when it says none."""
    for number, name in LEVELS.items():
        if text.startswith((f"[{name}]", f"[{name[:4]}")):
            return number
    return 20


def shown(entry: Entry, least: int, node: str, text: str) -> bool:
    return (entry.level >= least and (not node or entry.node == node or entry.node.startswith(node + "."))
            and (not text or text.lower() in entry.text.lower()))


class LogsScreen(Screen):
    BINDINGS = [
        Binding("escape", "app.pop_screen", "back"),
        Binding("space", "follow", "pause/resume following"),
        Binding("l", "level", "least level shown (debug, info, warn, error, fatal)"),
        Binding("n", "node", "only one node's lines"),
        Binding("slash", "text", "only lines with a text"),
        Binding("x", "clear_filters", "clear the filters"),
    ]
    DEFAULT_CSS = """
    LogsScreen #title { height: 1; background: $primary; }
    LogsScreen RichLog { height: 1fr; }
    """

    def __init__(self, node: str = "", process: str = "", launch=None) -> None:
        """``node``: start filtered to its lines; ``process`` of ``launch`` (a roc.launch.status
        RunStatus): that process's output instead of /rosout."""
        super().__init__()
        self.entries: deque[Entry] | list[Entry] = deque(maxlen=KEPT)  # /rosout's: the app's Logs
        self.least, self.node, self.text = 10, logger_name(node) if node else "", ""
        self.following = True
        self.process, self.launch = process, launch
        self.pending: list[Entry] = []  # arrived while paused
        self.last_stamp = float("-inf")  # of the last line written
        self.redraw_due = False

    def compose(self) -> ComposeResult:
        yield Static("", id="title")
        yield RichLog(max_lines=KEPT, wrap=False, id="log")
        yield Footer()

    def on_mount(self) -> None:
        if self.process:
            self.draw_title()
            self.read()
            return
        logs = self.app.logs  # type: ignore[attr-defined]
        self.entries = logs.entries
        logs.readers.append(self.arrived)
        follow(self.app, logs)
        self.redraw()

    def on_unmount(self) -> None:
        if not self.process:
            self.app.logs.readers.remove(self.arrived)  # type: ignore[attr-defined]

    @property
    def source(self) -> str:
        return f"output of {self.process}" if self.process else "/rosout"

    def draw_title(self) -> None:
        filters = [f"level >= {LEVELS[self.least].lower()}"]
        if self.node:
            filters.append(f"node {self.node}")
        if self.text:
            filters.append(f"text '{self.text}'")
        state = "following (Space: pause)" if self.following else f"paused, {len(self.pending)} new (Space: resume)"
        reach = "" if self.process else f"  {self.app.logs.reach()}"  # type: ignore[attr-defined]
        self.query_one("#title", Static).update(Text(f"logs: {self.source}  {', '.join(filters)}  {state}{reach}",
                                                     style="bold"))

    @work(thread=True, exclusive=True, group="logs")
    def read(self) -> None:
        """A process's output (/rosout is the app's: roc.tui.widgets.follow)."""
        worker = get_current_worker()
        try:
            for lines in self.launch.follow(self.process, lambda: worker.is_cancelled):
                now = time.time()
                self.app.call_from_thread(self.take, [Entry(now, level_of(line), self.process, line)
                                                      for line in lines])
        except (RocError, OSError) as error:
            self.app.call_from_thread(self.notify, f"logs: {error}", severity="error")

    def take(self, entries: Iterable[Entry]) -> None:
        entries = list(entries)
        self.entries.extend(entries)
        self.arrived(entries)

    def arrived(self, entries: list[Entry]) -> None:
        """Entries kept since the last: written after the last line when none is older, else every line
        written again in order (soon: a node's history comes in several batches)."""
        if not self.following:
            self.pending += entries
            self.draw_title()
        elif all(entry.stamp >= self.last_stamp for entry in entries):
            self.write(entries)
        elif not self.redraw_due:
            self.redraw_due = True
            self.set_timer(0.2, self.redraw)

    def write(self, entries: Iterable[Entry]) -> None:
        log = self.query_one("#log", RichLog)
        for entry in entries:
            if shown(entry, self.least, self.node, self.text):
                log.write(entry.line(), scroll_end=self.following)
            self.last_stamp = max(self.last_stamp, entry.stamp)

    def redraw(self) -> None:
        self.redraw_due = False
        self.query_one("#log", RichLog).clear()
        self.pending = []
        self.last_stamp = float("-inf")
        self.write(self.entries)
        self.draw_title()

    def visible_lines(self) -> list[str]:
        """The lines the filters keep (for tests)."""
        return [entry.line().plain for entry in self.entries if shown(entry, self.least, self.node, self.text)]

    def action_follow(self) -> None:
        self.following = not self.following
        if self.following:
            self.redraw()  # what came while paused, each line in its place
        else:
            self.draw_title()

    def action_level(self) -> None:
        levels = list(LEVELS)
        self.least = levels[(levels.index(self.least) + 1) % len(levels)]
        self.redraw()

    def action_node(self) -> None:
        def done(text: str | None) -> None:
            if text is not None:
                self.node = logger_name(text.strip()) if text.strip() else ""
                self.redraw()
        self.app.push_screen(Prompt("only the lines of the node (empty: every node)", self.node), done)

    def action_text(self) -> None:
        def done(text: str | None) -> None:
            if text is not None:
                self.text = text
                self.redraw()
        self.app.push_screen(Prompt("only the lines with this text (empty: every line)", self.text), done)

    def action_clear_filters(self) -> None:
        self.least, self.node, self.text = 10, "", ""
        self.redraw()
