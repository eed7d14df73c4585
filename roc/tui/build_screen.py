"""The live build: one row per package (state, elapsed time, current step) drawn from the run's
roc.handlers.board.TaskBoard, a failed package's stderr a keypress away (Enter or ``e``). The build
runs on a thread of its own (roc.tui.build_run); ``x`` stops it as Ctrl+C stops ``roc work build``."""

from __future__ import annotations

import time

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.screen import Screen
from textual.widgets import DataTable, Footer, Static

from roc.handlers.board import ABORTED, FAILED, NOT_STARTED, QUEUED, RUNNING, SKIPPED, TaskRow
from roc.handlers.console import format_duration
from roc.tui.model import Row
from roc.tui.widgets import ListTable, TextViewer

REDRAW_SECONDS = 0.25
PROBLEMS = {FAILED: "failed", ABORTED: "aborted", SKIPPED: "skipped", NOT_STARTED: "not started"}


def board_row(row: TaskRow, now: float) -> Row:
    """A task as a row: its step while it runs, the last line of its failure (or what skipped it) after."""
    elapsed = row.elapsed(now)
    reason = row.reason.splitlines()[-1] if row.reason else ""
    return Row(row.key, (row.label, row.state, format_duration(elapsed) if elapsed is not None else "-",
                         row.step_text() or reason), [PROBLEMS[row.state]] if row.state in PROBLEMS else [])


def progress_text(rows: list[TaskRow], seconds: float, finished: bool, interrupted: bool) -> str:
    done = sum(1 for r in rows if r.state not in (QUEUED, RUNNING, NOT_STARTED))
    running = sum(1 for r in rows if r.state == RUNNING)
    failed = sum(1 for r in rows if r.state == FAILED)
    state = "interrupted" if interrupted else "finished" if finished else "building"
    text = f"{state} [{format_duration(seconds)}]  {done}/{len(rows)} done  {running} running"
    return text + (f"  {failed} failed (Enter: stderr)" if failed else "")


class BuildScreen(Screen):
    BINDINGS = [
        Binding("escape", "app.pop_screen", "back"),
        Binding("e", "stderr", "stderr"),
        Binding("x", "stop", "stop the build"),
    ]
    DEFAULT_CSS = """
    BuildScreen #progress { height: 1; background: $primary; }
    BuildScreen ListTable { height: 1fr; }
    """

    def __init__(self, build) -> None:
        super().__init__()
        self.build = build  # a roc.tui.build_run.BuildRun
        self.drawn_changes = -1

    def compose(self) -> ComposeResult:
        yield Static("build starting...", id="progress")
        yield ListTable(("package", "state", "elapsed", "step"), marks=True, id="tasks")
        yield Footer()

    def on_mount(self) -> None:
        self.query_one("#tasks").focus()
        self.set_interval(REDRAW_SECONDS, self.redraw)

    def redraw(self) -> None:
        board = self.build.board
        rows = board.rows()
        now = time.monotonic()
        self.query_one("#tasks", ListTable).show([board_row(row, now) for row in rows])
        ended = board.ended_at is not None and board.started_at is not None
        took = board.ended_at - board.started_at if ended else now - self.build.started
        text = progress_text(rows, took, board.finished, board.interrupted)
        if self.build.error:
            text += f"  error: {self.build.error}"
        self.query_one("#progress", Static).update(Text(text, style="bold"))

    def on_data_table_row_selected(self, _event: DataTable.RowSelected) -> None:
        self.action_stderr()

    def action_stderr(self) -> None:
        key = self.query_one("#tasks", ListTable).selected_key()
        row = next((r for r in self.build.board.rows() if r.key == key), None)
        if row is None:
            return
        text = row.stderr.decode(errors="replace") or row.reason or "(no stderr output)"
        self.app.push_screen(TextViewer(f"{row.label}: {row.state}; stderr (Esc: back)", text))

    def action_stop(self) -> None:
        if self.build.running():
            self.build.stop.set()
            self.notify("stopping the build...")
