"""The TUI's building blocks: a table that follows a changing list (filter, cursor kept on its row),
a one-line prompt, a text viewer and the help screen."""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any, Protocol, cast

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Vertical
from textual.screen import ModalScreen
from textual.widgets import DataTable, Input, Static
from textual.widgets.data_table import ColumnKey

from roc.tui.feed import Feed
from roc.tui.model import Row, cell_number, cut_widths, matches, shorten, sorted_rows
from roc.tui.problems import NO_PUBLISHER


class Host(Protocol):
    """What screens ask of the application (roc.tui.app.RocApp)."""

    feed: Feed

    def open(self, kind: str, name: str) -> None: ...

    def open_package(self, name: str) -> None: ...

    def start_build(self, packages: list[str]) -> None: ...


def host(widget) -> Host:
    return cast(Host, widget.app)


class Followed(Protocol):
    """What the app keeps of a topic while the TUI runs (its diagnostics, its logs)."""

    params: dict[str, Any]  # of the daemon's ``values`` stream
    following: bool  # a stream reads the topic into it

    def take(self, messages: list[dict[str, Any]]) -> None: ...


def follow(app, kept: Followed) -> None:
    """Read ``kept``'s topic into it from now until the app ends (the stream waits for the topic to
    appear); once (again after a stream that failed)."""
    from textual.worker import get_current_worker

    from roc.errors import RocError

    if kept.following:
        return
    kept.following = True

    def read() -> None:
        worker = get_current_worker()
        try:
            for event in host(app).feed.stream("values", kept.params, lambda: worker.is_cancelled):
                if event["event"] == "values":
                    app.call_from_thread(kept.take, event["messages"])
        except RocError as error:
            app.call_from_thread(app.notify, f"{kept.params['topic']}: {error}", severity="error")
        finally:
            kept.following = False

    app.run_worker(read, thread=True, group=f"follow {kept.params['topic']}")


WARNINGS = (NO_PUBLISHER, "duplicate name", "warning")


def severity(problems: list[str]) -> str:
    """``error`` (QoS or type problems, a node gone), ``warning`` (nobody publishes, a name used twice) or ``""``."""
    if any(p not in WARNINGS for p in problems):
        return "error"
    return "warning" if problems else ""


STYLES = {"error": "bold red", "warning": "yellow", "": ""}
MARKS = {"error": "!! ", "warning": "!  ", "": "   "}  # still seen without colour (NO_COLOR)
MARKS_WIDTH = 2


