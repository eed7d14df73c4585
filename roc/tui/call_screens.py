"""A service (call it with a YAML request edited in place) and an action (send a goal, see its
feedback, cancel it). The request or goal starts as the type's prototype (``roc interface proto``);
Ctrl+S sends it. Requests are checked field by field before anything is sent (roc.ros.messages)."""

from __future__ import annotations

from typing import Any

from rich.text import Text
from textual import work
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import VerticalScroll
from textual.screen import Screen
from textual.widgets import Footer, Static, TextArea
from textual.worker import get_current_worker

from roc.errors import RocError
from roc.render import to_yaml
from roc.tui.widgets import host


def prototype_yaml(type_name: str) -> str:
    from roc.ros.messages import prototype

    try:
        return to_yaml(prototype(type_name)) if type_name else ""
    except RocError as error:
        return f"# {error}\n"


class CallScreen(Screen):
    """What the service and action screens share: a title, the YAML editor, an output pane."""

    BINDINGS = [
        Binding("escape", "app.pop_screen", "back"),
        Binding("ctrl+s", "send", "send"),
    ]
    DEFAULT_CSS = """
    CallScreen #title { height: 1; background: $primary; }
    CallScreen TextArea { height: 1fr; min-height: 4; }
    CallScreen #output-title { height: 1; background: $boost; }
    CallScreen VerticalScroll { height: 1fr; }
    """
    NOUN = "service"
    WHAT = "request"

    def __init__(self, name: str, type_name: str) -> None:
        super().__init__()
        self.target, self.type_name = name, type_name
        self.output: list[str] = []

    def compose(self) -> ComposeResult:
        yield Static(Text(f"{self.NOUN} {self.target}  {self.type_name}", style="bold"), id="title")
        yield TextArea(prototype_yaml(self.type_name), language=None, id="editor")
        yield Static(f"{self.WHAT} above in YAML; Ctrl+S sends it", id="output-title")
        with VerticalScroll():
            yield Static("", id="output")
        yield Footer()

    def on_mount(self) -> None:
        self.query_one("#editor").focus()

    def say(self, text: str, restart: bool = False) -> None:
        self.output = [text] if restart else [*self.output, text]
        self.query_one("#output", Static).update(Text("\n".join(self.output)))

    def message(self, cls) -> Any | None:
        """The editor's YAML as a message of ``cls``, or None (the error shown)."""
        from roc.ros.messages import fill_message, parse_values

        try:
            return fill_message(cls, parse_values(self.query_one("#editor", TextArea).text, self.WHAT))
        except RocError as error:
            self.say(f"error: {error}", restart=True)
            return None


class ServiceScreen(CallScreen):
    def action_send(self) -> None:
        from roc.ros.types import service_class

        try:
            cls: Any = service_class(self.type_name)
        except RocError as error:
            self.say(f"error: {error}", restart=True)
            return
        request = self.message(cls.Request)
        if request is not None:
            self.say("calling...", restart=True)
            self.call(request)

    @work(thread=True, exclusive=True, group="call")
    def call(self, request) -> None:
        from roc.ros.messages import dict_to_yaml, value_to_data

        worker = get_current_worker()
        # plain data both ways: the daemon fills the request and decodes the response (no rclpy here)
        params = {"service": self.target, "type": self.type_name, "request_data": value_to_data(request), "rate": None}
        try:
            for event in host(self).feed.stream("call", params, lambda: worker.is_cancelled):
                if event["event"] == "waiting":
                    self.app.call_from_thread(self.say, "waiting for the service to be available...")
                elif event["event"] == "response":
                    text = dict_to_yaml(event["value"])
                    self.app.call_from_thread(self.say, f"response:\n{text}", True)
        except RocError as error:
            self.app.call_from_thread(self.say, f"error: {error}")


