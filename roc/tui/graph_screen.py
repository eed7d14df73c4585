"""The first screen: the graph at a glance. Nodes, topics (type, publishers, subscribers, live rate
and bandwidth), services and actions in tabs, and a workspace's packages when ``roc tui`` runs in
one; counts in the header; topics with problems marked; ``/`` filters the list shown."""

from __future__ import annotations

from typing import Any

from rich.text import Text
from textual import work
from textual.app import ComposeResult
from textual.binding import Binding
from textual.screen import Screen
from textual.widgets import DataTable, Footer, Input, Static, TabbedContent, TabPane
from textual.worker import get_current_worker

from roc.errors import RocError
from roc.ros.present import plural
from roc.tui.feed import measure_rates
from roc.tui.model import Rates, counts, node_rows, topic_rows, typed_rows, visible
from roc.tui.widgets import ListTable, host

REFRESH_SECONDS = 1.0
# the topics' columns whose values change every second, at the widths of their longest values
TOPIC_WIDTHS = {"pub": 3, "sub": 3, "rate": 9, "bandwidth": 11}
# tab id -> (title, columns, marks)
LISTS = {
    "nodes": ("Nodes", ("node",), True),
    "topics": ("Topics", ("topic", "pub", "sub", "rate", "bandwidth", "type"), True),
    "services": ("Services", ("service", "type"), False),
    "actions": ("Actions", ("action", "type"), False),
}


