"""A node: what it publishes, subscribes, serves and calls (Enter opens one), and its parameters:
Enter edits a value (typed as ``roc param set`` types it), ``d`` dumps them to a YAML file; a managed
node's lifecycle state, ``t`` triggering a transition (as ``roc lifecycle set``); ``l`` its logs."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml
from rich.text import Text
from textual import work
from textual.app import ComposeResult
from textual.binding import Binding
from textual.screen import Screen
from textual.widgets import DataTable, Footer, Static

from roc.commands.lifecycle.managed import GET_STATE
from roc.commands.param.dump import nested
from roc.commands.param.set import parse_value
from roc.errors import RocError
from roc.fsutil import write_text_atomic
from roc.render import to_yaml
from roc.tui.model import Row
from roc.tui.widgets import ListTable, Prompt, host

# node_info's lists: (key, what a row of it is, the kind of thing Enter opens)
SIDES = (("publishers", "publishes", "topic"), ("subscribers", "subscribes", "topic"),
         ("service_servers", "serves", "service"), ("service_clients", "calls", "service"),
         ("action_servers", "serves action", "action"), ("action_clients", "calls action", "action"))


def value_text(value: Any) -> str:
    """A parameter value as YAML on one line, as it is typed back in."""
    return yaml.safe_dump(value, default_flow_style=True, width=1 << 20).strip().removesuffix("\n...").removesuffix(
        "...").strip()


def typed_for(current_type: str, text: str) -> dict[str, Any]:
    """``{type, value}`` of an edited value: YAML typed as ``roc param set`` types it, except that an
    integer given to a double parameter stays a double (``2`` for ``2.0``)."""
    typed = parse_value(text)
    if current_type == "double" and typed["type"] == "integer":
        return {"type": "double", "value": float(typed["value"])}
    if current_type == "double array" and typed["type"] == "integer array":
        return {"type": "double array", "value": [float(v) for v in typed["value"]]}
    return typed


class NodeScreen(Screen):
    BINDINGS = [
        Binding("escape", "app.pop_screen", "back"),
        Binding("e", "edit", "edit parameter"),
        Binding("d", "dump", "dump parameters"),
        Binding("r", "reload", "reload"),
        Binding("t", "transition", "lifecycle transition (a managed node)"),
        Binding("l", "logs", "the node's logs"),
    ]
    DEFAULT_CSS = """
    NodeScreen #title { height: 1; background: $primary; }
    NodeScreen ListTable { height: 1fr; }
    NodeScreen .caption { height: 1; color: $text-muted; }
    NodeScreen #lifecycle { height: auto; }
    """

    def __init__(self, node: str) -> None:
        super().__init__()
        self.node = node
        self.parameters: dict[str, dict[str, Any]] = {}  # name -> {type, value}
        self.managed = False
        self.transitions: list[dict[str, Any]] = []  # available now: {transition: {id, label}, ...}

    def compose(self) -> ComposeResult:
        yield Static(Text(f"node {self.node}", style="bold"), id="title")
        yield Static("", id="lifecycle")
        yield Static("interfaces (Enter: open)", classes="caption")
        yield ListTable(("what", "name", "type"), id="interfaces")
        yield Static("parameters (Enter or e: edit, d: dump to a file)", classes="caption", id="params-caption")
        yield ListTable(("parameter", "type", "value"), id="parameters")
        yield Footer()

    def on_mount(self) -> None:
        self.query_one("#interfaces").focus()
        self.action_reload()

    def action_reload(self) -> None:
        self.load()

    @work(thread=True, exclusive=True, group="node")
    def load(self) -> None:
        feed = host(self).feed
        try:
            info = feed.query("node_info", {"node": self.node})
        except RocError as error:
            self.app.call_from_thread(self.notify, str(error), severity="error")
            return
        rows = [Row(f"{kind}:{side}:{entry['name']}", (what, entry["name"], ", ".join(entry["types"])))
                for side, what, kind in SIDES for entry in info[side]]
        self.app.call_from_thread(self.query_one("#interfaces", ListTable).show, rows)
        self.managed = any(entry["name"] == f"{self.node}/get_state" and GET_STATE in entry["types"]
                           for entry in info["service_servers"])
        if self.managed:
            self.load_lifecycle()
        try:
            names = [p["name"] for p in feed.query("param_list", {"node": self.node})[0]["parameters"]]
            values = feed.query("param_get", {"node": self.node, "names": names}) if names else []
        except RocError as error:
            self.app.call_from_thread(self.query_one("#params-caption", Static).update, f"parameters: {error}")
            return
        self.parameters = dict(zip(names, values))
        self.app.call_from_thread(self.query_one("#parameters", ListTable).show, [
            Row(name, (name, value["type"], value_text(value["value"]))) for name, value in self.parameters.items()])

    def load_lifecycle(self) -> None:
        """The managed node's state and the transitions it can take (in a worker's thread)."""
        feed = host(self).feed
        try:
            state = feed.call(f"{self.node}/get_state", GET_STATE, {})["current_state"]
            self.transitions = feed.call(f"{self.node}/get_available_transitions",
                                         "lifecycle_msgs/srv/GetAvailableTransitions", {})["available_transitions"]
        except RocError as error:
            self.app.call_from_thread(self.query_one("#lifecycle", Static).update, f"lifecycle: {error}")
            return
        choices = ", ".join(t["transition"]["label"] for t in self.transitions) or "none"
        text = f"lifecycle state: {state['label']} [{state['id']}]  (t: transition: {choices})"
        self.app.call_from_thread(self.query_one("#lifecycle", Static).update, Text(text, style="bold"))

    def action_transition(self) -> None:
        if not self.managed:
            self.notify(f"{self.node} is not a managed node", severity="warning")
            return
        labels = [t["transition"]["label"] for t in self.transitions]

        def done(text: str | None) -> None:
            chosen = next((t["transition"] for t in self.transitions if text and text.strip() in
                           (t["transition"]["label"], str(t["transition"]["id"]))), None)
            if chosen is not None:
                self.change_state(chosen)
            elif text:
                self.notify(f"unknown transition '{text}'; available: {', '.join(labels)}", severity="error")
        self.app.push_screen(Prompt(f"transition of {self.node} ({', '.join(labels) or 'none available'})",
                                    labels[0] if labels else ""), done)

    @work(thread=True, group="node-write")
    def change_state(self, transition: dict[str, Any]) -> None:
        try:
            done = host(self).feed.call(f"{self.node}/change_state", "lifecycle_msgs/srv/ChangeState",
                                        {"transition": transition})["success"]
        except RocError as error:
            self.app.call_from_thread(self.notify, f"transition failed: {error}", severity="error")
            return
        if done:
            self.app.call_from_thread(self.notify, f"{transition['label']}: transitioning successful")
        else:
            self.app.call_from_thread(self.notify, f"{transition['label']}: transitioning failed", severity="error")
        self.load_lifecycle()

    def action_logs(self) -> None:
        from roc.tui.logs_screen import LogsScreen

        self.app.push_screen(LogsScreen(node=self.node))

    def on_data_table_row_selected(self, event: DataTable.RowSelected) -> None:
        key = event.row_key.value or ""
        if event.data_table.id == "parameters":
            self.edit(key)
        else:
            kind, _, name = key.split(":", 2)
            host(self).open(kind, name)

    def action_edit(self) -> None:
        name = self.query_one("#parameters", ListTable).selected_key()
        if name:
            self.edit(name)

    def edit(self, name: str) -> None:
        current = self.parameters[name]

        def done(text: str | None) -> None:
            if text is not None:
                self.set_parameter(name, typed_for(current["type"], text))
        self.app.push_screen(Prompt(f"{self.node} {name} ({current['type']}): new value in YAML",
                                    value_text(current["value"])), done)

    @work(thread=True, group="node-write")
    def set_parameter(self, name: str, typed: dict[str, Any]) -> None:
        try:
            result = host(self).feed.query("param_set", {"node": self.node, "parameters": [{"name": name, **typed}]})[0]
        except RocError as error:
            result = {"successful": False, "reason": str(error)}
        if result["successful"]:
            self.app.call_from_thread(self.notify, f"{name} set to {value_text(typed['value'])}")
        else:
            self.app.call_from_thread(self.notify, f"setting {name} failed: {result['reason'] or 'refused'}",
                                      severity="error")
        self.load()

    def action_dump(self) -> None:
        default = f"{self.node.strip('/').replace('/', '__') or 'node'}.yaml"

        def done(path: str | None) -> None:
            if path:
                self.dump(Path(path).expanduser())
        self.app.push_screen(Prompt(f"dump the parameters of {self.node} to the file", default), done)

    @work(thread=True, group="node-write")
    def dump(self, path: Path) -> None:
        """Write the node's parameters as ``roc param dump`` prints them (a parameter file)."""
        try:
            values = host(self).feed.query("param_dump", {"node": self.node})
            write_text_atomic(path, to_yaml({self.node: {"ros__parameters": nested(values)}}))
        except (RocError, OSError) as error:
            self.app.call_from_thread(self.notify, f"dump failed: {error}", severity="error")
            return
        self.app.call_from_thread(self.notify, f"wrote {path}")