class ActionScreen(CallScreen):
    BINDINGS = [*CallScreen.BINDINGS, Binding("ctrl+g", "cancel", "cancel goal")]
    NOUN = "action"
    WHAT = "goal"

    def __init__(self, name: str, type_name: str) -> None:
        super().__init__(name, type_name)
        self.goal_id: str | None = None

    def action_send(self) -> None:
        from roc.ros.types import action_class

        try:
            cls: Any = action_class(self.type_name)
        except RocError as error:
            self.say(f"error: {error}", restart=True)
            return
        goal = self.message(cls.Goal)
        if goal is not None:
            self.say("sending the goal...", restart=True)
            self.send(goal)

    @work(thread=True, exclusive=True, group="goal")
    def send(self, goal) -> None:
        from roc.ros.messages import dict_to_yaml, value_to_data

        worker = get_current_worker()
        params = {"action": self.target, "type": self.type_name, "goal_data": value_to_data(goal), "feedback": True}
        say = self.app.call_from_thread
        try:
            for event in host(self).feed.stream("goal", params, lambda: worker.is_cancelled):
                kind = event["event"]
                if kind == "waiting":
                    say(self.say, "waiting for an action server...")
                elif kind == "accepted":
                    self.goal_id = event["goal_id"]
                    say(self.say, f"goal accepted with ID {self.goal_id} (Ctrl+G: cancel)")
                elif kind == "rejected":
                    say(self.say, "goal rejected")
                elif kind == "feedback":
                    say(self.say, f"feedback: {dict_to_yaml(event['value'], flow_style=True)}")
                elif kind == "result":
                    self.goal_id = None
                    result = dict_to_yaml(event["value"], flow_style=True)
                    say(self.say, f"result ({event['status']}): {result}")
        except RocError as error:
            say(self.say, f"error: {error}")

    def action_cancel(self) -> None:
        if self.goal_id is None:
            self.notify("no goal running", severity="warning")
            return
        self.say("canceling the goal...")
        self.cancel(self.goal_id)

    @work(thread=True, group="cancel")
    def cancel(self, goal_id: str) -> None:
        from roc.commands.action.send_goal import cancel_accepted, cancel_call

        try:
            for event in host(self).feed.stream("call", cancel_call(self.target, goal_id), lambda: False):
                if event["event"] == "response":
                    accepted = cancel_accepted(event)
                    self.app.call_from_thread(self.say, "cancel accepted" if accepted else "cancel refused")
                    return
        except RocError as error:
            self.app.call_from_thread(self.say, f"error: {error}")


class PublishScreen(CallScreen):
    """Publish a message edited as YAML (the type's prototype to start): Ctrl+S once, Ctrl+R at a rate
    until Ctrl+T stops it."""

    BINDINGS = [Binding("escape", "app.pop_screen", "back"), Binding("ctrl+s", "send", "publish once"),
                Binding("ctrl+r", "repeat", "publish at a rate"), Binding("ctrl+t", "stop", "stop publishing")]
    NOUN = "publish on"
    WHAT = "message"

    def action_send(self, rate: float | None = None) -> None:
        from roc.ros.messages import value_to_data
        from roc.ros.types import message_class

        try:
            cls: Any = message_class(self.type_name)
        except RocError as error:
            self.say(f"error: {error}", restart=True)
            return
        message = self.message(cls)
        if message is not None:
            self.say("publishing..." if rate is None else f"publishing at {rate:g} Hz (Ctrl+T: stop)...", restart=True)
            self.publish(value_to_data(message), rate)

    def action_repeat(self) -> None:
        from roc.tui.widgets import Prompt

        def done(text: str | None) -> None:
            try:
                rate = float(text or "")
            except ValueError:
                rate = 0.0
            if rate > 0:
                self.action_send(rate)
            elif text is not None:
                self.say(f"error: '{text}' is no rate in Hz", restart=True)
        self.app.push_screen(Prompt("publish at how many Hz", "1"), done)

    def action_stop(self) -> None:
        self.workers.cancel_group(self, "publish")
        self.say("stopped")

    @work(thread=True, exclusive=True, group="publish")
    def publish(self, value: Any, rate: float | None) -> None:
        worker = get_current_worker()
        params = {"topic": self.target, "type": self.type_name, "value": value, "times": 1 if rate is None else 0,
                  "rate": rate, "keep_alive": 0.5}

        def published(count: int) -> None:  # on the app's thread: a Ctrl+T before it has the last word
            if not worker.is_cancelled:
                self.say(f"published message {count}", count > 1)
        try:
            for event in host(self).feed.stream("publish", params, lambda: worker.is_cancelled):
                if event["event"] == "published":
                    self.app.call_from_thread(published, event["count"])
        except RocError as error:
            self.app.call_from_thread(self.say, f"error: {error}")
