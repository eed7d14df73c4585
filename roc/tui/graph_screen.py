"""The first screen: the system at a glance. Nodes (with their process's CPU and memory) beside topics
(publishers, subscribers, live rate and bandwidth, type), then services, actions and a workspace's
packages in tabs; counts in the header; a line that counts the real problems (roc.tui.problems: the
graph's, and the /diagnostics statuses in ERROR), ``p`` going to each in turn; ``/`` filters the list shown."""

from __future__ import annotations

from typing import Any

from rich.text import Text
from textual import work
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Container
from textual.events import Resize
from textual.screen import Screen
from textual.widgets import DataTable, Footer, Input, Static, TabbedContent, TabPane
from textual.worker import get_current_worker

from roc.errors import RocError
from roc.render import plural
from roc.tui.feed import measure_rates
from roc.tui.model import Rates, counts, node_rows, topic_rows, typed_rows, visible
from roc.tui.problems import Problem, Watch
from roc.tui.processes import Processes
from roc.tui.widgets import ListTable, follow, host

REFRESH_SECONDS = 1.0
# the topics' columns whose values change every second, at the widths of their longest values
WIDTHS = {"topics": {"pub": 3, "sub": 3, "rate": 9, "bandwidth": 11}, "nodes": {"cpu": 6, "mem": 5, "pid": 7}}
# list -> (columns, marks, the columns cut to fit the screen); nodes and topics side by side in the first
# tab, the others a tab each
LISTS = {
    "nodes": (("node", "cpu", "mem", "pid"), True, ("node",)),
    "topics": (("topic", "pub", "sub", "rate", "bandwidth", "type"), True, ("topic", "type")),
    "services": (("service", "type"), False, ("service", "type")),
    "actions": (("action", "type"), False, ("action", "type")),
}
SYSTEM = ("nodes", "topics")
# below this many columns, the nodes are above the topics instead of beside them: beside them, the topics'
# names and types would get some 10 columns each
NARROW = 120
DIAGNOSTICS = "/diagnostics"  # followed from when it is published: its statuses in ERROR are problems


