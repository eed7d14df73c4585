"""``roc tui``'s application: the screens on a stack (Enter opens, Esc goes back), the keys every
screen has (``q`` quits, ``?`` lists every key, ``:`` the command palette), and the build that runs
while the TUI shows it."""

from __future__ import annotations

import os
import sys
from collections.abc import Callable
from functools import partial
from typing import TYPE_CHECKING

from textual.app import App
from textual.binding import Binding
from textual.command import DiscoveryHit, Hit, Hits, Provider

from roc.errors import RocError, UsageError
from roc.tui.feed import Feed
from roc.tui.graph_screen import GraphScreen
from roc.tui.packages import WorkspaceView
from roc.tui.widgets import TextViewer, binding_lines

if TYPE_CHECKING:  # builds load the engine's modules only when one starts
    from roc.tui.build_run import BuildRun, Start


class GraphCommands(Provider):
    """The palette's commands: open any node, topic, service or action by name, the tf frames, a build."""

    def commands(self) -> list[tuple[str, Callable[[], object], str]]:
        app = self.app
        assert isinstance(app, RocApp)
        found: list[tuple[str, Callable[[], object], str]] = [
            ("tf frames", partial(app.open, "frame", ""), "the live tf tree")]
        if app.workspace is not None:
            found.append(("build the workspace", partial(app.start_build, []), "roc work build, shown live"))
        snapshot = app.graph_screen.snapshot if app.graph_screen else None
        for kind, noun in (("nodes", "node"), ("topics", "topic"), ("services", "service"), ("actions", "action")):
            for entry in (snapshot or {}).get(kind, []):
                name = entry.get("full_name", entry["name"])
                found.append((f"{noun} {name}", partial(app.open, noun, name), f"open the {noun}"))
        return found

    async def discover(self) -> Hits:
        for text, command, help_text in self.commands()[:20]:
            yield DiscoveryHit(text, command, help=help_text)

    async def search(self, query: str) -> Hits:
        matcher = self.matcher(query)
        for text, command, help_text in self.commands():
            score = matcher.match(text)
            if score > 0:
                yield Hit(score, matcher.highlight(text), command, help=help_text)


class RocApp(App[int]):
    TITLE = "roc tui"
    BINDINGS = [
        Binding("q", "quit", "quit"),
        Binding("question_mark", "help", "help"),
        Binding("colon,ctrl+p", "command_palette", "commands"),
    ]
    COMMANDS = {GraphCommands}

    def __init__(self, feed: Feed | None = None, workspace: WorkspaceView | None = None,
                 build: Start | None = None, new_build: Callable[[list[str]], Start] | None = None,
                 checks=None) -> None:
        """``build``: show this build at once (``roc work build --tui``) instead of the graph;
        ``new_build``: how to build packages of the workspace from the TUI; ``checks``: roc.toml's
        ``[check]`` expectations (roc.check.expectations.CheckFile) the problems line holds the graph
        to. With NO_COLOR set, no
        colour at all (Textual alone would draw in greys), styles such as bold and reverse kept."""
        super().__init__(ansi_color=True if os.environ.get("NO_COLOR") else None)
        self.new_build = new_build
        self.feed = feed or Feed()
        self.workspace = workspace
        self.graph_screen: GraphScreen | None = None
        self.build: BuildRun | None = None
        self._first_build = build
        self.checks = checks

    def on_mount(self) -> None:
        if self._first_build is not None:
            from roc.tui.build_run import BuildRun
            from roc.tui.build_screen import BuildScreen

            self.build = BuildRun(self._first_build)
            self.push_screen(BuildScreen(self.build))
        else:
            self.graph_screen = GraphScreen(self.workspace, self.checks)
            self.push_screen(self.graph_screen)

    def open(self, kind: str, name: str) -> None:
        """Push the screen of a node, topic, service, action, or the tf frames."""
        from roc.tui.call_screens import ActionScreen, ServiceScreen
        from roc.tui.frames_screen import FramesScreen
        from roc.tui.node_screen import NodeScreen
        from roc.tui.topic_screen import TopicScreen

        if kind == "node":
            self.push_screen(NodeScreen(name))
        elif kind == "topic":
            self.push_screen(TopicScreen(name))
        elif kind in ("service", "action"):
            screen = ServiceScreen if kind == "service" else ActionScreen
            self.push_screen(screen(name, self.type_of(kind, name)))
        elif kind == "frame":
            self.push_screen(FramesScreen())

    def type_of(self, kind: str, name: str) -> str:
        """A service's or action's type from the last snapshot ("" when unknown)."""
        snapshot = self.graph_screen.snapshot if self.graph_screen else None
        entry = next((e for e in (snapshot or {}).get(f"{kind}s", []) if e["name"] == name), None)
        return entry["types"][0] if entry and entry["types"] else ""

    def open_package(self, name: str) -> None:
        if self.workspace is not None:
            self.push_screen(TextViewer(f"package {name}", self.workspace.details(name)))

    def start_build(self, packages: list[str]) -> None:
        """Build ``packages`` (all when empty) of the workspace and show it; one build at a time."""
        from roc.tui.build_run import BuildRun
        from roc.tui.build_screen import BuildScreen

        if self.new_build is None:
            return
        if self.build is not None and self.build.running():
            self.notify("a build is running", severity="warning")
        else:
            try:
                self.build = BuildRun(self.new_build(packages))
            except RocError as error:
                self.notify(str(error), severity="error")
                return
        self.push_screen(BuildScreen(self.build))

    def action_help(self) -> None:
        screen = type(self.screen).__name__.removesuffix("Screen")
        lines = binding_lines(f"{screen} screen", self.screen.BINDINGS, self.get_key_display)
        lines += binding_lines("everywhere", self.BINDINGS, self.get_key_display)
        lines += ["Arrows, Page Up/Down, Home/End move in a list; Enter opens what is under the cursor;",
                  "Esc goes back (or clears the filter). In an input: Enter accepts, Esc cancels."]
        self.push_screen(TextViewer("keys (Esc: back)", "\n".join(lines)))

    async def action_quit(self) -> None:
        """Quit; a running build is stopped first (its process trees with it)."""
        if self.build is not None and self.build.running():
            self.notify("stopping the build...")
            self.build.stop.set()
            await self.run_in_thread(self.build.finish)
        shown_build = self._first_build is not None and self.build is not None  # roc work build --tui
        self.exit(self.build.code or 0 if shown_build and self.build else 0)

    async def run_in_thread(self, function) -> None:
        import asyncio

        await asyncio.get_running_loop().run_in_executor(None, function)


def require_terminal(what: str) -> None:
    if not (sys.stdin.isatty() and sys.stdout.isatty()):
        raise UsageError(f"{what} needs a terminal (stdin and stdout are not both one)")


def run_build_app(start: Start, verb: str = "build") -> int:
    """``roc work build --tui``: the build shown live; once the user quits, the console's summary
    is printed and the build's exit code returned (a build still running is stopped first)."""
    import io

    from roc.handlers.console import ConsoleHandler
    from roc.render import print_text

    summary = io.StringIO()
    console = ConsoleHandler(summary, start_end=False, stderr=False, kind=verb)
    app = RocApp(build=lambda handlers, stop: start([*handlers, console], stop))
    try:
        app.run()
    finally:
        code = app.build.finish() if app.build is not None else 1
    print_text(summary.getvalue().lstrip("\n"))
    if app.build is not None and app.build.error:
        raise RocError(app.build.error)
    return code