class ListTable(DataTable):
    """Rows (roc.tui.model.Row) shown as a table: on each ``show`` only changed cells are redrawn, and
    the cursor stays on the row it was on. ``filter`` keeps the rows whose cells match it. Without
    colour (NO_COLOR: ANSI mode), the cursor's row is drawn in reverse video. Home and End move the
    cursor to the first and the last row (DataTable's scroll a row cursor's table sideways, so a key
    that acts on the row under the cursor acted on another than the one the user went to)."""

    BINDINGS = [
        Binding("home", "scroll_top", "first row", show=False),
        Binding("end", "scroll_bottom", "last row", show=False),
    ]

    DEFAULT_CSS = """
    ListTable:ansi > .datatable--cursor { text-style: reverse; }
    ListTable:ansi > .datatable--header { text-style: bold underline; }
    """

    def __init__(self, columns: tuple[str, ...], marks: bool = False, widths: dict[str, int] | None = None,
                 cut_columns: tuple[str, ...] = (), **options) -> None:
        """``widths``: columns of a fixed width, for values that change all the time (rates): a
        column sized to its content is measured again, row by row, whenever a cell outgrows it.
        ``cut_columns``: columns of names (or ``type``) shortened (roc.tui.model.shorten) so that every
        column fits the table's width: none is pushed out of sight."""
        super().__init__(cursor_type="row", zebra_stripes=False, **options)
        self.columns_names = columns
        self.widths = widths or {}
        self.cut_columns = cut_columns
        self.cut: int | None = None  # the width the cut_columns' cells are cut to (None: whole)
        self.marks = marks  # a first column of marks for rows with problems
        self.filter = ""
        self.rows_by_key: dict[str, Row] = {}
        self._all: list[Row] = []
        self.sort_column: int | None = None  # the column the rows are sorted by (None: as given)
        self.descending = False
        self._showing = False
        self._shown: list[str] = []

    def on_mount(self) -> None:
        if self.marks:
            self.add_column("", key="!", width=MARKS_WIDTH)
        for name in self.columns_names:
            self.add_column(name, key=name, width=self.widths.get(name))

    def _on_hide(self, event) -> None:
        """A focused table that its tab hides lets the focus go, instead of Textual's move to a visible
        sibling: in a hidden tab the sibling is hidden too, and focusing it brings its tab back (the
        first screen's Tab or ``3`` then bounced back to the nodes). The screen focuses the new tab's list."""
        if self.screen.focused is self:  # not has_focus: it follows a moment later, by a Blur event
            self.screen.set_focus(None)
        super()._on_hide(event)

    def _update_dimensions(self, new_rows) -> None:
        """DataTable's, then the rows drawn before they were measured are drawn again where their columns
        widened: Textual 8.2 does that only on a Resize event, which does not always follow (a screen kept
        columns as wide as their headers)."""
        widths = [column.content_width for column in self.columns.values()]
        super()._update_dimensions(new_rows)
        if widths != [column.content_width for column in self.columns.values()]:
            self._update_count += 1  # part of the key of DataTable's row and line caches
            self.refresh()

    def on_resize(self, _event) -> None:
        if self._all:
            self.show(self._all)

    def fit(self, rows: list[Row]) -> int | None:
        """The width the ``cut_columns`` are cut to so that every column of ``rows`` fits the table."""
        if not self.cut_columns or not self.size.width:  # not laid out (a hidden tab): as it was
            return self.cut
        natural = {name: max([len(name), *(len(row.cells[index]) for row in rows)])
                   for index, name in enumerate(self.columns_names)}
        fixed = sum(self.widths.get(name, width) for name, width in natural.items() if name not in self.cut_columns)
        padding = 2 * self.cell_padding * (len(self.columns_names) + self.marks)
        room = (self.size.width - self.styles.scrollbar_size_vertical - padding - fixed
                - (MARKS_WIDTH if self.marks else 0))
        return cut_widths(room, [natural[name] for name in self.cut_columns])

    def _cells(self, row: Row) -> list:
        style = STYLES[severity(row.problems)]
        texts = row.cells if self.cut is None else [
            shorten(cell, self.cut, name == "type") if name in self.cut_columns else cell
            for name, cell in zip(self.columns_names, row.cells)]
        cells: list = [Text(cell, style=style) for cell in texts]  # never Rich markup: "[1, 2]" is a value
        if self.marks:
            cells.insert(0, Text(MARKS[severity(row.problems)].strip(), style=style))
        return cells

    def show(self, rows: Iterable[Row]) -> None:
        self._all = list(rows)
        if self._showing:  # asked again while drawing (clear() scrolls to the top, and a screen may watch
            # that): drawn once this is done, not twice over (the rows added twice: DuplicateKey)
            self.call_after_refresh(lambda: self.show(self._all))
            return
        self._showing = True
        try:
            self._show()
        finally:
            self._showing = False

    def _show(self) -> None:
        shown = [r for r in self._all if not self.filter or matches(self.filter, *r.cells)]
        if self.sort_column is not None:
            shown = sorted_rows(shown, self.sort_column, self.descending)
        if not self._shown and len(shown) > self.app.size.height:
            # the first fill: the rows a screen can show now (a first paint of 200 topics costs their
            # measuring), the others right after it is painted
            shown = shown[:self.app.size.height]
            self.call_after_refresh(lambda: self.show(self._all))
        keys = [r.key for r in shown]
        current = self.selected_key()
        cut = self.fit(shown)
        if cut != self.cut:  # every row drawn again, its columns measured anew
            self.cut = cut
            self.clear()
            self._shown, self.rows_by_key = [], {}
            for name in self.cut_columns:
                self.columns[ColumnKey(name)].content_width = len(name)
        if keys[:len(self._shown)] != self._shown:  # rows gone or moved: all drawn again
            self.clear()
            self._shown, self.rows_by_key = [], {}
        columns = (["!"] if self.marks else []) + list(self.columns_names)
        for row in shown[:len(self._shown)]:  # the rows drawn before: only their changed cells
            old = self.rows_by_key.get(row.key)
            if old == row:
                continue
            for column, value, before in zip(columns, self._cells(row), self._cells(old) if old else []):
                if value != before:
                    width = self.columns[ColumnKey(column)].content_width
                    grows = column not in self.widths and value.cell_len > width
                    self.update_cell(row.key, column, value, update_width=grows)
        for row in shown[len(self._shown):]:  # new rows, at the end
            self.add_row(*self._cells(row), key=row.key)
        if not self._shown and current in keys:
            self.move_cursor(row=keys.index(current), animate=False)
        self._shown = keys
        self.rows_by_key = {r.key: r for r in shown}

    def sort_by(self, column: int, descending: bool | None = None) -> None:
        """Rows sorted by ``column``: numbers largest first (as top), texts from A, unless ``descending`` says;
        its header marked ▼ or ▲."""
        if descending is None:
            descending = any(cell_number(row.cells[column]) is not None for row in self._all)
        for index, name in enumerate(self.columns_names):
            mark = (" ▼" if descending else " ▲") if index == column else ""
            self.columns[ColumnKey(name)].label = Text(name + mark)
        self.sort_column, self.descending = column, descending
        self._shown = []  # every row drawn again, in the new order
        self.clear()
        self.show(self._all)

    def sort_next(self) -> None:
        """Sorted by the next column (after the last: as given)."""
        column = 0 if self.sort_column is None else self.sort_column + 1
        if column < len(self.columns_names):
            self.sort_by(column)
        else:
            for name in self.columns_names:
                self.columns[ColumnKey(name)].label = Text(name)
            self.sort_column = None
            self._shown = []
            self.clear()
            self.show(self._all)

    def sort_reversed(self) -> None:
        if self.sort_column is not None:
            self.sort_by(self.sort_column, not self.descending)

    def on_data_table_header_selected(self, event: DataTable.HeaderSelected) -> None:
        """A click on a column's header sorts by it (again: the other way)."""
        column = self.columns_names.index(str(event.column_key.value)) if event.column_key.value in self.columns_names \
            else None
        if column is not None:
            self.sort_by(column, not self.descending if column == self.sort_column else None)

    def set_filter(self, text: str) -> None:
        self.filter = text
        self.show(self._all)

    def selected_key(self) -> str | None:
        if not self._shown or self.cursor_row < 0 or self.cursor_row >= len(self._shown):
            return None
        return self._shown[self.cursor_row]

    def select(self, key: str) -> None:
        """The cursor to the row of ``key`` (if shown)."""
        if key in self._shown:
            self.move_cursor(row=self._shown.index(key), animate=False)

    def selected(self) -> Row | None:
        key = self.selected_key()
        return self.rows_by_key.get(key) if key else None

    def keys_in_view(self, margin: int = 2) -> set[str]:
        """The keys of the rows on the screen (and ``margin`` more each side)."""
        first = int(self.scroll_y)
        return set(self._shown[max(0, first - margin):first + self.size.height + margin])

    @property
    def shown_count(self) -> int:
        return len(self._shown)