class ListTabs(TabbedContent):
    """Tabs that change only when asked (a key, a click on a tab), never because a list inside one got the
    focus: Textual follows the focus a moment later, so a tab chosen just then was switched back."""

    def _on_tab_pane_focused(self, event: TabPane.Focused) -> None:
        event.prevent_default()
        event.stop()


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
        Binding("p", "next_problem", "next problem"),
        Binding("c", "forget_gone", "forget the nodes gone", show=False),
        Binding("f", "frames", "tf frames"),
        Binding("b", "build", "build the package under the cursor and what it needs (Packages)", show=False),
        Binding("B", "build(True)", "build the whole workspace (Packages)", show=False),
        Binding("H", "toggle_hidden", "show hidden names", show=False),
        Binding("s", "sort", "sort the list by its next column (numbers largest first)", show=False),
        Binding("S", "sort_reversed", "sort the other way", show=False),
    ]
    DEFAULT_CSS = """
    GraphScreen { overflow: hidden; }
    GraphScreen #header { height: 1; background: $primary; color: $text; }
    GraphScreen #problems { height: 1; }
    GraphScreen #detail { height: 2; color: $text-muted; }
    GraphScreen #filter { display: none; }
    GraphScreen ListTable { height: 1fr; }
    GraphScreen #tabs { height: 1fr; }
    GraphScreen #system { layout: horizontal; height: 1fr; }
    GraphScreen #system.narrow { layout: vertical; }
    GraphScreen #system #nodes-table { width: 1fr; min-width: 46; max-width: 72; }
    GraphScreen #system #topics-table { width: 2fr; }
    GraphScreen #system.narrow #nodes-table { width: 1fr; max-width: 100%; height: 2fr; }
    GraphScreen #system.narrow #topics-table { width: 1fr; height: 3fr; }
    """

    def __init__(self, workspace=None, checks=None) -> None:
        """``checks``: roc.toml's ``[check]`` expectations (roc.check.expectations.CheckFile), or None."""
        super().__init__()
        self.workspace = workspace  # a roc.tui.packages.WorkspaceView, or None outside a workspace
        self.problem_watch = Watch(checks)
        self.processes = Processes()
        self.problems: list[Problem] = []
        self.problem_index = -1
        self.current = "topics"  # the list the keys act on (the focused one)
        self.rates = Rates()
        self.hidden = False
        self.snapshot: dict[str, Any] | None = None
        self.measured: list[str] = []  # the topics the rates stream measures
        self.status = "roc tui  connecting to the roc daemon..."
        self.shown_texts: dict[str, Text] = {}  # selector -> the text shown there
        self.workspace_error = ""

    def compose(self) -> ComposeResult:
        yield Static(self.status, id="header")
        yield Static("", id="problems")
        with ListTabs(initial="system-tab", id="tabs"):
            narrow = "narrow" if self.app.size.width < NARROW else ""  # as on_resize sets it: no restyle then
            with TabPane("System", id="system-tab"), Container(id="system", classes=narrow):
                for name in SYSTEM:
                    yield self.list_table(name)
            for name in ("services", "actions"):
                with TabPane(name.title(), id=name):
                    yield self.list_table(name)
            if self.workspace is not None:
                with TabPane("Packages", id="packages"):
                    yield ListTable(self.workspace.COLUMNS, marks=True, id="packages-table")
        yield Static("", id="detail")
        yield Input(placeholder="filter: words that must all appear (Enter: keep, Esc: clear)", id="filter")
        yield Footer()

    @staticmethod
    def list_table(name: str) -> ListTable:
        columns, marks, cut = LISTS[name]
        return ListTable(columns, marks=marks, id=f"{name}-table", widths=WIDTHS.get(name), cut_columns=cut)

    def on_resize(self, event: Resize) -> None:
        self.query_one("#system").set_class(event.size.width < NARROW, "narrow")

    def on_mount(self) -> None:
        follow(self.app, self.app.logs)  # type: ignore[attr-defined]  # /rosout from the start: the logs view's backlog
        self.poll()
        self.set_interval(REFRESH_SECONDS, self.poll)
        if self.workspace is not None:
            self.show_packages()
            self.set_interval(2.0, self.show_packages)
        self.query_one("#topics-table").focus()
        self.watch(self.table("topics"), "scroll_y", self.show_again, init=False)

    # -- data ------------------------------------------------------------------------------------
    @work(thread=True, exclusive=True, group="snapshot")
    def poll(self) -> None:
        try:
            snapshot = host(self).feed.snapshot()
        except RocError as error:
            self.app.call_from_thread(self.show_status, f"roc daemon: {error}")
            return
        usage = self.processes.update(snapshot)  # psutil: off the app's thread
        self.app.call_from_thread(self.show_snapshot, snapshot, usage)

    def show_status(self, text: str) -> None:
        self.status = text
        if self.query("#header"):  # none once the app is closing
            self.put("#header", Text(text))

    def show_snapshot(self, snapshot: dict[str, Any], usage=None) -> None:
        if not self.query("#problems"):  # the app is closing
            return
        self.snapshot = snapshot
        if self.app.screen is not self:  # under another screen: drawn when it is back (on_screen_resume)
            self.problem_watch.nodes_gone([n["full_name"] for n in visible(snapshot["nodes"], self.hidden)])
            return
        number = counts(snapshot, self.hidden)
        self.show_status("roc tui  " + "  ".join(plural(number[kind], kind.rstrip("s"))
                                                 for kind in ("nodes", "topics", "services", "actions")))
        topics = visible(snapshot["topics"], self.hidden)
        nodes = [n["full_name"] for n in visible(snapshot["nodes"], self.hidden)]
        if any(t["name"] == DIAGNOSTICS and t["publishers"] for t in topics):
            follow(self.app, self.app.diagnostics)  # type: ignore[attr-defined]
        self.problems = self.problem_watch.problems(topics, nodes, self.rates.rate, [
            (s.key, f"{DIAGNOSTICS} {s.name}: ERROR {s.message} (:diagnostics)")
            for s in self.app.diagnostics.errors()])  # type: ignore[attr-defined]
        self.show_problems()
        gone = self.problem_watch.nodes_gone(nodes)
        self.table("nodes").show(node_rows(snapshot, self.hidden, usage or self.processes.usage, gone))
        topics_table = self.table("topics")
        self.rates.in_view = topics_table.keys_in_view() if topics_table.shown_count else None
        topics_table.show(topic_rows(snapshot, self.rates, self.hidden))
        self.table("services").show(typed_rows(snapshot["services"], self.hidden))
        self.table("actions").show(typed_rows(snapshot["actions"], self.hidden))
        published = sorted(t["name"] for t in topics if t["publishers"])
        if published != self.measured:
            self.measured = published
            self.rates.keep(set(published))
            self.call_after_refresh(self.measure, published)  # once this is on the screen
        self.show_detail()

    def on_screen_resume(self) -> None:
        self.show_again()

    def show_again(self, *_changed) -> None:
        """The lists drawn again from the last snapshot: rows that came into view (scrolled, filtered,
        their tab chosen) get their rates measured now (see Rates.texts)."""
        if self.snapshot is not None:
            self.show_snapshot(self.snapshot)
        else:
            self.show_detail()

    def put(self, selector: str, text: Text) -> None:
        """Show ``text`` in a line of the screen, if it changed (a line drawn again costs a layout)."""
        if self.shown_texts.get(selector) != text:
            self.shown_texts[selector] = text
            self.query_one(selector, Static).update(text)

    def show_problems(self) -> None:
        """The problems line: how many, the first (or the one ``p`` went to), and the key."""
        if not self.problems:
            self.put("#problems", Text("no problems", style="green"))
            return
        index = self.problem_index if 0 <= self.problem_index < len(self.problems) else 0
        severity = "bold red" if any(p.severity == "error" for p in self.problems) else "yellow"
        self.put("#problems", Text.assemble((f"{plural(len(self.problems), 'problem')}", severity),
                                            f" ({index + 1}/{len(self.problems)}, p: next)  ",
                                            self.problems[index].text))

    @work(thread=True, exclusive=True, group="rates")
    def measure(self, topics: list[str]) -> None:
        worker = get_current_worker()
        self.app.call_from_thread(self.rates.restart)
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
    def table(self, name: str) -> ListTable:
        return self.query_one(f"#{name}-table", ListTable)

    def active_tab(self) -> str:
        """The list the keys act on: nodes or topics (the first tab), services, actions, packages."""
        tab = self.query_one("#tabs", TabbedContent).active
        return self.current if tab == "system-tab" else tab

    def show_detail(self) -> None:
        """Under the list: the problems of the row under the cursor, or how many rows the filter keeps."""
        table = self.table(self.active_tab())
        row = table.selected()
        text = "; ".join(row.problems) if row and row.problems else ""
        if table.filter:
            text = (f"filter '{table.filter}': {table.shown_count} shown (/ changes it, Esc clears it)"
                    + (f"  |  {text}" if text else ""))
        self.put("#detail", Text(text))

    def on_data_table_row_highlighted(self, event: DataTable.RowHighlighted) -> None:
        if event.data_table.has_focus:  # a list redrawn in the background is not the one the keys act on
            self.note_focus(event.data_table)
        self.show_detail()

    def on_descendant_focus(self, event) -> None:
        if isinstance(event.widget, ListTable):
            self.note_focus(event.widget)

    def note_focus(self, table: DataTable) -> None:
        name = (table.id or "").removesuffix("-table")
        if name in SYSTEM and self.current != name:
            self.current = name
            self.query_one("#filter", Input).value = self.table(name).filter
            self.show_detail()

    def on_tabbed_content_tab_activated(self, event: TabbedContent.TabActivated) -> None:
        table = self.table(self.active_tab())
        table.focus()
        self.query_one("#filter", Input).value = table.filter
        self.show_again()

    def on_data_table_row_selected(self, event: DataTable.RowSelected) -> None:
        key = event.row_key.value
        tab = (event.data_table.id or "").removesuffix("-table")
        row = event.data_table.rows_by_key.get(key) if key and isinstance(event.data_table, ListTable) else None
        if key is None or row is not None and "gone" in row.problems:
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
            self.show_again()

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

    def action_show_tab(self, name: str) -> None:
        if name not in self.tabs():
            return
        if name in SYSTEM:
            self.current = name
            self.query_one("#tabs", TabbedContent).active = "system-tab"
            self.table(name).focus()
            self.query_one("#filter", Input).value = self.table(name).filter
            self.show_detail()
        else:
            self.query_one("#tabs", TabbedContent).active = name

    def action_next_problem(self) -> None:
        """The cursor to the row of the next problem (a topic or a node), its text on the problems line."""
        if not self.problems:
            self.notify("no problems")
            return
        self.problem_index = (self.problem_index + 1) % len(self.problems)
        problem = self.problems[self.problem_index]
        if problem.kind == "diagnostic":  # in the diagnostics view, not in a list here: said on the line
            self.show_problems()
            return
        self.action_show_tab(f"{problem.kind}s")
        table = self.table(f"{problem.kind}s")
        if problem.name not in table.rows_by_key and table.filter:
            table.set_filter("")
        table.select(problem.name)
        self.show_problems()
        self.show_detail()

    def action_forget_gone(self) -> None:
        self.problem_watch.forget_gone()
        if self.snapshot is not None:
            self.show_snapshot(self.snapshot)

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

    def action_sort(self) -> None:
        self.table(self.active_tab()).sort_next()
        self.show_again()

    def action_sort_reversed(self) -> None:
        self.table(self.active_tab()).sort_reversed()
        self.show_again()
