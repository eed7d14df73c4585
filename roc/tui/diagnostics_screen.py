"""Diagnostics: the statuses published on /diagnostics (diagnostic_msgs/DiagnosticArray, decoded by the
daemon), one row per hardware id and name, the hardware with the worst status first; Enter shows a
status's values and its history (each change of level or message, with its time), kept live.

The statuses are the app's (``Diagnostics``, read by roc.tui.widgets.follow from the moment the first screen sees
/diagnostics until the TUI ends): leaving the view loses no history, and the first screen's problems
line counts the statuses in ERROR."""

from __future__ import annotations

import time
from collections import deque
from dataclasses import dataclass, field
from typing import Any

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.screen import Screen
from textual.widgets import DataTable, Footer, Static

from roc.tui.model import Row
from roc.tui.widgets import ListTable, TextViewer, follow

LEVELS = {0: "OK", 1: "WARN", 2: "ERROR", 3: "STALE"}
RANK = {2: 3, 3: 2, 1: 1, 0: 0}  # worst first: an error, then stale data, then a warning
HISTORY = 10000  # changes kept per status (a status that changes every second: about 3 hours)


def level_number(level: Any) -> int:
    """A status's level as decoded (an octet arrives as a one-character string)."""
    if isinstance(level, str):
        return ord(level[0]) if level else 0
    return int(level)


@dataclass
class Status:
    hardware_id: str
    name: str
    level: int = 0
    message: str = ""
    values: list[tuple[str, str]] = field(default_factory=list)
    seen: float = 0.0
    history: deque = field(default_factory=lambda: deque(maxlen=HISTORY))  # (time, level, message)

    @property
    def key(self) -> str:
        return f"{self.hardware_id}\t{self.name}"

    def update(self, value: dict[str, Any], when: float) -> None:
        level, message = level_number(value["level"]), value["message"]
        if not self.history or (level, message) != (self.level, self.message):
            self.history.append((when, level, message))
        self.level, self.message, self.seen = level, message, when
        self.values = [(pair["key"], pair["value"]) for pair in value["values"]]

    def details(self) -> str:
        lines = [f"{self.name}  (hardware id: {self.hardware_id or '-'})",
                 f"level {LEVELS.get(self.level, self.level)}: {self.message}", "", "values:"]
        lines += [f"  {key}: {value}" for key, value in self.values] or ["  (none)"]
        lines += ["", "history (changes of level or message):"]
        lines += [f"  {time.strftime('%H:%M:%S', time.localtime(when))}  {LEVELS.get(level, level):<5}  {message}"
                  for when, level, message in self.history]
        return "\n".join(lines)


def rows(statuses: dict[str, Status]) -> list[Row]:
    """Grouped by hardware id (the group with the worst status first), then the worst status first."""
    worst: dict[str, int] = {}
    for status in statuses.values():
        worst[status.hardware_id] = max(worst.get(status.hardware_id, 0), RANK.get(status.level, 3))
    ordered = sorted(statuses.values(), key=lambda s: (-worst[s.hardware_id], s.hardware_id,
                                                       -RANK.get(s.level, 3), s.name))
    problems = {0: [], 1: ["warning"], 2: ["error"], 3: ["stale"]}
    return [Row(s.key, (LEVELS.get(s.level, str(s.level)), s.hardware_id, s.name, s.message),
                problems.get(s.level, ["error"])) for s in ordered]


class Diagnostics:
    """The statuses of a diagnostics topic, by key, as they came since the TUI began to follow it."""

    def __init__(self, topic: str = "/diagnostics") -> None:
        self.topic = topic
        self.params = {"topic": topic}
        self.statuses: dict[str, Status] = {}
        self.messages = 0
        self.following = False  # a stream reads the topic into these statuses

    def take(self, messages: list[dict[str, Any]]) -> None:
        for message in messages:
            when = message["time"] * 1e-9
            for value in message["value"]["status"]:
                key = f"{value['hardware_id']}\t{value['name']}"
                self.statuses.setdefault(key, Status(value["hardware_id"], value["name"])).update(value, when)
        self.messages += len(messages)

    def errors(self) -> list[Status]:
        """The statuses in ERROR now."""
        return [status for status in self.statuses.values() if status.level == 2]


class DiagnosticsScreen(Screen):
    BINDINGS = [
        Binding("escape", "app.pop_screen", "back"),
        Binding("enter", "details", "values and history", show=False),
    ]
    DEFAULT_CSS = """
    DiagnosticsScreen #title { height: 1; background: $primary; }
    DiagnosticsScreen ListTable { height: 1fr; }
    """

    @property
    def store(self) -> Diagnostics:
        return self.app.diagnostics  # type: ignore[attr-defined]

    @property
    def statuses(self) -> dict[str, Status]:
        return self.store.statuses

    def compose(self) -> ComposeResult:
        yield Static(Text(f"diagnostics: {self.store.topic}, waiting for a status...", style="bold"), id="title")
        yield ListTable(("level", "hardware id", "name", "message"), marks=True, id="statuses")
        yield Footer()

    def on_mount(self) -> None:
        self.query_one("#statuses").focus()
        follow(self.app, self.store)
        self.draw()
        self.set_interval(1.0, self.draw)

    def draw(self) -> None:
        if not self.statuses:
            return
        counts = {name: sum(1 for s in self.statuses.values() if s.level == level) for level, name in LEVELS.items()}
        summary = "  ".join(f"{count} {name}" for name, count in counts.items() if count)
        self.query_one("#title", Static).update(Text(f"diagnostics: {self.store.topic}  {summary}  (Enter: values "
                                                     "and history)", style="bold"))
        self.query_one("#statuses", ListTable).show(rows(self.statuses))

    def on_data_table_row_selected(self, event: DataTable.RowSelected) -> None:
        self.show_details(event.row_key.value)

    def action_details(self) -> None:
        self.show_details(self.query_one("#statuses", ListTable).selected_key())

    def show_details(self, key: str | None) -> None:
        """The status's values and history, drawn again every second as new messages come."""
        if key in self.statuses:
            status = self.statuses[key]
            self.app.push_screen(TextViewer(f"diagnostic status {status.name} (Esc: back)", status.details(),
                                            follow=status.details))
