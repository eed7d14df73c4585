"""The ``roc launch`` runs of this host (roc.launch.status): each process with its run, pid, state,
restarts and last line of output, refreshed every second; Enter shows a process's output as the logs
view shows /rosout; ``s`` stops a process (on purpose: the run goes on, and does not fail for it), ``R``
restarts one of a roc.toml system (the launch library starts a launch file's processes once)."""

from __future__ import annotations

from typing import Any

from rich.text import Text
from textual import work
from textual.app import ComposeResult
from textual.binding import Binding
from textual.screen import Screen
from textual.widgets import DataTable, Footer, Static

from roc.errors import RocError
from roc.tui.model import Row
from roc.tui.widgets import ListTable

PROBLEM_STATES = {"failed": ["error"], "waiting": ["warning"]}


class LaunchScreen(Screen):
    BINDINGS = [
        Binding("escape", "app.pop_screen", "back"),
        Binding("s", "control('stop')", "stop the process"),
        Binding("R", "control('restart')", "restart the process"),
    ]
    DEFAULT_CSS = """
    LaunchScreen #title { height: 1; background: $primary; }
    LaunchScreen ListTable { height: 1fr; }
    LaunchScreen #detail { height: 1; color: $text-muted; }
    """

    def __init__(self) -> None:
        super().__init__()
        self.runs: dict[str, Any] = {}  # row key -> the roc.launch.status.RunStatus of its run
        self.restartable: dict[str, bool] = {}  # row key -> whether its run can start it again

    def compose(self) -> ComposeResult:
        yield Static(Text("roc launch runs on this host: looking...", style="bold"), id="title")
        yield ListTable(("process", "run", "pid", "state", "restarts", "last line"), marks=True, id="processes")
        yield Static("", id="detail")
        yield Footer()

    def on_mount(self) -> None:
        self.query_one("#processes").focus()
        self.poll()
        self.set_interval(1.0, self.poll)

    @work(thread=True, exclusive=True, group="launch")
    def poll(self) -> None:
        from roc.launch.status import runs

        found = runs()
        rows, owners, restartable = [], {}, {}
        for status, answer in found:
            for process in answer["processes"]:
                key = f"{answer['pid']}:{process['name']}"
                owners[key] = status
                restartable[key] = answer.get("restartable", True)
                state = process["state"] + (f" ({process['detail']})" if process["detail"] else "")
                shown = f"{process['host']}:{process['name']}" if process.get("host") else process["name"]
                rows.append(Row(key, (shown, f"{answer['title']} [{answer['pid']}]",
                                      str(process["pid"] or "-"), state, str(process["restarts"]),
                                      process["last_line"]), PROBLEM_STATES.get(process["state"], [])))
        self.runs, self.restartable = owners, restartable
        title = (f"roc launch runs on this host: {len(found)}  (Enter: output, s: stop, R: restart a roc.toml "
                 "system's process)" if found else "no roc launch runs on this host (for this user)")
        self.app.call_from_thread(self.show, rows, title)

    def show(self, rows: list[Row], title: str) -> None:
        self.query_one("#title", Static).update(Text(title, style="bold"))
        self.query_one("#processes", ListTable).show(rows)
        self.show_detail()

    def show_detail(self) -> None:
        """Under the list, what can be done with the process under the cursor."""
        key = self.query_one("#processes", ListTable).selected_key()
        text = "" if key is None else (
            "Enter: its output, s: stop it, R: restart it" if self.restartable.get(key, True) else
            "Enter: its output, s: stop it; a launch file's process cannot be restarted (the launch library "
            "starts each once)")
        self.query_one("#detail", Static).update(Text(text))

    def on_data_table_row_highlighted(self, _event: DataTable.RowHighlighted) -> None:
        self.show_detail()

    def selected(self) -> tuple[Any, str] | None:
        key = self.query_one("#processes", ListTable).selected_key()
        if key is None or key not in self.runs:
            return None
        return self.runs[key], key.split(":", 1)[1]

    def on_data_table_row_selected(self, _event: DataTable.RowSelected) -> None:
        from roc.tui.logs_screen import LogsScreen

        chosen = self.selected()
        if chosen is not None:
            self.app.push_screen(LogsScreen(process=chosen[1], launch=chosen[0]))

    def action_control(self, method: str) -> None:
        chosen = self.selected()
        if chosen is None:
            return
        status, process = chosen
        key = self.query_one("#processes", ListTable).selected_key() or ""
        if method == "restart" and not self.restartable.get(key, True):
            self.notify(f"{process} was started by a launch file: the launch library starts each of its processes "
                        "once and cannot start one again on request (a system declared in roc.toml can)",
                        title="cannot restart", timeout=8)
            self.query_one("#detail", Static).update(Text(f"{process}: cannot restart a launch file's process (the "
                                                          "launch library starts each once); s stops it", style="bold"))
            return
        try:
            status.request(method, process=process)
        except (RocError, OSError) as error:
            self.notify(f"{method} {process}: {error}", severity="error")
            return
        self.notify(f"{method} {process}: asked")