class GraphScreen(Screen):
    BINDINGS = [
        Binding("slash", "filter", "filter"),
        # priority: Enter in the filter must not also reach the list it focuses (a race in a terminal)
        Binding("enter", "enter", "open (in the filter: keep it)", show=False, priority=True),
        Binding("escape", "clear_filter", "clear the filter", show=False),
        Binding("tab", "switch_tab(1)", "next list", show=False),
        Binding("shift+tab", "switch_tab(-1)", "previous list", show=False),
        Binding("1", "show_tab('nodes')", "nodes", show=False),
        Binding("2", "show_tab('topics')", "topics", show=False),
        Binding("3", "show_tab('services')", "services", show=False),
        Binding("4", "show_tab('actions')", "actions", show=False),
        Binding("5", "show_tab('packages')", "packages (in a workspace)", show=False),
        Binding("f", "frames", "tf frames"),
        Binding("b", "build", "build the package under the cursor and what it needs (Packages)", show=False),
        Binding("B", "build(True)", "build the whole workspace (Packages)", show=False),
        Binding("H", "toggle_hidden", "show hidden names", show=False),
    ]
    DEFAULT_CSS = """
    GraphScreen { overflow: hidden; }
    GraphScreen #header { height: 1; background: $primary; color: $text; }
    GraphScreen #detail { height: 2; color: $text-muted; }
    GraphScreen #filter { display: none; }
    GraphScreen ListTable { height: 1fr; }
    GraphScreen #tabs { height: 1fr; }
    """

    def __init__(self, workspace=None) -> None:
        super().__init__()
        self.workspace = workspace  # a roc.tui.packages.WorkspaceView, or None outside a workspace
        self.rates = Rates()
        self.hidden = False
        self.snapshot: dict[str, Any] | None = None
        self.measured: list[str] = []  # the topics the rates stream measures
        self.status = "roc tui  connecting to the roc daemon..."
        self.workspace_error = ""

    def compose(self) -> ComposeResult:
        yield Static(self.status, id="header")
        with TabbedContent(initial="topics", id="tabs"):
            for tab, (title, columns, marks) in LISTS.items():
                with TabPane(title, id=tab):
                    widths = TOPIC_WIDTHS if tab == "topics" else None
                    yield ListTable(columns, marks=marks, id=f"{tab}-table", widths=widths)
            if self.workspace is not None:
                with TabPane("Packages", id="packages"):
                    yield ListTable(self.workspace.COLUMNS, marks=True, id="packages-table")
        yield Static("", id="detail")
        yield Input(placeholder="filter: words that must all appear (Enter: keep, Esc: clear)", id="filter")
        yield Footer()

    def on_mount(self) -> None:
        self.poll()
        self.set_interval(REFRESH_SECONDS, self.poll)
        if self.workspace is not None:
            self.show_packages()
            self.set_interval(2.0, self.show_packages)
        self.query_one("#topics-table").focus()

    # -- data ------------------------------------------------------------------------------------
    @work(thread=True, exclusive=True, group="snapshot")
    def poll(self) -> None:
        try:
            snapshot = host(self).feed.snapshot()
        except RocError as error:
            self.app.call_from_thread(self.show_status, f"roc daemon: {error}")
            return
        self.app.call_from_thread(self.show_snapshot, snapshot)

    def show_status(self, text: str) -> None:
        self.status = text
        self.query_one("#header", Static).update(Text(text))

    def show_snapshot(self, snapshot: dict[str, Any]) -> None:
        self.snapshot = snapshot
        number = counts(snapshot, self.hidden)
        problems = f"  {plural(number['problems'], 'topic')} with problems" if number["problems"] else ""
        self.show_status("roc tui  " + "  ".join(plural(number[kind], kind.rstrip("s"))
                                                 for kind in ("nodes", "topics", "services", "actions")) + problems)
        self.table("nodes").show(node_rows(snapshot, self.hidden))
        self.table("topics").show(topic_rows(snapshot, self.rates, self.hidden))
        self.table("services").show(typed_rows(snapshot["services"], self.hidden))
        self.table("actions").show(typed_rows(snapshot["actions"], self.hidden))
        published = sorted(t["name"] for t in visible(snapshot["topics"], self.hidden) if t["publishers"])
        if published != self.measured:
            self.measured = published
            self.rates.keep(set(published))
            self.measure(published)
        self.show_detail()

    @work(thread=True, exclusive=True, group="rates")
    def measure(self, topics: list[str]) -> None:
        worker = get_current_worker()
        try:
            measure_rates(host(self).feed, topics, lambda event: self.app.call_from_thread(self.rates.add, event),
                          lambda: worker.is_cancelled)
        except RocError as error:
            self.app.call_from_thread(self.show_status, f"rates: {error}")

    def show_packages(self) -> None:
        try:
            self.table("packages").show(self.workspace.rows())
        except RocError as error:  # a workspace roc work list would refuse too
            if str(error) != self.workspace_error:
                self.workspace_error = str(error)
                self.notify(f"workspace {self.workspace.root}: {error}", severity="error", timeout=10)

    # -- views -----------------------------------------------------------------------------------
    def table(self, tab: str) -> ListTable:
        return self.query_one(f"#{tab}-table", ListTable)

    def active_tab(self) -> str:
        return self.query_one("#tabs", TabbedContent).active

    def show_detail(self) -> None:
        """Under the list: the problems of the row under the cursor, or how many rows the filter keeps."""
        table = self.table(self.active_tab())
        row = table.selected()
        text = "; ".join(row.problems) if row and row.problems else ""
        if table.filter:
            text = (f"filter '{table.filter}': {table.shown_count} shown (/ changes it, Esc clears it)"
                    + (f"  |  {text}" if text else ""))
        self.query_one("#detail", Static).update(Text(text))

    def on_data_table_row_highlighted(self, _event: DataTable.RowHighlighted) -> None:
        self.show_detail()

    def on_tabbed_content_tab_activated(self, event: TabbedContent.TabActivated) -> None:
        table = self.table(event.pane.id or "topics")
        table.focus()
        self.query_one("#filter", Input).value = table.filter
        self.show_detail()

    def on_data_table_row_selected(self, event: DataTable.RowSelected) -> None:
        key = event.row_key.value
        tab = self.active_tab()
        if key is None:
            return
        if tab == "packages":
            host(self).open_package(key)
        else:
            host(self).open(tab.rstrip("s"), key)

    # -- actions ---------------------------------------------------------------------------------
    def action_filter(self) -> None:
        box = self.query_one("#filter", Input)
        box.display = True
        box.value = self.table(self.active_tab()).filter
        box.focus()

    def on_input_changed(self, event: Input.Changed) -> None:
        if event.input.id == "filter":
            self.table(self.active_tab()).set_filter(event.value)
            self.show_detail()

    def action_enter(self) -> None:
        focused = self.focused
        if isinstance(focused, Input):  # the filter stays, said under the list
            focused.display = False
            self.table(self.active_tab()).focus()
        elif isinstance(focused, DataTable):
            focused.action_select_cursor()

    def action_clear_filter(self) -> None:
        box = self.query_one("#filter", Input)
        box.value = ""
        box.display = False
        self.table(self.active_tab()).set_filter("")
        self.table(self.active_tab()).focus()
        self.show_detail()

    def tabs(self) -> list[str]:
        return [*LISTS, *(["packages"] if self.workspace is not None else [])]

    def action_switch_tab(self, step: int) -> None:
        tabs = self.tabs()
        self.action_show_tab(tabs[(tabs.index(self.active_tab()) + step) % len(tabs)])

    def action_show_tab(self, tab: str) -> None:
        if tab in self.tabs():
            self.query_one("#tabs", TabbedContent).active = tab

    def action_frames(self) -> None:
        host(self).open("frame", "")

    def action_build(self, everything: bool = False) -> None:
        if self.workspace is None:
            self.notify("not in a workspace: run roc tui in one to build", severity="warning")
            return
        selected = self.table("packages").selected_key() if self.active_tab() == "packages" else None
        host(self).start_build([selected] if selected and not everything else [])

    def action_toggle_hidden(self) -> None:
        self.hidden = not self.hidden
        if self.snapshot is not None:
            self.show_snapshot(self.snapshot)