class Prompt(ModalScreen[str | None]):
    """One line of input; Enter gives it, Esc gives None."""

    BINDINGS = [Binding("escape", "cancel", "cancel")]
    DEFAULT_CSS = """
    Prompt { align: center middle; }
    Prompt > Vertical { width: 72; height: auto; border: round $accent; background: $surface; padding: 0 1; }
    """

    def __init__(self, title: str, value: str = "") -> None:
        super().__init__()
        self.title_text, self.value = title, value

    def compose(self) -> ComposeResult:
        with Vertical():
            yield Static(self.title_text)
            yield Input(self.value, id="prompt")

    def on_input_submitted(self, event: Input.Submitted) -> None:
        self.dismiss(event.value)

    def action_cancel(self) -> None:
        self.dismiss(None)


class TextViewer(ModalScreen[None]):
    """A read-only text (a failed package's stderr, the help); Esc or q closes it."""

    BINDINGS = [Binding("escape,q", "close", "close")]
    DEFAULT_CSS = """
    TextViewer { align: center middle; }
    TextViewer > Vertical { width: 100%; height: 100%; border: round $accent; background: $surface; }
    TextViewer TextArea { height: 1fr; }
    """

    def __init__(self, title: str, text: str, follow: Callable[[], str] | None = None) -> None:
        """``follow``: the text drawn again every second (where the reader scrolled to kept)."""
        super().__init__()
        self.title_text, self.text, self.follow = title, text, follow

    def compose(self) -> ComposeResult:
        with Vertical():
            yield Static(Text(self.title_text, style="bold"))
            from textual.widgets import TextArea  # not before a viewer opens: a first screen without it is faster

            yield TextArea(self.text, read_only=True, soft_wrap=False, id="viewer")

    def on_mount(self) -> None:
        if self.follow is not None:
            self.set_interval(1.0, self.draw_again)

    def draw_again(self) -> None:
        from textual.widgets import TextArea

        assert self.follow is not None
        text = self.follow()
        viewer = self.query_one("#viewer", TextArea)
        if text != viewer.text:
            scrolled = viewer.scroll_offset
            viewer.text = text
            viewer.scroll_to(scrolled.x, scrolled.y, animate=False)

    def action_close(self) -> None:
        self.dismiss(None)


def binding_lines(title: str, bindings: Iterable[BindingType], display: Callable[[Binding], str]) -> list[str]:
    """One line per key binding: its keys as ``display`` shows a key (``/``, ``esc``) and what it does."""
    lines = []
    for binding in bindings:
        if isinstance(binding, Binding) and binding.description:
            keys = ", ".join(display(Binding(key.strip(), binding.action)) for key in binding.key.split(","))
            lines.append(f"  {keys:<18} {binding.description}")
    return [title, *lines, ""] if lines else []
